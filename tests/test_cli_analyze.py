"""``dnnevo analyze`` on a one-generation run of every task: analysis.json, the figures, the
summary, and one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import assert_one_line_error, assert_png, run_cli

import dnnevo
from dnnevo import analysis
from dnnevo.runs import rundir
from dnnevo.config import EvolutionConfig
from dnnevo.runs import RunDir

TINY = ["--quick", "--set", "generations=1", "--set", "population=10"]
PRESETS = ("sequence-1bit", "nav1d-classifier", "nav1d-single", "landmark")
"""One preset per task family; nav1d-single is the multi-trial nav1d system (8 neurons)."""


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("analyze-runs")
    out = {}
    for name in PRESETS:
        out[name] = root / name
        r = run_cli("run", name, *TINY, "--out", out[name], "--threads", "1")
        assert r.returncode == 0, r.stderr
    return out


@pytest.mark.parametrize("preset", PRESETS)
def test_analyze_writes_json_and_figures(runs: dict[str, Path], preset: str) -> None:
    run = runs[preset]
    r = run_cli("analyze", run, "--trials", "4", "--steps", "21", "--cuts", "2")
    assert r.returncode == 0, r.stderr
    assert "equilibria" in r.stdout and "lesions (4 fresh trials, seed 0)" in r.stdout
    doc = json.loads((run / "analysis.json").read_text())
    assert doc["format"] == "dnnevo-analysis" and doc["task"] == EvolutionConfig.from_toml(
        RunDir(run).config.read_text()).task
    net = dnnevo.Network.load(RunDir(run).best)
    assert len(doc["conditions"]) >= 2
    for cond in doc["conditions"]:
        assert cond["equilibria"], cond["label"]
        for e in cond["equilibria"]:
            rate = analysis.vector_field(net, cond["input"], np.array(e["state"]))
            assert np.max(np.abs(rate * net.tau)) < 1e-9
            assert e["stability"] in analysis.STABILITIES
    assert len(doc["bifurcation"]["values"]) == 21
    assert {"branches", "cycle_branch", "retried", "even"} <= doc["bifurcation"].keys()
    assert len(doc["lesions"]["lesions"]) == net.size + 2
    i, j = doc["neurons"]
    assert i != j
    basins = doc["trial_basins"]
    assert len(basins["basins"]) > 10 and set(basins["basins"]) <= {-1, *range(len(basins["attractors"]))}
    # The letters of the basins' line are explained: the first condition's stable equilibria.
    letters = ", ".join(chr(65 + k) for k in range(len(basins["attractors"])))
    if letters:
        assert f"stable: {letters})" in r.stdout and f"    {letters}: the stable equilibri" in r.stdout, r.stdout
    for name in ("analysis-phase.png", "analysis-bifurcation.png", "analysis-lesions.png", "analysis-basins.png"):
        assert_png(run / name)
    hidden = [p for p in run.iterdir() if p.name.startswith(".") and p.name != rundir.LOCK_NAME]
    assert not hidden, "temporary files left behind"


def test_analyze_options_and_a_two_neuron_portrait(tmp_path: Path, runs: dict[str, Path]) -> None:
    run = runs["sequence-1bit"]
    (run / "analysis-lesions.png").write_bytes(b"an earlier analysis's figure")
    (run / "analysis-notes.png").write_bytes(b"the user's own file")
    r = run_cli("analyze", run, "--input", "0,0.25", "--input", "0,0.5", "--neurons", "0,2", "--no-lesions",
                "--sweep", "0:2", "--sweep-input", "0", "--steps", "5", "--sweep-cycles")
    assert r.returncode == 0, r.stderr
    doc = json.loads((run / "analysis.json").read_text())
    assert [c["label"] for c in doc["conditions"]] == ["0,0.25", "0,0.5"]
    # The swept input's partners keep the first --input's values.
    assert doc["bifurcation"]["input"] == [0.0, 0.25]
    assert doc["neurons"] == [0, 2] and doc["lesions"] is None
    # No figure of an earlier analysis is left beside an analysis.json that does not describe it.
    assert not (run / "analysis-lesions.png").exists()
    assert (run / "analysis-notes.png").read_bytes() == b"the user's own file"
    assert r.stdout.rstrip().endswith("; removed the earlier analysis's analysis-lesions.png"), r.stdout
    assert doc["bifurcation"]["index"] == 0 and doc["bifurcation"]["values"][-1] == 2.0
    assert len(doc["bifurcation"]["cycles"]) == 5
    # A 2-neuron oscillator: the portrait draws nullclines and the cycle.
    from dnnevo.analysis import plot_phase_portrait

    net = dnnevo.Network(tau=[1.0, 1.0], theta=[3.75, 1.75], weights=[[5.5, 2.0], [-2.0, 5.5]],
                         sensor_weights=[[1.0], [0.0]])
    found = [analysis.attractors(net, [0.0], "off")]
    assert len(found[0].cycles) == 1
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    assert plot_phase_portrait(found, ax, net=net, neurons=(0, 1)) is ax
    assert len(ax.collections) >= 2  # the two nullclines
    fig.savefig(tmp_path / "p.png")
    plt.close(fig)
    assert_png(tmp_path / "p.png")


def test_analyze_errors(runs: dict[str, Path], tmp_path: Path) -> None:
    run = runs["sequence-1bit"]
    assert_one_line_error(run_cli("analyze", run, "--neurons", "1,1"), "--neurons", "two different")
    assert_one_line_error(run_cli("analyze", run, "--input", "0,1,2"), "--input 0,1,2 has 3 values")
    assert_one_line_error(run_cli("analyze", run, "--input", "a,b"), "not a comma-separated list")
    assert_one_line_error(run_cli("analyze", run, "--sweep", "1"), "--sweep '1'")
    assert_one_line_error(run_cli("analyze", run, "--sweep-input", "5"), "--sweep-input is 5")
    assert_one_line_error(run_cli("analyze", run, "--steps", "1"), "--steps is 1")
    assert_one_line_error(run_cli("analyze", tmp_path / "missing"), "missing")


def test_analyze_help_has_an_example() -> None:
    r = run_cli("analyze", "--help")
    assert r.returncode == 0 and "dnnevo analyze runs/demo" in r.stdout


def test_nav1d_single_records_a_whole_chain(runs: dict[str, Path]) -> None:
    """nav1d-single's network learns its environment in trial 1 of a 5-trial chain and keeps its
    state between trials: analyze records such a chain, not the 2 trials of the classifier."""
    from dnnevo.tasks import nav1d

    run = RunDir(runs["nav1d-single"])
    config, raw = run.read_config()
    net = run.read_best(config, raw)
    assert nav1d.chain_len(config) == config.task_params["trials_per_environment"] == 5
    (outputs, inputs), = analysis.recorded_trials(config, net, seed=0)
    record = nav1d.record(config, net, nav1d.fresh_chains(config, 1, 5, 0)[0])
    assert record.trial.max() == 4
    assert np.array_equal(outputs, record.outputs) and inputs.shape == (len(outputs), 2)
    classifier = RunDir(runs["nav1d-classifier"]).read_config()[0]
    assert nav1d.chain_len(classifier) == 1
