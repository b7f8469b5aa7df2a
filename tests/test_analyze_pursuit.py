"""``dnnevo analyze`` on a Python task: a quick predator-avoidance run analysed through the task
protocol (its class's ``analysis``), a pursuer's appearance found where it is known, and the
refusal for a Python task that declares nothing."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import assert_one_line_error, assert_png, run_cli

import dnnevo
from dnnevo import analysis, presets
from dnnevo.closedloop import named
from dnnevo.errors import ConfigError, TaskError
from dnnevo.analysis import events
from dnnevo.robots import Pursuit
from dnnevo.robots.pursuit import appears
from dnnevo.runs import RunDir
from dnnevo.tasks import user

TINY = ["--quick", "--set", "generations=1", "--set", "population=10", "--threads", "1"]


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("analyze-pursuit") / "run"
    r = run_cli("run", "predator-avoidance", *TINY, "--out", out)
    assert r.returncode == 0, r.stderr
    return out


def test_analyze_a_predator_avoidance_run(run: Path) -> None:
    r = run_cli("analyze", run, "--trials", "4", "--steps", "11", "--cuts", "1")
    assert r.returncode == 0, r.stderr
    assert "input pursuer front at 1.5 m" in r.stdout and "sweep of pursuer front" in r.stdout
    assert "lesions (4 fresh trials, seed 0)" in r.stdout
    assert "pursuer appears: in the trained world" in r.stdout
    assert "sensor hidden for the first 3 s:" in r.stdout
    doc = json.loads((run / "analysis.json").read_text())
    assert doc["task"] == "python:dnnevo.robots.pursuit.Pursuit"
    assert [c["label"] for c in doc["conditions"]][0] == "nothing sensed"
    assert doc["bifurcation"]["index"] == 8 and len(doc["bifurcation"]["values"]) == 11
    assert len(doc["lesions"]["lesions"]) == 6 + 1
    seen = doc["pursuer_appears"]
    assert {"visible_at_start", "t", "series", "groups", "seed", "purpose", "hidden_s"} <= seen.keys()
    assert seen["seed"] == 0 and seen["purpose"] == "evaluate"
    assert len(seen["t"]) == 71 and seen["t"][20] == 0.0
    probe = seen["groups"]["sensor hidden for the first 3 s"]
    assert probe["events"] >= 90  # one per episode that a pursuer did not end in the first 3 s
    assert {"away_speed", "speed", "turn_away", "bearing_deg", "distance", "rates", "caught",
            "farther", "moves_away"} <= probe.keys()
    assert len(probe["rates"]["mean"]) == 71 and len(probe["rates"]["mean"][0]) == 6
    for name in ("analysis-phase.png", "analysis-bifurcation.png", "analysis-lesions.png",
                 "analysis-basins.png", "analysis-pursuer.png"):
        assert_png(run / name)


def test_recorded_episodes_are_the_judged_ones_and_replay_exactly(run: Path) -> None:
    """The recorded trials are fresh episodes, step by step, that a network driven again by
    their inputs reproduces: the basins figure's states are the real ones."""
    config, raw = RunDir(run).read_run_config()
    net = RunDir(run).read_best(config, raw)
    trials = analysis.recorded_trials(config, net, seed=3)
    assert len(trials) == 4 and all(i.shape[1] == 12 and o.shape[1] == 6 for o, i in trials)
    outputs, inputs = trials[0]
    states = analysis.replay(config, net, inputs)
    assert np.allclose(1.0 / (1.0 + np.exp(-(states - net.theta))), outputs, atol=1e-12)
    again = user.record(config, net, 1, seed=3)[0]
    assert np.array_equal(again.inputs, inputs)
    # The judged episodes: as long, one by one, as those `dnnevo assess --seed 3` runs.
    recorded = user.record(config, net, 6, seed=3)
    _, _, judged = named.closed_loop(config).judged(net, 6, 3, "evaluate")
    assert [len(e.outputs) for e in recorded] == judged.lengths.ravel().tolist()
    # ... and their rewards add up to the judged returns (summed in the same order).
    assert [np.cumsum(e.rewards)[-1] for e in recorded] == judged.returns.ravel().tolist()


@pytest.mark.parametrize("bad", [dict(main_input=1.0), dict(main_input=True), dict(output_neuron="0"),
                                 dict(output_neuron=6), dict(input_names="abc"),
                                 dict(conditions={"x": ["a"] * 12}), dict(conditions={"x": [float("nan")] * 12})])
