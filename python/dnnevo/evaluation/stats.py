"""The statistics behind ``dnnevo assess`` and ``dnnevo sweep``: Wilson score intervals for
success rates, the pass / fail / undecided verdict against a task's threshold, how many trials
would decide an undecided verdict, and a bootstrap interval for the median first-success
generation with censored runs.

A rate ``k/n`` gets the 95% Wilson score interval (Wilson 1927; method 3 of Newcombe 1998): the
set of true rates ``p`` that a score test at the 5% level does not reject,
``|k/n - p| <= z sqrt(p (1 - p) / n)``. Unlike ``k/n ± z sqrt(...)`` it stays inside [0, 1] and is
not degenerate at ``k = 0`` or ``k = n``.

>>> lo, hi = wilson(81, 263)             # Newcombe (1998), Table I: 0.2553 to 0.3662
>>> round(lo, 4), round(hi, 4)
(0.2553, 0.3662)
>>> verdict(200, 200, 0.95), verdict(180, 200, 0.95), verdict(190, 200, 0.95)
('pass', 'fail', 'undecided')
>>> trials_to_decide(0.97, 0.95)         # if 97% holds, 457 trials put 95% below the interval
457
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from dnnevo.errors import InvalidArgumentError

__all__ = [
    "fisher_exact",
    "BOOTSTRAP_RESAMPLES",
    "BOOTSTRAP_SEED",
    "MAX_TRIALS",
    "Z95",
    "Median",
    "Verdict",
    "bootstrap_median",
    "censored_median",
    "trials_to_decide",
    "verdict",
    "wilson",
]

Z95 = 1.959963984540054
"""The standard normal quantile of 0.975: a two-sided 95% interval."""

MAX_TRIALS = 10**15
"""The most trials :func:`trials_to_decide` will name."""

BOOTSTRAP_RESAMPLES = 10_000
"""Resamples :func:`bootstrap_median` draws by default."""

BOOTSTRAP_SEED = 20_240_611
"""The fixed seed of :func:`bootstrap_median`, so a summary is the same every time it is made."""

Verdict = Literal["pass", "fail", "undecided"]
"""``"pass"``: the interval lies at or above the threshold; ``"fail"``: it lies below;
``"undecided"``: it straddles the threshold."""


def _real(x: object) -> bool:
    """Whether ``x`` is a real number, Python's or NumPy's (a count from ``ok.sum()``), and not a
    bool."""
    return isinstance(x, numbers.Real) and not isinstance(x, bool | np.bool_)


def _check_counts(k: float, n: float) -> tuple[float, float]:
    if not (_real(n) and math.isfinite(n) and n > 0):
        raise InvalidArgumentError(f"n is {n!r}; a rate needs n > 0 trials")
    if not (_real(k) and math.isfinite(k) and 0 <= k <= n):
        raise InvalidArgumentError(f"k is {k!r}; it must lie in [0, n] = [0, {n}]")
    return float(k), float(n)


def _check_unit(name: str, value: float, *, open_ends: bool) -> float:
    ok = _real(value) and (0 < value < 1 if open_ends else 0 <= value <= 1)
    if not ok:
        allowed = "(0, 1)" if open_ends else "[0, 1]"
        raise InvalidArgumentError(f"{name} is {value!r}; it must lie in {allowed}")
    return float(value)


def _check_z(z: float) -> float:
    if not (_real(z) and math.isfinite(z) and z > 0):
        raise InvalidArgumentError(f"z is {z!r}; it must be a positive number such as 1.96")
    return float(z)


def wilson(k: float, n: float, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval ``(lo, hi)`` of ``k`` successes in ``n`` trials; 95% by
    default. ``k`` may be fractional (an effective count, see :mod:`dnnevo.evaluation.assessment`).

    >>> wilson(0, 10)                        # hi = z^2 / (n + z^2)
    (0.0, 0.2775327998628892)
    >>> round(wilson(10, 10)[0], 6)          # lo = n / (n + z^2)
    0.722467
    """
    k, n = _check_counts(k, n)
    z = _check_z(z)
    # The roots of (k/n - p)^2 = z^2 p (1 - p) / n, written without cancellation at k = 0 or n.
    centre = 2 * k + z * z
    spread = z * math.sqrt(z * z + 4 * k * (n - k) / n)
    denominator = 2 * (n + z * z)
    p = k / n
    lo = 0.0 if k == 0 else min(max((centre - spread) / denominator, 0.0), p)
    hi = 1.0 if k == n else max(min((centre + spread) / denominator, 1.0), p)
    return lo, hi


def fisher_exact(k1: int, n1: int, k2: int, n2: int) -> float:
    """The two-sided p-value of Fisher's exact test that ``k1`` successes of ``n1`` and ``k2`` of
    ``n2`` come from one rate: the probability, given the margins, of a table at most as likely
    as the one seen (with a relative tolerance of 1e-7 for ties, as R and SciPy).

    >>> round(fisher_exact(9, 10, 6, 10), 4)
    0.3034
    >>> fisher_exact(10, 10, 9, 10)
    1.0
    """
    for k, n in ((k1, n1), (k2, n2)):
        if not (isinstance(k, int) and isinstance(n, int) and 0 <= k <= n and n >= 1):
            raise InvalidArgumentError(f"counts {k} of {n}: expected whole numbers with 0 <= k <= n, n >= 1")
    total = k1 + k2
    whole = math.comb(n1 + n2, total)

    def chance(k: int) -> float:
        return math.comb(n1, k) * math.comb(n2, total - k) / whole

    seen = chance(k1)
    tables = range(max(0, total - n2), min(n1, total) + 1)
    return min(1.0, sum(c for k in tables if (c := chance(k)) <= seen * (1 + 1e-7)))


