"""One assessment for every task: a champion judged on fresh conditions, each success rate with
its 95% Wilson interval and a pass / fail / undecided verdict (see :mod:`dnnevo.evaluation.stats`).
``dnnevo evaluate`` prints it and ``dnnevo sweep`` applies it to every seed's final champion.

It wraps each task's own assessment (:func:`dnnevo.tasks.sequence.assess`, :func:`dnnevo.tasks.nav1d.assess`,
:func:`dnnevo.tasks.landmark.assess`), which runs the trials, and judges its counts:

- ``sequence``: one rate per target, the fraction of trials in which every trigger after the
  warm-up was right; threshold 0.9. The run passes when every target passes, fails when any
  target fails, and is undecided otherwise.
- ``landmark``: the fraction of trials classified right over both landmarks; threshold 0.95.
  Each landmark's own rate and interval are shown too, but only the overall rate is judged.
- ``nav1d``: the fraction of scored trials done right; threshold 0.95. Chains are independent,
  but trials within one chain share the network's state, so they are not. With one scored trial
  per chain (``goal``, ``classify``) the interval is over trials. With several (``single``, a
  ``chained`` goal task) the interval counts each chain as one observation: it is the Wilson
  interval of the trial rate with ``n`` = the number of chains, as if every chain's trials were
  all right or all wrong together (design effect = scored trials per chain, the largest it can
  be). That is conservative, never too narrow.

A trial count ``trials`` means what ``dnnevo evaluate --trials`` means: trials per target
(sequence), trials per landmark (landmark) or chains (nav1d); :data:`DEFAULT_TRIALS` holds the
defaults.

>>> import dnnevo
>>> from dnnevo.evaluation import assessment as assess
>>> from dnnevo.experiments import presets
>>> config = presets.get("nav1d-far")
>>> a = assess.assess(config, dnnevo.Network.random(5, 1, seed=0), 50, seed=1)
>>> a.task, a.trials, a.rates[-1].name, a.verdict in ("pass", "fail", "undecided")
('nav1d', 50, 'overall', True)
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from dnnevo import _core
from dnnevo.evaluation import stats
from dnnevo.tasks._checks import nonnegative
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError, InvalidArgumentError
from dnnevo.evaluation.stats import Verdict

__all__ = [
    "CONFIDENCE",
    "DEFAULT_TRIALS",
    "EXIT_STATUS",
    "THRESHOLDS",
    "Assessment",
    "Rate",
    "assess",
    "combine",
    "scored_trials",
]

CONFIDENCE = 0.95
"""The confidence level of every interval."""

THRESHOLDS = {"sequence": 0.9, "landmark": 0.95, "nav1d": 0.95}
"""Each task's success threshold: the rate its rule needs (``SUCCESS_FRACTION`` in
``crates/tasks/src/sequence/scoring.rs``, ``SUCCESS_RATE`` in ``nav1d/task.rs`` and ``landmark/task.rs``)."""

DEFAULT_TRIALS = {"sequence": 1000, "landmark": 500, "nav1d": 1000}
"""``dnnevo evaluate``'s default trial counts: trials per target, trials per landmark, chains.
On one core a sequence or nav1d assessment takes under half a second (the 2-bit task's 4000
trials 0.45 s, nav1d's slowest 0.2 s); landmark's 1000 robot trials take 1.2-1.7 s (about 1.5 ms
each)."""

UNITS = {"sequence": "trials per target", "landmark": "trials per landmark", "nav1d": "chains"}
"""What a trial count counts, per task."""

EXIT_STATUS: dict[Verdict, int] = {"pass": 0, "fail": 1, "undecided": 3}
"""``dnnevo evaluate``'s exit status per verdict (2 is a usage or input error, 130 Ctrl-C)."""


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


def _rate(name: str, k: int, n: int, *, threshold: float | None = None, effective_n: float | None = None,
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


def assess(
    config: EvolutionConfig, net: _core.Network, trials: int | None = None, *, seed: int,
    robot_like: bool = False,
) -> Assessment:
    """Judges ``net`` on fresh conditions drawn from ``seed``: ``trials`` per target, per
    landmark or chains (default :data:`DEFAULT_TRIALS`). ``robot_like`` applies to landmark
    runs only."""
    if config.task not in THRESHOLDS:
        raise ConfigError(f"task {config.task!r} has no success rule to judge; tasks with one: "
                          f"{', '.join(sorted(THRESHOLDS))}")
    if robot_like and config.task != "landmark":
        raise ConfigError(f"robot_like applies to landmark runs; this is a {config.task} run")
    nonnegative("seed", seed)
    if trials is None:
        trials = DEFAULT_TRIALS[config.task]
    if not isinstance(trials, int) or isinstance(trials, bool) or trials < 1:
        raise InvalidArgumentError(f"trials is {trials!r}; it must be an integer >= 1")
    if config.task == "sequence":
        return _sequence(config, net, trials, seed)
    if config.task == "landmark":
        return _landmark(config, net, trials, seed, robot_like)
    return _nav1d(config, net, trials, seed)


_INDEPENDENT = "Wilson score interval, 95%; trials are independent"


def _sequence(config: EvolutionConfig, net: _core.Network, trials: int, seed: int) -> Assessment:
    from dnnevo.tasks import sequence

    report = sequence.assess(config, net, trials, seed)
    threshold = THRESHOLDS["sequence"]
    rates = [_rate(f"{t['target']}*", round(t["success_fraction"] * trials), trials, threshold=threshold)
             for t in report["targets"]]
    return Assessment(
        task="sequence", trials=trials, unit=UNITS["sequence"], seed=seed, rates=rates,
        verdict=combine([r.verdict for r in rates if r.verdict is not None]), method=_INDEPENDENT,
        details={"mean_performance": {t["target"]: t["mean_performance"] for t in report["targets"]}},
        report=report,
    )


def _landmark(config: EvolutionConfig, net: _core.Network, trials: int, seed: int, robot_like: bool) -> Assessment:
    from dnnevo.tasks import landmark

    report = landmark.assess(config, net, trials, seed, robot_like=robot_like)
    (a, b), (c, d) = report["confusion"]
    overall = _rate("overall", a + d, a + b + c + d, threshold=THRESHOLDS["landmark"], per_trial=2.0)
    rates = [_rate("landmark 1", a, a + b), _rate("landmark 2", d, c + d), overall]
    return Assessment(
        task="landmark", trials=trials, unit=UNITS["landmark"], seed=seed, rates=rates,
        verdict=combine([r.verdict for r in rates if r.verdict is not None]),
        method=_INDEPENDENT + "; only the overall rate is judged",
        details={"confusion": report["confusion"], "robot_like": robot_like}, report=report,
    )


def scored_trials(objective: str, episode: dict[str, Any]) -> list[bool]:
    """Whether each scored trial of a nav1d chain was done right, as the task judges it: the
    goal reached (``goal``; trials 2.. with ``single``) or the environment classified right
    (``classify``: ``f(v_C) >= 0.5`` exactly in landmark-near environments)."""
    out = []
    for t, (condition, reached, f) in enumerate(
        zip(episode["conditions"], episode["reached"], episode["classification"], strict=True)
    ):
        if objective == "single" and t == 0:
            continue
        if objective == "classify":
            f = math.nan if f is None else f
            out.append(f >= 0.5 if condition["environment"] == "near" else f < 0.5)
        else:
            out.append(bool(reached))
    return out


def _nav1d(config: EvolutionConfig, net: _core.Network, trials: int, seed: int) -> Assessment:
    from dnnevo.tasks import nav1d

    report = nav1d.assess(config, net, trials, seed)
    objective = report["objective"]
    scored = [(e["environment"], scored_trials(objective, e)) for e in report["episodes"]]
    per_chain = max(len(s) for _, s in scored)
    if any(len(s) != per_chain for _, s in scored) or per_chain == 0:
        raise ConfigError(f"the nav1d chains score {sorted({len(s) for _, s in scored})} trials each; "
                          "judging needs the same number >= 1 in every chain")
    clustered = per_chain > 1

    def rate(name: str, chains: list[list[bool]], threshold: float | None = None) -> Rate:
        k, n = sum(map(sum, chains)), per_chain * len(chains)
        return _rate(name, k, n, threshold=threshold, effective_n=len(chains) if clustered else n)

    rates = [rate(env, [s for e, s in scored if e == env]) for env in ("far", "near")
             if any(e == env for e, _ in scored)]
    overall = rate("overall", [s for _, s in scored], THRESHOLDS["nav1d"])
    if abs(overall.rate - report["rate"]) > 1e-12:
        raise RuntimeError(f"nav1d: the scored trials give {overall.rate} but the task's rate is "
                          f"{report['rate']}; dnnevo.evaluation.assessment and the task disagree on what is scored")
    method = (f"Wilson score interval, 95%, clustered by chain: the {per_chain} scored trials of a "
              "chain share the network's state, so each chain counts as one observation (the "
              "worst case; never too narrow)" if clustered
              else _INDEPENDENT + " (one scored trial per chain, each from a reset state)")
    return Assessment(
        task="nav1d", trials=trials, unit=UNITS["nav1d"], seed=seed, rates=[*rates, overall],
        verdict=combine([r.verdict for r in [overall] if r.verdict is not None]), method=method,
        details={"objective": objective, "scored_per_chain": per_chain,
                 "classify_weight": float(config.task_json().get("classify_weight", 0.0))}, report=report,
    )
