"""Refusals that leave nothing behind and say what fits: a folder a command will not write is
left byte for byte as it was, a missing folder is called missing, and every integer argument of
the native module is checked with an error that names it (issue 48, section 1)."""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np
import pytest

import dnnevo
from dnnevo import _core
from dnnevo.errors import InvalidArgumentError

from cli_helpers import assert_one_line_error, run_cli


def snapshot(folder: Path) -> dict[str, str]:
    """Every entry of ``folder`` (hidden ones included) with its content's digest."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "dir"
            for p in sorted(folder.rglob("*"))}


@pytest.mark.parametrize("command", [
    ["run", "sequence-1bit", "--quick"],
    ["sweep", "sequence-1bit", "--quick", "--seeds", "0"],
])
def test_a_refused_folder_is_left_as_it_was(tmp_path: Path, command: list[str]) -> None:
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("my notes\n")
    before = snapshot(folder)
    r = run_cli(*command, "--out", folder)
    assert_one_line_error(r, "is not empty; it holds files that are not a dnnevo run (notes.txt)")
    assert "dnnevo resume" not in r.stderr
    assert snapshot(folder) == before


def test_the_advice_fits_what_the_folder_holds(tmp_path: Path) -> None:
    run = tmp_path / "run"
    assert run_cli("run", "sequence-1bit", "--quick", "--out", run).returncode == 0
    before = snapshot(run)
    again = run_cli("run", "sequence-1bit", "--quick", "--out", run)
    assert_one_line_error(again, f"it holds a run: resume it with 'dnnevo resume {run}'")
    assert snapshot(run) == before
    sweep = tmp_path / "sweep"
    sweep.mkdir()
    (sweep / "sweep.json").write_text(json.dumps({}))
    into = run_cli("run", "sequence-1bit", "--quick", "--out", sweep)
    assert_one_line_error(into, "it holds a sweep: continue it with the same 'dnnevo sweep' command")


def test_a_missing_folder_is_called_missing(tmp_path: Path) -> None:
    r = run_cli("resume", tmp_path / "nowhere")
    assert_one_line_error(r, f"{tmp_path / 'nowhere'} does not exist")
    with pytest.raises(dnnevo.DnnevoError, match="does not exist"):
        dnnevo.resume(tmp_path / "nowhere")


SEQUENCE = dnnevo.presets.get("sequence-1bit").native.builtin()
NAV1D = dnnevo.presets.get("nav1d-far").native.builtin()
LANDMARK = dnnevo.presets.get("landmark").native.builtin()
NET5 = dnnevo.Network.random(5, 2, seed=0)
NET5_1 = dnnevo.Network.random(5, 1, seed=0)
NET8 = dnnevo.Network.random(8, 7, seed=0)

#: Every integer argument of the native module's functions: (function, arguments, the one set
#: to -1). A new integer argument belongs here.
CALLS = [
    (SEQUENCE.timings, (0, 0, 0), ["seed", "generation", "trial"]),
    (SEQUENCE.fresh_timings, (0, 0), ["seed", "trial"]),
    (SEQUENCE.trial_order, (0, 0), ["seed", "generation"]),
    (SEQUENCE.assess, (NET5, 1, 0), ["trials_per_target", "seed"]),
    (NAV1D.chains, (0, 0), ["seed", "generation"]),
    (NAV1D.fresh_chains, (1, 1, 0), ["count", "trials", "seed"]),
    (NAV1D.assess, (NET5_1, 1, 0), ["chains", "seed"]),
    (LANDMARK.record, (NET8, 1, 0, 0, False), ["landmark", "seed", "trial"]),
    (LANDMARK.assess, (NET8, 1, 0, False), ["per_landmark", "seed"]),
    (_core.condition_seed, (0, 0), ["seed", "generation"]),
]


def _cases():
    import inspect
    for fn, args, names in CALLS:
        params = [p for p in inspect.signature(fn).parameters]
        for name in names:
            yield pytest.param(fn, args, params.index(name), name, id=f"{fn.__qualname__}-{name}")


@pytest.mark.parametrize("fn, args, at, name", list(_cases()))
def test_a_negative_integer_argument_is_an_error_naming_it(fn, args, at: int, name: str) -> None:
    bad = list(args)
    bad[at] = -1
    with pytest.raises(InvalidArgumentError, match=rf"{name} is -1; it must be an integer in"):
        fn(*bad)


def test_negative_timings_and_threads_are_named() -> None:
    with pytest.raises(InvalidArgumentError, match=r"timing\[1\]\[0\] is -3"):
        SEQUENCE.trial(NET5, "01", [(2, 2), (-3, 2)])
    evolution = dnnevo.GeneticAlgorithm(dnnevo.presets.get("sequence-1bit", quick=True), seed=0)
    with pytest.raises(InvalidArgumentError, match="threads is -1"):
        evolution.step(threads=-1)


def test_numpy_numbers_stand_for_python_ones_and_what_toml_cannot_hold_is_named() -> None:
    config = dnnevo.EvolutionConfig(population=np.int64(50), mutation_rate=np.float32(0.5),
                                    task_params={"max_steps": np.int64(10), "pair": (1, np.float64(2.5)),
                                                 "flags": {"on": np.bool_(True)}})
    assert (config.population, type(config.population)) == (50, int)
    assert config.task_params == {"max_steps": 10, "pair": [1, 2.5], "flags": {"on": True}}
    assert type(config.task_params["max_steps"]) is int
    assert "max_steps = 10" in config.to_toml()
    for params, message in [({"x": None}, "task_params.x is None"),
                            ({"x": np.zeros(2)}, "task_params.x is an array; a config holds lists"),
                            ({"x": [1, {"y": object()}]}, "task_params.x[1].y is of type object"),
                            ({1: 2}, "task_params has the key 1")]:
        with pytest.raises(dnnevo.ConfigError, match=re.escape(message)):
            dnnevo.EvolutionConfig(task_params=params)
