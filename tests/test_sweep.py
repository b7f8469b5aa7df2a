"""dnnevo.experiments.sweep: the statistics of a sweep, on hand-made seed results (no runs)."""

from __future__ import annotations

import csv
import doctest
import math

import pytest

from dnnevo.evaluation import assessment as assess
from dnnevo.evaluation import stats
from dnnevo.experiments import sweep
from dnnevo.errors import InvalidArgumentError


def test_doctests() -> None:
    assert doctest.testmod(sweep).failed == 0


def seed_result(seed: int, first_success: int | None, k: int, n: int = 100) -> sweep.SeedResult:
    rate = assess.rate("overall", k, n, threshold=0.95)
    final = assess.Assessment(task="nav1d", trials=n, unit="chains", seed=sweep.eval_seed(seed),
                              rates=[rate], verdict=assess.combine([rate.verdict or "fail"]), method="m")
    return sweep.SeedResult(seed=seed, best_fitness=0.5, best_generation=3, first_success=first_success,
                            last_generation=29, wall_s=1.5, final=final)


def test_summary_counts_censors_and_judges() -> None:
    # Seeds 0-4: successes at generations 4, 9 and 2; seeds 3 and 4 never (censored at 29).
    # Final champions: 100/100 pass, 96/100 undecided, 80/100 fail, 100/100 pass, 50/100 fail.
    runs = [seed_result(0, 4, 100), seed_result(1, 9, 96), seed_result(2, 2, 80),
            seed_result(3, None, 100), seed_result(4, None, 50)]
    s = sweep.summarize(runs)
    assert (s.succeeded, s.seeds, s.success_interval) == (3, 5, stats.wilson(3, 5))
    assert s.first_success.median == 9 and s.first_success.censored == 2   # 3rd of 2, 4, 9, inf, inf
    assert s.first_success == stats.bootstrap_median([4, 9, 2, math.inf, math.inf])
    assert (s.passed, s.verdicts) == (2, {"pass": 2, "fail": 2, "undecided": 1})
    assert s.pass_interval == stats.wilson(2, 5)
    d = s.to_dict()
    assert d["success"] == {"k": 3, "n": 5, "rate": 0.6, "interval": list(stats.wilson(3, 5))}
    assert d["median_first_success"]["median"] == 9 and d["median_first_success"]["interval"][1] is None
    rows = list(csv.DictReader(s.csv_text().splitlines()))
    assert tuple(rows[0]) == sweep.CSV_COLUMNS
    assert [r["seed"] for r in rows] == ["0", "1", "2", "3", "4", "all"]
    assert [r["first_success"] for r in rows[:5]] == ["4", "9", "2", "", ""]
    assert [r["succeeded"] for r in rows[:5]] == ["1", "1", "1", "0", "0"]
    assert [r["final_verdict"] for r in rows[:5]] == ["pass", "undecided", "fail", "pass", "fail"]
    assert rows[1]["eval_seed"] == "1000004" and rows[1]["final_k"] == "96"
    agg = rows[5]
    assert (agg["succeeded"], agg["first_success"], agg["first_success_hi"]) == ("0.6", "9", "not reached")
    assert (agg["final_k"], agg["final_n"], agg["wall_s"]) == ("2", "5", "7.5")


def test_median_not_reached_when_more_than_half_are_censored() -> None:
    s = sweep.summarize([seed_result(0, 4, 100), seed_result(1, None, 100), seed_result(2, None, 100)])
    assert not s.first_success.reached
    assert s.to_dict()["median_first_success"]["median"] is None
    assert list(csv.DictReader(s.csv_text().splitlines()))[-1]["first_success"] == "not reached"


def test_empty_sweep_is_an_error() -> None:
    with pytest.raises(InvalidArgumentError, match="at least one run"):
        sweep.summarize([])


def test_summary_counts_step_artefacts() -> None:
    from dnnevo.evaluation.stepcheck import StepCheck

    runs = [seed_result(0, 4, 100), seed_result(1, 9, 100), seed_result(2, None, 50)]
    fine = [seed_result(s, None, k).final for s, k in ((0, 100), (1, 20), (2, 10))]
    runs = [sweep.SeedResult(**{**vars(r), "step": StepCheck(base=r.final, checks={"dt/10": f},
                                                             integrators={})})
            for r, f in zip(runs, fine)]
    s = sweep.summarize(runs)
    # Seed 1 passes at the run's step and fails at the finer one; seed 2 fails at both.
    assert (s.checked, s.artefacts) == (3, 1)
    assert [r.artefact for r in runs] == [False, True, False]
    assert s.to_dict()["step_artefacts"] == {"k": 1, "n": 3}
    rows = list(csv.DictReader(s.csv_text().splitlines()))
    assert [r["step_artefact"] for r in rows] == ["0", "1", "0", "1"]
    assert [float(r["step_change"]) for r in rows[:3]] == [0.0, 0.8, 0.4]
