"""dnnevo.evaluation.stats: Wilson intervals against published values and by their defining property, the
verdict, the trials that would decide, and the censored median with its bootstrap interval."""

from __future__ import annotations

import doctest
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from dnnevo.evaluation import stats
from dnnevo.errors import InvalidArgumentError
from dnnevo.evaluation.stats import Z95, bootstrap_median, censored_median, trials_to_decide, verdict, wilson

INF = math.inf


def test_doctests() -> None:
    assert doctest.testmod(stats).failed == 0


@pytest.mark.parametrize(
    ("k", "n", "lo", "hi"),
    [
        # Newcombe, "Two-sided confidence intervals for the single proportion: comparison of seven
        # methods", Stat. Med. 17 (1998) 857-872, Table I, method 3 (Wilson score, no continuity
        # correction), given to 4 decimals.
        (81, 263, 0.2553, 0.3662),
        (15, 148, 0.0624, 0.1605),
        (0, 20, 0.0000, 0.1611),
        (1, 29, 0.0061, 0.1718),
    ],
)
def test_wilson_matches_newcombe(k: int, n: int, lo: float, hi: float) -> None:
    got = wilson(k, n)
    assert got == pytest.approx((lo, hi), abs=5e-5)


def test_wilson_at_the_ends_by_hand() -> None:
    # k = 0: the interval is [0, z^2 / (n + z^2)]; k = n: [n / (n + z^2), 1]. With z = 1.95996,
    # z^2 = 3.84146, so for n = 10: 3.84146 / 13.84146 = 0.27753 and 10 / 13.84146 = 0.72247.
    assert wilson(0, 10) == (0.0, pytest.approx(0.27753, abs=1e-5))
    assert wilson(10, 10) == (pytest.approx(0.72247, abs=1e-5), 1.0)
    assert wilson(0, 10, z=1.0) == (0.0, pytest.approx(1 / 11))


counts = st.integers(1, 10_000).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n)))


@given(counts)
def test_wilson_bounds_and_score_property(kn: tuple[int, int]) -> None:
    k, n = kn
    p = k / n
    lo, hi = wilson(k, n)
    assert 0.0 <= lo <= p <= hi <= 1.0
    # Each bound not at 0 or 1 is a root of the score equation (p - b)^2 = z^2 b (1 - b) / n.
    for b in (lo, hi):
        if 0.0 < b < 1.0:
            assert (p - b) ** 2 == pytest.approx(Z95**2 * b * (1 - b) / n, rel=1e-6, abs=1e-12)


@given(counts, st.integers(2, 50))
def test_wilson_shrinks_with_n(kn: tuple[int, int], m: int) -> None:
    k, n = kn
    lo, hi = wilson(k, n)
    lo_m, hi_m = wilson(k * m, n * m)
    assert hi_m - lo_m < hi - lo


@given(counts, st.floats(0.01, 0.99))
def test_verdict_reads_the_interval(kn: tuple[int, int], threshold: float) -> None:
    k, n = kn
    lo, hi = wilson(k, n)
    expected = "pass" if lo >= threshold else "fail" if hi < threshold else "undecided"
    assert verdict(k, n, threshold) == expected


def test_verdict_examples() -> None:
    # 73 perfect trials are the fewest that pass 95%: 73 / (73 + z^2) = 0.95001.
    assert verdict(73, 73, 0.95) == "pass" and verdict(72, 72, 0.95) == "undecided"
    assert verdict(0, 73, 0.05) == "fail" and verdict(0, 72, 0.05) == "undecided"
    assert verdict(900, 1000, 0.9) == "undecided"  # the observed rate is the threshold
    assert verdict(950, 1000, 0.9) == "pass" and verdict(850, 1000, 0.9) == "fail"


@given(st.floats(0.0, 1.0), st.floats(0.05, 0.95))
def test_trials_to_decide_is_the_smallest_deciding_n(rate: float, threshold: float) -> None:
    n = trials_to_decide(rate, threshold)
    if rate == threshold:
        assert n is None
        return
    assert n is not None and n >= 1
    assert verdict(rate * n, n, threshold) == ("pass" if rate > threshold else "fail")
    if n > 1:
        assert verdict(rate * (n - 1), n - 1, threshold) == "undecided"


def test_trials_to_decide_examples() -> None:
    assert trials_to_decide(1.0, 0.95) == 73
    assert trials_to_decide(1.0, 0.9) == 35
    assert trials_to_decide(0.9, 0.9) is None
    assert trials_to_decide(0.9 + 1e-12, 0.9) is None       # beyond MAX_TRIALS
    # Closed form: z^2 t (1 - t) / (p - t)^2 = 3.84146 * 0.0475 / 0.0004 = 456.2 -> 457.
    assert trials_to_decide(0.97, 0.95) == 457
    assert trials_to_decide(0.93, 0.95) == 457