def test_a_wrong_declaration_is_one_line_naming_it(bad: dict[str, object], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(Pursuit, "analysis", dataclasses.replace(Pursuit.analysis, **bad))  # type: ignore[arg-type]
    name = next(iter(bad))
    with pytest.raises(ConfigError, match=r"Pursuit\.analysis" + (": condition 'x'" if name == "conditions" else rf"\.{name}")):
        user.analysed(presets.get("predator-avoidance"))


def test_a_pursuer_appears_when_it_comes_within_the_sensors_reach() -> None:
    """A robot standing in a corner and two pursuers in the far one, beyond the sensor's reach
    (6.5 m between edges): the pursuer appears at the first step at which the nearer one's centre
    is within 6.5 m plus both radii, and not before."""
    env = Pursuit()
    env.reset(np.arange(1, dtype=np.int64), np.random.default_rng(0))
    env.fleet.place([[0.5, 0.5, 0.0]], [[[7.5, 5.5, np.pi], [7.0, 5.5, np.pi]]])
    s = env.settings
    reach = s["sectors"]["range"] + s["robot"]["radius"] + s["pursuers"]["radius"]
    sensed, near = [env.observe()[0, 8:]], []
    still = np.full((1, 6), 0.5)  # both wheels at rest
    for _ in range(120):
        near.append(np.hypot(*(env.fleet.pursuers[0, :, :2] - env.fleet.poses[0, :2]).T).min())
        obs, _, _ = env.step(still, np.ones(1, dtype=bool))
        sensed.append(obs[0, 8:])
    near.append(np.hypot(*(env.fleet.pursuers[0, :, :2] - env.fleet.poses[0, :2]).T).min())
    expected = int(np.argmax(np.array(near) < reach))
    assert 20 < expected < 100  # out of reach for more than 2 s, then in reach
    assert appears(np.array(sensed), quiet=20) == [expected]
    assert appears(np.array(sensed), quiet=expected + 1) == []  # not unseen for that long


def test_onsets_count_only_after_enough_quiet() -> None:
    seen = np.zeros(40, dtype=bool)
    seen[[0, 1, 12, 30, 31]] = True
    assert events.onsets(seen, quiet=10) == [12, 30]
    assert events.onsets(seen, quiet=11) == [30]
    assert events.onsets(np.ones(5, dtype=bool), quiet=0) == []  # visible from the start: no onset
    w = events.aligned(np.arange(10.0), 8, before=3, after=3)
    assert np.array_equal(w[:5], [5, 6, 7, 8, 9]) and np.isnan(w[5:]).all()


def test_a_python_task_without_analysis_defaults_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "nav"
    r = run_cli("run", "reactive-navigation", *TINY, "--set", "task_params.max_steps=50", "--out", out)
    assert r.returncode == 0, r.stderr
    assert_one_line_error(run_cli("analyze", out, "--no-lesions"), "has no analysis defaults",
                          "analysis = dnnevo.tasks.protocol.Analysis(")


def test_the_analysis_declaration_leaves_the_runs_digest_alone() -> None:
    """Pursuit's Analysis is declared outside its class body, since a run folder records a digest
    of the class's source (fitness_sha256) and resume and assess refuse a class that changed:
    this is the digest of the reference reproduction's predator-avoidance runs (at 43deba7)."""
    from dnnevo import presets
    from dnnevo.closedloop import named

    config = presets.get("predator-avoidance")
    # Recorded before digests took in what the class reads from its module: still accepted.
    digests = named.closed_loop(config).digests()
    assert "9cd751a8cf583ae73f4345f0bbc6415a4e8386ae9044bfb5529ef83ddd52f7f4" in digests


def test_a_task_that_breaks_the_protocol_while_recorded_is_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    """Recording checks the observations as a rollout does, and shows the task read-only rates."""
    config = presets.get("predator-avoidance")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=1)
    real = Pursuit.step

    def wrong_shape(self, rates, active):  # type: ignore[no-untyped-def]
        obs, reward, done = real(self, rates, active)
        return obs[:, :3], reward, done

    monkeypatch.setattr(Pursuit, "step", wrong_shape)
    with pytest.raises(TaskError, match=r"Pursuit\.step returned observations of shape \(2, 3\)"):
        user.record(config, net, 2, seed=0)

    def writes(self, rates, active):  # type: ignore[no-untyped-def]
        rates[:] = 0.0
        return real(self, rates, active)

    monkeypatch.setattr(Pursuit, "step", writes)
    with pytest.raises(ValueError, match="read-only"):
        user.record(config, net, 2, seed=0)
