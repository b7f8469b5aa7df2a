"""Single precision against double: each experiment of the ``precision`` family beside the f64
experiment it repeats with ``precision = "f32"``, on the seeds both have done (issue 49). The
results marker ``precision-vs-f64`` stands for this table.

>>> twin(plan.experiment("sequence-1bit-f32")).name
'sequence-1bit'
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence

from dnnevo.evaluation import stats
from dnnevo.experiments import plan, sweep
from dnnevo.experiments.report import done_results, k_of_n
from dnnevo.experiments.scheduler import Outcome

__all__ = ["FAMILY", "HEADER", "twin", "rows"]

FAMILY = plan.PRECISION_FAMILY
"""The family of the f32 experiments."""

HEADER = ("experiment (f64 / f32)", "seeds done by both", "met the rule during the run: f64",
          "f32", "final champions passing on fresh trials: f64", "f32",
          "f64 vs f32, Fisher's exact test, two-sided p (met / passing)")


def twin(e: plan.Experiment) -> plan.Experiment:
    """The f64 experiment that ``e`` (of the ``precision`` family) repeats in f32."""
    return plan.experiment(e.name.removesuffix(plan.F32_SUFFIX))


def rows(order: Sequence[plan.Job], outcomes: dict[str, Outcome]) -> list[tuple[str, ...]]:
    """One row (:data:`HEADER`) per experiment of the family, from the results in ``outcomes``."""
    out: list[tuple[str, ...]] = []
    for e in plan.EXPERIMENTS:
        if e.family != FAMILY:
            continue
        f64 = twin(e)
        double, single = (done_results(x.name, order, outcomes) for x in (f64, e))
        seeds = sorted(double.keys() & single.keys())
        head = (f"{f64.name} / {e.name}", str(len(seeds)) if seeds else "none yet")
        if not seeds:
            out.append((*head, "-", "-", "-", "-", "-"))
        elif e.kind == plan.EVOLVE:
            a, b = (sweep.summarize([sweep.SeedResult.from_dict(done[s]["run"]) for s in seeds])
                    for done in (double, single))
            n = len(seeds)
            p = [stats.fisher_exact(x, n, y, n) for x, y in ((a.succeeded, b.succeeded), (a.passed, b.passed))]
            out.append((*head, k_of_n(a.succeeded, n), k_of_n(b.succeeded, n), k_of_n(a.passed, n),
                        k_of_n(b.passed, n), f"{p[0]:.2f} / {p[1]:.2f}"))
        else:
            rates = [[float(done[s]["goal_rate"]) for s in seeds] for done in (double, single)]
            goal = [f"goal in {statistics.mean(r):.1%} of trials (mean over seeds)" for r in rates]
            out.append((*head, "-", "-", *goal, "-"))
    return out