@pytest.mark.parametrize(
    ("call", "fragment"),
    [
        (lambda: wilson(11, 10), "k is 11"),
        (lambda: wilson(-1, 10), "k is -1"),
        (lambda: wilson(0, 0), "n is 0"),
        (lambda: wilson(1, math.nan), "n is nan"),
        (lambda: wilson(1, 2, z=0), "z is 0"),
        (lambda: verdict(1, 2, 1.0), "threshold is 1.0"),
        (lambda: trials_to_decide(1.5, 0.9), "rate is 1.5"),
        (lambda: censored_median([]), "non-empty"),
        (lambda: censored_median([1, math.nan]), "NaN"),
        (lambda: bootstrap_median([1, 2], resamples=0), "resamples is 0"),
    ],
)
def test_bad_input_is_a_typed_error(call, fragment: str) -> None:
    with pytest.raises(InvalidArgumentError, match=fragment):
        call()


def test_censored_median_by_hand() -> None:
    assert censored_median([7, 3, 5]) == 5
    assert censored_median([1, 2, 3, INF, INF]) == 3        # 2 of 5 censored
    assert censored_median([2, 4, INF, INF]) == 4           # exactly half censored: reached
    assert censored_median([2, INF, INF, INF]) == INF       # more than half: not reached
    assert censored_median([1, INF, INF]) == INF
    assert censored_median([INF]) == INF


def test_bootstrap_median_by_hand() -> None:
    m = bootstrap_median([5, 5, 5, 5])
    assert (m.median, m.lo, m.hi, m.censored, m.reached) == (5, 5, 5, 0, True)
    # Two of five censored: a resample holds three or more censored values with probability
    # 0.317 > 2.5%, so the upper bound is "not reached"; three or more of {1, 2} (the median
    # drops to 1 or 2) with probability 0.317 too, so the lower bound is 2 at most.
    m = bootstrap_median([1, 2, 3, INF, INF])
    assert m.median == 3 and m.hi == INF and m.lo in (1, 2) and m.censored == 2
    assert bootstrap_median([1, 2, 3, INF, INF]) == m       # fixed seed: reproducible
    assert bootstrap_median([1, 2, 3, INF, INF], seed=1).resamples == stats.BOOTSTRAP_RESAMPLES
    m = bootstrap_median([2, INF, INF, INF])
    assert not m.reached and m.hi == INF


@given(st.lists(st.one_of(st.integers(0, 500).map(float), st.just(INF)), min_size=1, max_size=12))
def test_bootstrap_bounds_are_data_values(values: list[float]) -> None:
    m = bootstrap_median(values, resamples=200)
    assert m.lo in values and m.hi in values and m.lo <= m.hi
    assert m.censored == values.count(INF)
    assert m.reached == (m.censored <= len(values) / 2)


def test_fisher_exact_matches_hand_computed_tables_and_is_symmetric() -> None:
    # [[6, 0], [2, 4]]: of the C(12, 8) = 495 tables with 8 successes, the two as unlikely as
    # this one (6/6 with 2/6, and 2/6 with 6/6) have 15 each.
    assert stats.fisher_exact(6, 6, 2, 6) == pytest.approx(30 / 495, rel=1e-12)
    assert stats.fisher_exact(10, 10, 9, 10) == 1.0
    assert stats.fisher_exact(0, 5, 0, 7) == 1.0
    for k1, n1, k2, n2 in [(9, 10, 6, 10), (3, 8, 7, 9), (0, 10, 10, 10), (4, 4, 0, 12)]:
        p = stats.fisher_exact(k1, n1, k2, n2)
        assert 0 < p <= 1 and p == pytest.approx(stats.fisher_exact(k2, n2, k1, n1), rel=1e-12)
    with pytest.raises(InvalidArgumentError, match="counts 11 of 10"):
        stats.fisher_exact(11, 10, 1, 10)


def test_numpy_counts_are_counts() -> None:
    """A count from a NumPy sum (np.int64) was refused with "k is np.int64(0); it must lie in
    [0, n]", which it did; a bool is still no count."""
    import numpy as np

    from dnnevo.evaluation import stats

    assert stats.wilson(np.int64(3), np.int64(10)) == stats.wilson(3, 10)
    assert stats.wilson(np.float64(2.5), 10) == stats.wilson(2.5, 10)
    with pytest.raises(InvalidArgumentError, match="k is True"):
        stats.wilson(True, 10)
