"""dnnevo.evaluation.assessment: every task's assessment in one shape, with hand-built networks whose rates are
known exactly."""

from __future__ import annotations

import doctest
import math

import numpy as np
import pytest

from dnnevo import tasks
from dnnevo.cli import assess as _cli_assess
from dnnevo.tasks import nav1d
import dnnevo
from dnnevo.evaluation import assessment as assess
from dnnevo import presets
from dnnevo.evaluation import stats
from dnnevo.errors import ConfigError, InvalidArgumentError


def constant(theta: list[float], size: int, n_inputs: int) -> dnnevo.Network:
    """No weights and no sensors: the state stays 0 and neuron i fires at f(-theta[i])."""
    t = np.zeros(size)
    t[: len(theta)] = theta
    return dnnevo.Network(tau=np.ones(size), theta=t, weights=np.zeros((size, size)),
                          sensor_weights=np.zeros((size, n_inputs)))


def test_doctests() -> None:
    assert doctest.testmod(assess).failed == 0


def test_combine() -> None:
    assert assess.combine(["pass"]) == "pass"
    assert assess.combine(["pass", "fail", "undecided"]) == "fail"
    assert assess.combine(["undecided", "pass"]) == "undecided"
    with pytest.raises(InvalidArgumentError):
        assess.combine([])


def test_rate_converts_trials_to_decide_into_the_trial_unit() -> None:
    # 196/200 = 98% against 95%: undecided; 203 trials decide it (stats), which for landmark's
    # overall rate (one trial of each landmark per --trials unit) is 102 trials per landmark.
    assert stats.trials_to_decide(0.98, 0.95) == 203
    r = assess.rate("overall", 196, 200, threshold=0.95, per_trial=2.0)
    assert (r.verdict, r.trials_to_decide) == ("undecided", 102)
    r = assess.rate("0*", 180, 200, threshold=0.9)  # the observed rate is the threshold
    assert (r.verdict, r.trials_to_decide) == ("undecided", None)
    r = assess.rate("landmark 1", 3, 4)               # shown, not judged
    assert (r.verdict, r.threshold, r.trials_to_decide) == (None, None, None)
    assert r.interval == stats.wilson(3, 4)


def test_sequence_judges_every_target() -> None:
    cfg = presets.get("sequence-1bit")
    silent = constant([50.0] * 5, 5, 2)  # output ~0 forever: every 0* trial right, every 1* wrong
    a = tasks.assess(cfg, silent, 40, seed=0)
    assert (a.task, a.trials, a.unit, a.seed) == ("sequence", 40, "trials per target", 0)
    zero, one = a.rates
    assert (zero.name, zero.k, zero.n, zero.verdict) == ("0*", 40, 40, "pass")
    assert (one.name, one.k, one.n, one.verdict) == ("1*", 0, 40, "fail")
    assert a.verdict == "fail" and a.weakest is one
    assert a.details["mean_performance"]["0"] == pytest.approx(1.0)
    d = a.to_dict()
    assert d["rates"][0]["interval"] == list(stats.wilson(40, 40)) and d["verdict"] == "fail"
    # 20 perfect trials cannot pass 90% (35 are needed): undecided, and 35 would decide.
    a = tasks.assess(presets.get("sequence-1bit", overrides=['task_params.targets=["0"]']), silent, 20, seed=0)
    assert a.verdict == "undecided" and a.rates[0].trials_to_decide == 35


def test_landmark_judges_the_overall_rate_and_shows_each_landmark() -> None:
    cfg = presets.get("landmark")
    says_one = constant([50.0], 8, 1)  # classifier f(-50) ~ 0: always "landmark 1"
    a = tasks.assess(cfg, says_one, 3, seed=0)
    assert a.details == {"confusion": [[3, 0], [3, 0]], "robot_like": False}
    one, two, overall = a.rates
    assert (one.name, one.k, one.n, one.verdict) == ("landmark 1", 3, 3, None)
    assert (two.name, two.k, two.n, two.verdict) == ("landmark 2", 0, 3, None)
    assert (overall.k, overall.n, overall.threshold, overall.verdict) == (3, 6, 0.95, "fail")
    assert a.verdict == "fail" and a.judged == [overall]
    assert tasks.assess(cfg, says_one, 2, seed=0, robot_like=True).details["robot_like"] is True


