"""The mistakes a user makes when bringing a task of their own are named in one line: an
environment passed without its ClosedLoop, a misspelt setting, a fitness function that returns
something else than numbers, a rollout that could not run, a module.Class typed without its
``python:`` prefix, a network attribute written to, and a run folder's missing champion."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dnnevo
from dnnevo import ConfigError, FitnessError
from dnnevo.closedloop import ClosedLoop, FarSeeker, rollout

from cli_helpers import assert_one_line_error, run_cli

SMALL = dnnevo.EvolutionConfig(population=8, generations=2, size=2, n_inputs=1, selection="rank")


def test_an_environment_without_its_closed_loop_is_named() -> None:
    for call in (lambda: dnnevo.evolve(FarSeeker(), SMALL, progress=False),
                 lambda: dnnevo.resume("no-such-run", FarSeeker(), progress=False)):
        with pytest.raises(ConfigError, match=r"task has type FarSeeker; .*\(FarSeeker looks like an "
                                              r"environment: wrap it, ClosedLoop\(FarSeeker\(\.\.\.\), max_steps=\.\.\.\)"):
            call()
    with pytest.raises(ConfigError, match="task has type int; expected a task or preset name"):
        dnnevo.evolve(3, SMALL, progress=False)  # type: ignore[arg-type]


@pytest.mark.parametrize("make, message", [
    (lambda: dnnevo.EvolutionConfig(populaton=20), "EvolutionConfig has no setting 'populaton' (did you mean 'population'?)"),
    (lambda: dnnevo.IntegratorConfig(dtt=0.1), "IntegratorConfig has no setting 'dtt' (did you mean 'dt'?)"),
    (lambda: dnnevo.EvolutionConfig(zzz=1), "EvolutionConfig has no setting 'zzz'; its settings: task, population,"),
])
def test_a_misspelt_setting_is_a_config_error_with_the_closest_name(make, message) -> None:
    with pytest.raises(ConfigError) as e:
        make()
    assert str(e.value).startswith(message)


def test_the_configs_still_take_their_settings_by_name_and_position() -> None:
    assert dnnevo.EvolutionConfig(population=20).population == 20
    assert dnnevo.IntegratorConfig("rk4", 0.05, 2) == dnnevo.IntegratorConfig(method="rk4", dt=0.05, substeps=2)


@pytest.mark.parametrize("value", ["good", "1.5", None, object()])
def test_a_fitness_function_that_returns_no_numbers_is_a_fitness_error(value) -> None:
    with pytest.raises(FitnessError, match="the fitness function returned values that are not numbers"):
        dnnevo.evolve(lambda networks: [value] * len(networks), SMALL, progress=False)


def test_an_environment_class_not_object_is_named() -> None:
    with pytest.raises(ConfigError, match=r"task is the class FarSeeker; .*ClosedLoop\(FarSeeker\(\.\.\.\)"):
        dnnevo.evolve(FarSeeker, SMALL, progress=False)


@pytest.mark.parametrize("missing", ["reset", "step"])
def test_an_environment_without_reset_or_step_is_named_by_rollout_and_closed_loop(missing: str) -> None:
    methods = {"observation_size": 1, "reset": lambda self, e, rng: np.zeros((len(e), 1)),
               "step": lambda self, r, a: (np.zeros((len(a), 1)), np.zeros(len(a)), np.zeros(len(a), bool))}
    del methods[missing]
    env = type("Half", (), methods)()
    net = dnnevo.Network.random(2, 1, seed=0)
    for call in (lambda: rollout([net], env, max_steps=3), lambda: ClosedLoop(env, max_steps=3)):
        with pytest.raises(dnnevo.TaskError, match=f"Half has no {missing} method"):
            call()


def test_network_attributes_cannot_be_written_to() -> None:
    net = dnnevo.Network.random(2, 1, seed=0)
    with pytest.raises(ValueError, match="read-only"):
        net.tau[0] = -5.0
    assert net.tau[0] > 0


def test_a_module_class_without_its_prefix_is_pointed_to_it(tmp_path: Path) -> None:
    r = run_cli("run", "pulses.TwoPulses", "--out", tmp_path / "run")
    assert_one_line_error(r, "unknown preset 'pulses.TwoPulses' (a task written in Python is named "
                             "python:pulses.TwoPulses)")


def fitness(networks):
    return np.array([net.tau[0] for net in networks])


def test_a_run_of_a_fitness_function_says_to_resume_it_from_python(tmp_path: Path) -> None:
    out = tmp_path / "run"
    dnnevo.evolve(fitness, SMALL, out=out, progress=False)
    with pytest.raises(dnnevo.DnnevoError, match=r"it holds a run: resume it with "
                                                 r"dnnevo.resume\('.*run', task=fitness\) from Python"):
        dnnevo.evolve(fitness, SMALL, out=out, progress=False)
    (out / "best.json").unlink()
    r = run_cli("show", out)
    assert_one_line_error(r, "has no best.json, though it has a checkpoint; dnnevo.resume(")
    dnnevo.resume(out, fitness, progress=False)
    assert (out / "best.json").exists()


def test_a_run_of_a_script_s_class_says_to_resume_it_from_python(tmp_path: Path) -> None:
    (tmp_path / "light.py").write_text(
        "import dnnevo\nfrom dnnevo.closedloop import ClosedLoop, FarSeeker\n\n"
        "class Seeker(FarSeeker):\n    pass\n\n"
        "config = dnnevo.EvolutionConfig(population=8, generations=1, size=5, n_inputs=1, selection='rank')\n"
        "dnnevo.evolve(ClosedLoop(Seeker(), max_steps=30), config, out='run', progress=False)\n")
    import subprocess
    import sys
    subprocess.run([sys.executable, "light.py"], cwd=tmp_path, check=True, capture_output=True)
    with pytest.raises(dnnevo.DnnevoError, match=r"resume it with dnnevo.resume\('.*run', "
                                                 r"task=ClosedLoop\(\.\.\.\)\) from Python"):
        dnnevo.evolve(fitness, SMALL, out=tmp_path / "run", progress=False)


def test_a_run_of_a_script_s_fitness_function_says_to_resume_it_with_the_function(tmp_path: Path) -> None:
    (tmp_path / "fit.py").write_text(
        "import dnnevo\n\ndef fitness(networks):\n    return [n.tau[0] for n in networks]\n\n"
        "config = dnnevo.EvolutionConfig(population=8, generations=1, size=2, n_inputs=1)\n"
        "dnnevo.evolve(fitness, config, out='run', progress=False)\n")
    import subprocess
    import sys
    subprocess.run([sys.executable, "fit.py"], cwd=tmp_path, check=True, capture_output=True)
    with pytest.raises(dnnevo.DnnevoError, match=r"resume it with dnnevo.resume\('.*run', task=fitness\) from Python"):
        dnnevo.evolve(fitness, SMALL, out=tmp_path / "run", progress=False)


def test_a_run_of_a_task_class_missing_its_champion_says_to_resume_it(tmp_path: Path) -> None:
    out = tmp_path / "run"
    dnnevo.evolve(ClosedLoop(FarSeeker(), max_steps=50), SMALL, out=out, progress=False)
    (out / "best.json").unlink()
    r = run_cli("show", out)
    assert_one_line_error(r, f"has no best.json, though it has a checkpoint; 'dnnevo resume {out}' writes it again")


class _Sized:
    """An environment with an argument named as a run setting, and any step."""

    observation_size = 1

    def __init__(self, size: int = 5) -> None:
        self.size = size

    def reset(self, episodes, rng):
        return np.zeros((len(episodes), 1))

    def step(self, rates, active):
        return np.zeros((len(rates), 1)), rates[:, 0], np.zeros(len(rates), dtype=bool)


def test_a_long_step_and_an_argument_named_as_a_run_setting_are_not_refused(tmp_path) -> None:
    from dnnevo.closedloop import ClosedLoop

    # The step is judged against the networks' own time constants, not against a probe's.
    ClosedLoop(_Sized(), max_steps=5, dt=2.5, substeps=1)
    loop = ClosedLoop(_Sized(size=8), max_steps=5)
    assert loop.arguments() == {}  # size is the run's; task_params may not hold it
    config = dnnevo.EvolutionConfig(population=6, generations=1, size=2, n_inputs=1, selection="rank")
    assert "size" not in dnnevo.evolve(loop, config, progress=False).config.task_params
