"""Sequence learning (paper §5): trial timings, recorded trials, the success assessment and the
"switch" test, for a network and an :class:`EvolutionConfig` of the ``sequence`` task.

Success rule (from ``crates/tasks/src/sequence/``): on fresh random timings, a network learns a
target when, in at least 90% of trials, every trigger from index ``2 * len(target)`` on is
correct (the mean output over the trigger window is on the target bit's side of 0.5). It
succeeds on B when it learns every target in B.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.tasks._checks import bounded_count, nonnegative, task_params
from dnnevo.config import EvolutionConfig

__all__ = ["SWITCH_AFTER", "SWITCH_HOLD", "Switch", "TrialRecord", "assess", "fresh_timings", "run_trial", "switch_table", "switch_trial",
           "target_list", "timings", "trial_order"]


@dataclass(frozen=True)
class TrialRecord:
    """One trial, time step by time step (arrays of length T, ``outputs`` is (T, N))."""

    target: str
    trigger: npt.NDArray[np.float64]
    reinforcement: npt.NDArray[np.float64]
    output: npt.NDArray[np.float64]
    outputs: npt.NDArray[np.float64]
    targets: npt.NDArray[np.int64]
    """The expected bit of each trigger."""
    r: npt.NDArray[np.float64]
    """The reinforcement earned by each trigger."""
    mean_output: npt.NDArray[np.float64]
    trigger_correct: npt.NDArray[np.bool_]
    final_state: npt.NDArray[np.float64]


def _params(config: EvolutionConfig) -> str:
    return task_params(config, "sequence")


def timings(config: EvolutionConfig, seed: int, generation: int, trial: int) -> list[tuple[int, int]]:
    """The (delay, gap) of each trigger of ``trial`` in ``generation``, as evolution drew them."""
    return _core.sequence_timings(_params(config), seed, generation, trial)


def target_list(config: EvolutionConfig) -> list[str]:
    """The config's targets, such as ``["0", "1"]`` (the task's default when not set)."""
    task_params(config, "sequence")
    return list(config.task_params.get("targets", ["0", "1"]))


def fresh_timings(config: EvolutionConfig, seed: int, trial: int) -> list[tuple[int, int]]:
    """The (delay, gap) of each trigger of fresh trial ``trial``, as :func:`assess` draws them
    for ``seed`` (never those of evolution)."""
    return _core.sequence_fresh_timings(_params(config), nonnegative("seed", seed),
                                        nonnegative("trial", trial))


def trial_order(config: EvolutionConfig, seed: int, generation: int) -> list[int]:
    """The order in which ``generation``'s trials run, as trial numbers (target-major: trial ``t``
    is of target ``t // trials_per_target``). In order, unless ``task_params.chain`` is true:
    then the trials run as one chain without a reset between them, in an order drawn per
    generation."""
    return _core.sequence_trial_order(_params(config), seed, generation)


def run_trial(
    config: EvolutionConfig,
    net: _core.Network,
    pattern: str,
    timing: list[tuple[int, int]],
    *,
    reset: bool = True,
) -> TrialRecord:
    """Runs one trial of ``pattern`` (e.g. ``"01"``); with ``reset=False`` it continues from
    ``net.state``."""
    d: dict[str, Any] = json.loads(
        _core.sequence_trial(_params(config), net, pattern, list(timing), reset)
    )
    return TrialRecord(
        target=d["target"],
        trigger=np.array(d["trigger"]),
        reinforcement=np.array(d["reinforcement"]),
        output=np.array(d["output"]),
        outputs=np.array(d["outputs"]),
        targets=np.array(d["targets"], dtype=np.int64),
        r=np.array(d["r"]),
        mean_output=np.array(d["mean_output"]),
        trigger_correct=np.array(d["trigger_correct"], dtype=bool),
        final_state=np.array(d["final_state"]),
    )


def assess(
    config: EvolutionConfig, net: _core.Network, trials_per_target: int, seed: int
) -> dict[str, Any]:
    """Mean performance and success fraction per target on fresh timings, and the verdict."""
    return json.loads(_core.sequence_assess(_params(config), net, bounded_count("trials_per_target", trials_per_target),
                                            nonnegative("seed", seed)))


SWITCH_AFTER = 8
"""Triggers of the first target before the switch in the switch test, as in the paper's Fig. 5."""


def switch_trial(
    config: EvolutionConfig,
    net: _core.Network,
    first: str,
    second: str,
    timing: list[tuple[int, int]],
    *,
    switch_after: int = SWITCH_AFTER,
) -> tuple[TrialRecord, TrialRecord, int | None]:
    """The paper's Fig. 5 test: ``first`` for ``switch_after`` triggers, then ``second`` without
    a reset. Returns both records and how many triggers after the switch the network needed before
    every later trigger was correct, or None if it never settled: when fewer than
    :data:`SWITCH_HOLD` triggers were right at the end, a last lucky answer is not a switch."""
    a = run_trial(config, net, first, timing[:switch_after])
    cont = net.copy()
    cont.reset(a.final_state)
    b = run_trial(config, cont, _rotate(second, switch_after), timing[switch_after:], reset=False)
    correct = b.trigger_correct
    for k in range(len(correct) - SWITCH_HOLD + 1):
        if correct[k:].all():
            return a, b, k
    return a, b, None


SWITCH_HOLD = 4
"""Triggers a network must get right to the end of a switch trial for the switch to count."""


@dataclass(frozen=True)
class Switch:
    """How a network went from target ``first`` to ``second`` in :func:`switch_table`: for each
    trial, the triggers after the switch it needed before every later trigger was correct
    (``None`` where it never settled)."""

    first: str
    second: str
    settled_after: tuple[int | None, ...]

    @property
    def settled(self) -> int:
        """Trials in which the network settled on ``second``."""
        return sum(k is not None for k in self.settled_after)

    @property
    def median_triggers(self) -> float | None:
        """The median triggers needed over the trials that settled, or None if none did."""
        done = [k for k in self.settled_after if k is not None]
        return float(np.median(done)) if done else None


def switch_table(
    config: EvolutionConfig,
    net: _core.Network,
    trials: int,
    seed: int,
    *,
    switch_after: int = SWITCH_AFTER,
) -> list[Switch]:
    """:func:`switch_trial` for every ordered pair of the config's targets, on ``trials`` fresh
    trials each: trial ``j`` of every pair has the timings of :func:`fresh_timings` ``2j`` and
    ``2j + 1`` one after the other, so every pair meets the same conditions."""
    targets = target_list(config)
    timings = [fresh_timings(config, seed, 2 * j) + fresh_timings(config, seed, 2 * j + 1)
               for j in range(bounded_count("trials", trials))]
    if not 0 < switch_after < len(timings[0]):
        raise ValueError(f"switch_after is {switch_after}; it must lie in 1..{len(timings[0]) - 1}, "
                         "the triggers of two trials")
    return [Switch(a, b, tuple(switch_trial(config, net, a, b, t, switch_after=switch_after)[2]
                               for t in timings))
            for a in targets for b in targets if a != b]


def _rotate(pattern: str, shift: int) -> str:
    """``pattern`` continued from trigger ``shift``, so a switch keeps the sequence's phase."""
    s = shift % len(pattern)
    return pattern[s:] + pattern[:s]