def test_nav1d_independent_trials() -> None:
    cfg = presets.get("nav1d-classifier")
    says_near = constant([0.0, 0.0, -50.0], 5, 2)  # f(v_C) ~ 1: right exactly in near environments
    a = tasks.assess(cfg, says_near, 30, seed=2)
    far, near, overall = a.rates
    assert (far.k, near.k, near.n) == (0, near.n, near.n) and far.n + near.n == 30
    assert (overall.k, overall.n, overall.effective_n) == (near.n, 30, 30.0)
    assert overall.rate == a.report["rate"] and a.details["scored_per_chain"] == 1
    assert "independent" in a.method and a.verdict == "fail"


def test_nav1d_clusters_the_trials_of_a_chain() -> None:
    cfg = presets.get("nav1d-single")
    a = tasks.assess(cfg, constant([8.0, -8.0], 8, 2), 20, seed=1)  # always drives right
    overall = a.rates[-1]
    assert a.details == {"objective": "single", "scored_per_chain": 4, "classify_weight": 0.0}
    assert (overall.n, overall.effective_n) == (80, 20.0)  # trials 2-5 of 20 chains
    assert overall.rate == pytest.approx(a.report["rate"])
    assert overall.interval == pytest.approx(stats.wilson(overall.rate * 20, 20))
    assert "clustered by chain" in a.method
    # The clustered interval is wider than one that took the 80 trials as independent.
    lo, hi = stats.wilson(overall.k, 80)
    assert overall.interval[1] - overall.interval[0] > hi - lo


def test_shaped_single_networks_show_their_classifier_by_trial() -> None:
    from pathlib import Path

    from dnnevo.tasks import nav1d as _cli_nav1d

    says_near = constant([8.0, -8.0, -50.0], 8, 2)  # drives right; f(v_C) ~ 1 says near
    plain = presets.get("nav1d-single")
    shaped = presets.get("nav1d-single", overrides=["task_params.classify_weight=0.5"])
    a = tasks.assess(shaped, says_near, 20, seed=1)
    assert a.details["classify_weight"] == 0.5
    lines = _cli_nav1d.preface(Path("run"), a)
    at = next(i for i, line in enumerate(lines) if line.startswith("The classifier"))
    rows = {line.split()[0]: line.split()[2:] for line in lines[at + 2:]}
    assert set(rows["far"]) == {"0.0%"} and set(rows["near"]) == {"100.0%"}
    # The goals, and so the verdict, do not depend on the shaping.
    b = tasks.assess(plain, says_near, 20, seed=1)
    assert a.rates == b.rates
    assert not any(line.startswith("The classifier") for line in _cli_nav1d.preface(Path("run"), b))


def test_scored_trials_follow_the_task() -> None:
    far = {"environment": "far", "goal": "left", "start": 0.0, "landmark": 10.0}
    near = {**far, "environment": "near"}
    ep = {"environment": "far", "conditions": [far, far], "reached": [False, True],
          "classification": [0.2, None]}
    assert nav1d.scored_trials("goal", ep) == [False, True]
    assert nav1d.scored_trials("single", ep) == [True]
    assert nav1d.scored_trials("classify", ep) == [True, False]  # no output (NaN) is wrong
    ep = {**ep, "conditions": [near, near], "classification": [0.5, 0.49]}
    assert nav1d.scored_trials("classify", ep) == [True, False]


def test_defaults_and_bad_input() -> None:
    cfg = presets.get("sequence-1bit")
    net = dnnevo.Network.random(5, 2, seed=0)
    assert tasks.assess(cfg, net, seed=0).trials == tasks.DEFAULT_TRIALS["sequence"]
    with pytest.raises(InvalidArgumentError, match="trials is 0"):
        tasks.assess(cfg, net, 0, seed=0)
    with pytest.raises(ConfigError, match="robot_like applies to landmark"):
        tasks.assess(cfg, net, 5, seed=0, robot_like=True)
    other = dnnevo.EvolutionConfig(task="mine", size=5, n_inputs=2)
    with pytest.raises(ConfigError, match="no success rule"):
        tasks.assess(other, net, 5, seed=0)
    assert set(_cli_assess.EXIT_STATUS.values()) == {0, 1, 3}
    assert math.isclose(tasks.THRESHOLDS["sequence"], 0.9)