def verdict(k: float, n: float, threshold: float, z: float = Z95) -> Verdict:
    """Judges the rate ``k/n`` against a success rule "rate >= ``threshold``": ``"pass"`` when
    the whole Wilson interval is at or above ``threshold``, ``"fail"`` when it is below, else
    ``"undecided"``.

    >>> verdict(35, 35, 0.9), verdict(34, 34, 0.9)   # 35 perfect trials are needed for 90%
    ('pass', 'undecided')
    """
    threshold = _check_unit("threshold", threshold, open_ends=True)
    lo, hi = wilson(k, n, z)
    if lo >= threshold:
        return "pass"
    if hi < threshold:
        return "fail"
    return "undecided"


def trials_to_decide(rate: float, threshold: float, z: float = Z95) -> int | None:
    """The smallest number of trials ``n`` whose Wilson interval around ``rate`` (``k = rate *
    n``) no longer straddles ``threshold``, assuming the observed rate holds; None when ``rate ==
    threshold``, which no number of trials decides (or when it would take :data:`MAX_TRIALS` or
    more).

    The threshold is outside the interval exactly when ``n (rate - threshold)^2 >= z^2 t (1 - t)``
    (strictly ``>`` on the fail side), so ``n`` comes in closed form and is checked against
    :func:`verdict`.

    >>> trials_to_decide(1.0, 0.95), trials_to_decide(0.97, 0.95), trials_to_decide(0.95, 0.95)
    (73, 457, None)
    """
    rate = _check_unit("rate", rate, open_ends=False)
    threshold = _check_unit("threshold", threshold, open_ends=True)
    z = _check_z(z)
    if rate == threshold:
        return None
    bound = z * z * threshold * (1 - threshold) / (rate - threshold) ** 2
    if not bound < MAX_TRIALS:
        return None
    n = max(1, math.ceil(bound))
    # Rounding can put the closed form one off; the verdict is monotone in n, so step to it.
    while n > 1 and verdict(rate * (n - 1), n - 1, threshold, z) != "undecided":
        n -= 1
    while verdict(rate * n, n, threshold, z) == "undecided":
        n += 1
    return n


@dataclass(frozen=True)
class Median:
    """A median with a bootstrap interval; ``math.inf`` stands for "not reached"."""

    median: float
    lo: float
    hi: float
    censored: int
    """How many values were censored (``math.inf``)."""
    count: int
    resamples: int
    seed: int

    @property
    def reached(self) -> bool:
        """False when more than half the values are censored, so the median is unknown."""
        return math.isfinite(self.median)


def _values(values: Sequence[float]) -> npt.NDArray[np.float64]:
    a = np.asarray(values, dtype=float)
    if a.ndim != 1 or a.size == 0:
        raise InvalidArgumentError(f"values has shape {a.shape}; a median needs a non-empty list")
    if np.isnan(a).any() or (a == -np.inf).any():
        raise InvalidArgumentError("values holds NaN or -inf; use math.inf for a censored value")
    return a


def censored_median(values: Sequence[float]) -> float:
    """The median of ``values`` with censored ones given as ``math.inf``: the smallest value
    that at least half of them are at or below (the survival-analysis median; for an even count
    the lower of the two middle values). ``math.inf`` when more than half are censored.

    >>> censored_median([3, 1, 2, 8]), censored_median([5, math.inf, math.inf])
    (2.0, inf)
    """
    return _lower_median(np.sort(_values(values)))


def _lower_median(ordered: npt.NDArray[np.float64]) -> float:
    """The ceil(n/2)-th smallest of the sorted ``ordered``."""
    return float(ordered[(ordered.size + 1) // 2 - 1])


def bootstrap_median(
    values: Sequence[float],
    *,
    level: float = 0.95,
    resamples: int = BOOTSTRAP_RESAMPLES,
    seed: int = BOOTSTRAP_SEED,
) -> Median:
    """:func:`censored_median` of ``values`` with a percentile bootstrap interval: ``resamples``
    resamples with replacement drawn from a generator seeded with ``seed``, so the interval is
    reproducible. Censored values (``math.inf``) stay censored in every resample, so a bound can
    be ``math.inf`` ("not reached").

    >>> m = bootstrap_median([4, 6, 7, 9, 12, math.inf])
    >>> m.median, m.censored, m.lo <= m.median <= m.hi
    (7.0, 1, True)
    """
    a = _values(values)
    level = _check_unit("level", level, open_ends=True)
    if not isinstance(resamples, int) or isinstance(resamples, bool) or resamples < 1:
        raise InvalidArgumentError(f"resamples is {resamples!r}; it must be an integer >= 1")
    rng = np.random.default_rng(seed)
    draws = np.sort(a[rng.integers(0, a.size, size=(resamples, a.size))], axis=1)
    medians = np.sort(draws[:, (a.size + 1) // 2 - 1])
    tail = (1 - level) / 2
    lo = medians[min(int(math.floor(tail * resamples)), resamples - 1)]
    hi = medians[max(int(math.ceil((1 - tail) * resamples)) - 1, 0)]
    return Median(median=_lower_median(np.sort(a)), lo=float(lo), hi=float(hi),
                  censored=int(np.isinf(a).sum()), count=int(a.size), resamples=resamples, seed=seed)
