"""One assessment for every task: a network judged on fresh conditions, each success rate with
its 95% Wilson interval and a pass / fail / undecided verdict (see :mod:`dnnevo.evaluation.stats`).

This module knows no task. Each task module builds its :class:`Assessment` from its own trials
(``judge`` in :mod:`dnnevo.tasks.sequence`, :mod:`dnnevo.tasks.nav1d`,
:mod:`dnnevo.tasks.landmark`) with :func:`rate` and :func:`combine`, and
:func:`dnnevo.tasks.assess` picks the task of a config. ``dnnevo assess`` prints an assessment
and ``dnnevo sweep`` applies one to every seed's final champion.

>>> r = rate("overall", 97, 100, threshold=0.9)
>>> r.verdict, f"{r.interval[0]:.3f}"
('pass', '0.915')
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from dnnevo.errors import InvalidArgumentError
from dnnevo.evaluation import stats
from dnnevo.evaluation.stats import Verdict

__all__ = ["CONFIDENCE", "INDEPENDENT", "Assessment", "Rate", "combine", "rate", "verdict_line"]

CONFIDENCE = 0.95
"""The confidence level of every interval."""

INDEPENDENT = "Wilson score interval, 95%; trials are independent"
"""The method of an assessment whose trials are independent, in words."""
"""The method of an assessment whose trials are independent, in words."""


@dataclass(frozen=True)
class Rate:
    """One success rate: ``k`` right out of ``n`` trials, with its Wilson interval.

    ``effective_n`` is how many independent observations the interval counts (``n``, or the
    number of chains for clustered nav1d trials). A rate with a ``threshold`` is judged; one
    without (a landmark's own rate) is only shown.
    """

    name: str
    k: int
    n: int
    interval: tuple[float, float]
    effective_n: float
    threshold: float | None = None
    verdict: Verdict | None = None
    trials_to_decide: int | None = None
    """For an undecided rate: the trial count (in the assessment's unit) that would decide it if
    the observed rate held; None otherwise, or when the rate equals the threshold."""

    @property
    def rate(self) -> float:
        """``k / n``."""
        return self.k / self.n

    def to_dict(self) -> dict[str, Any]:
        """The rate as plain JSON types."""
        return {
            "name": self.name, "k": self.k, "n": self.n, "rate": self.rate,
            "interval": list(self.interval), "effective_n": self.effective_n,
            "threshold": self.threshold, "verdict": self.verdict,
            "trials_to_decide": self.trials_to_decide,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Rate:
        """The rate of :meth:`to_dict`, checked; a malformed one raises :class:`ValueError`."""
        k, n = d["k"], d["n"]
        if not (_count(k) and _count(n) and 0 <= k <= n and n > 0):
            raise ValueError(f"rate {d.get('name')!r}: k = {k!r}, n = {n!r} are not counts with 0 <= k <= n")
        if d["verdict"] not in (None, "pass", "fail", "undecided"):
            raise ValueError(f"rate {d.get('name')!r}: unknown verdict {d['verdict']!r}")
        lo, hi = (float(x) for x in d["interval"])
        return cls(str(d["name"]), k, n, (lo, hi), float(d["effective_n"]),
                   None if d["threshold"] is None else float(d["threshold"]), d["verdict"],
                   d["trials_to_decide"])


def _count(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def rate(name: str, k: int, n: int, *, threshold: float | None = None, effective_n: float | None = None,
          per_trial: float = 1.0) -> Rate:
    """A rate; with a ``threshold``, judged. ``per_trial``: effective observations per unit of
    the assessment's trial count (2 for landmark's overall rate: one trial of each landmark)."""
    if n <= 0:
        raise InvalidArgumentError(f"a rate needs at least one trial; {name} has {n}")
    eff = float(n if effective_n is None else effective_n)
    k_eff = k / n * eff
    interval = stats.wilson(k_eff, eff)
    if threshold is None:
        return Rate(name, k, n, interval, eff)
    verdict = stats.verdict(k_eff, eff, threshold)
    needed = None
    if verdict == "undecided":
        observations = stats.trials_to_decide(k / n, threshold)
        if observations is not None:
            needed = math.ceil(observations / per_trial - 1e-9)
    return Rate(name, k, n, interval, eff, threshold, verdict, needed)


def combine(verdicts: Sequence[Verdict]) -> Verdict:
    """The overall verdict of several judged rates: pass when all pass, fail when any fails,
    else undecided.

    >>> combine(["pass", "pass"]), combine(["pass", "undecided", "fail"]), combine(["pass", "undecided"])
    ('pass', 'fail', 'undecided')
    """
    if not verdicts:
        raise InvalidArgumentError("no rates to combine")
    if "fail" in verdicts:
        return "fail"
    return "pass" if all(v == "pass" for v in verdicts) else "undecided"


@dataclass(frozen=True)
class Assessment:
    """A network judged on fresh conditions, in the same shape for every task."""

    task: str
    trials: int
    """The trial count asked for, in :attr:`unit`."""
    unit: str
    seed: int
    rates: list[Rate]
    """Every rate: judged ones (with a verdict) and shown ones."""
    verdict: Verdict
    method: str
    """How the intervals were computed, in words."""
    details: dict[str, Any] = field(default_factory=dict)
    """Task-specific facts: ``mean_performance`` (sequence), ``confusion`` and ``robot_like``
    (landmark), ``objective``, ``scored_per_chain`` and ``classify_weight`` (nav1d)."""
    report: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    """The task's own assessment, as its module returned it (not in :meth:`to_dict`)."""

    @property
    def judged(self) -> list[Rate]:
        """The rates the verdict combines."""
        return [r for r in self.rates if r.verdict is not None]

    @property
    def weakest(self) -> Rate:
        """The judged rate with the lowest lower bound: the one closest to failing."""
        return min(self.judged, key=lambda r: (r.interval[0], r.rate))

    def to_dict(self) -> dict[str, Any]:
        """The assessment as plain JSON types."""
        return {
            "task": self.task, "seed": self.seed, "trials": self.trials, "unit": self.unit,
            "confidence": CONFIDENCE, "method": self.method,
            "rates": [r.to_dict() for r in self.rates], "verdict": self.verdict, **self.details,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Assessment:
        """The assessment of :meth:`to_dict` (without the task's own :attr:`report`), checked; a
        malformed one raises :class:`ValueError`, :class:`KeyError` or :class:`TypeError`."""
        rates = [Rate.from_dict(r) for r in d["rates"]]
        verdict = d["verdict"]
        if not rates or verdict != combine([r.verdict for r in rates if r.verdict is not None] or ["fail"]):
            raise ValueError(f"verdict {verdict!r} does not follow from the rates")
        if not _count(d["trials"]) or not _count(d["seed"]):
            raise ValueError("trials and seed must be integers")
        details = {k: v for k, v in d.items() if k not in _ASSESSMENT_KEYS}
        return cls(task=str(d["task"]), trials=d["trials"], unit=str(d["unit"]), seed=d["seed"],
                   rates=rates, verdict=verdict, method=str(d["method"]), details=details)


_ASSESSMENT_KEYS = ("task", "seed", "trials", "unit", "confidence", "method", "rates", "verdict")


def verdict_line(a: Assessment) -> str:
    """The verdict line of an assessment judged by one overall rate."""
    r = a.judged[0]
    return f"overall: {r.rate:.1%} right; success needs >= {r.threshold:.0%}: {a.verdict}"
