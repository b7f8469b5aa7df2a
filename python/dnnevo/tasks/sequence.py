"""Sequence learning (paper §5): trial timings, recorded trials, the success assessment and the
"switch" test, for a network and an :class:`EvolutionConfig` of the ``sequence`` task.

Success rule (from ``crates/tasks/src/sequence/``): on fresh random timings, a network learns a
target when, in at least 90% of trials, every trigger from index ``2 * len(target)`` on is
correct (the mean output over the trigger window is on the target bit's side of 0.5). It
succeeds on B when it learns every target in B.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core, plot
from dnnevo._checks import bounded_count, builtin, nonnegative
from dnnevo.config import EvolutionConfig
from dnnevo.evaluation.assessment import INDEPENDENT, Assessment, combine, rate
from dnnevo.runs import RunDir, save_figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["ANALYSIS_CONDITIONS", "DEFAULT_TRIALS", "INPUT_NAMES", "MAIN_INPUT", "OUTPUT_NEURON", "NAME", "ROBOT_LIKE", "SWITCH_AFTER", "SWITCH_HOLD", "SWITCH_TRIALS",
           "THRESHOLD", "UNIT", "Switch", "TrialRecord", "assess", "draw", "assess_extra",
           "extra_lines", "fig5_pair", "fresh_timings", "judge", "overall", "preface",
           "rate_column", "recorded_trials", "run_trial", "switch_lines", "switch_table", "switch_test",
           "switch_trial", "target_list", "timings", "trial_order"]

NAME = "sequence"
"""The task's name in a config."""

THRESHOLD: float = _core.SEQUENCE_SUCCESS_FRACTION
"""The fraction of fresh trials per target that must be right: the core's own number
(``SEQUENCE_SUCCESS_FRACTION`` of the binding)."""

DEFAULT_TRIALS = 1000
"""``dnnevo assess``'s default: trials per target (4000 trials of the 2-bit task take under
half a second on one core)."""

UNIT = "trials per target"
"""What a trial count counts."""

ROBOT_LIKE = False
"""Sequence learning has no robot-like test."""

INPUT_NAMES = ["trigger", "reinforcement"]
"""The network's inputs, in order, as the analysis names them."""

ANALYSIS_CONDITIONS: dict[str, list[float]] = {"off": [0.0, 0.0], "trigger": [1.0, 0.0], "reinforcement": [0.0, 1.0]}
"""The constant input conditions ``dnnevo analyze`` finds the attractors of, by default."""

MAIN_INPUT = 1
"""The input a bifurcation sweep varies by default: the one the task's behaviour turns on."""

OUTPUT_NEURON = 0
"""The neuron whose firing rate is the task's answer (``task_params.classifier`` overrides it)."""


TrialRecord = _core.SequenceRecord
"""One trial, time step by time step, as the core records it (arrays of length T, ``outputs``
is (T, N); ``targets``, ``r``, ``mean_output``, ``trigger_correct`` per trigger;
``final_state``)."""


def _task(config: EvolutionConfig) -> _core.SequenceTask:
    return builtin(config, NAME, _core.SequenceTask)


def timings(config: EvolutionConfig, seed: int, generation: int, trial: int) -> list[tuple[int, int]]:
    """The (delay, gap) of each trigger of ``trial`` in ``generation``, as evolution drew them."""
    return _task(config).timings(seed, generation, trial)


def target_list(config: EvolutionConfig) -> list[str]:
    """The config's targets, such as ``["0", "1"]`` (the task's default when not set)."""
    return list(_task(config).params()["targets"])


def fresh_timings(config: EvolutionConfig, seed: int, trial: int) -> list[tuple[int, int]]:
    """The (delay, gap) of each trigger of fresh trial ``trial``, as :func:`assess` draws them
    for ``seed`` (never those of evolution)."""
    return _task(config).fresh_timings(nonnegative("seed", seed), nonnegative("trial", trial))


def trial_order(config: EvolutionConfig, seed: int, generation: int) -> list[int]:
    """The order in which ``generation``'s trials run, as trial numbers (target-major: trial ``t``
    is of target ``t // trials_per_target``). In order, unless ``task_params.chain`` is true:
    then the trials run as one chain without a reset between them, in an order drawn per
    generation."""
    return _task(config).trial_order(seed, generation)


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
    return _task(config).trial(net, pattern, list(timing), reset)


def assess(
    config: EvolutionConfig, net: _core.Network, trials_per_target: int, seed: int
) -> dict[str, Any]:
    """Mean performance and success fraction per target on fresh timings, and the verdict."""
    return _task(config).assess(net, bounded_count("trials_per_target", trials_per_target),
                                nonnegative("seed", seed))


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


def judge(config: EvolutionConfig, net: _core.Network, trials: int, seed: int, *,
          robot_like: bool = False) -> Assessment:
    """``net`` judged on ``trials`` fresh trials per target drawn from ``seed``: one rate per
    target, each judged against :data:`THRESHOLD`; the run passes when every target passes."""
    report = assess(config, net, trials, seed)
    threshold = THRESHOLD
    rates = [rate(f"{t['target']}*", round(t["success_fraction"] * trials), trials, threshold=threshold)
             for t in report["targets"]]
    return Assessment(
        task="sequence", trials=trials, unit=UNIT, seed=seed, rates=rates,
        verdict=combine([r.verdict for r in rates if r.verdict is not None]), method=INDEPENDENT,
        details={"mean_performance": {t["target"]: t["mean_performance"] for t in report["targets"]}},
        report=report,
    )


SWITCH_TRIALS = 20
"""Fresh trials per ordered pair of targets in ``assess``'s switch test."""


def preface(where: Path, a: Assessment) -> list[str]:
    """What ``assess`` ran, and the rule it judges by."""
    return [
        f"{where}: champion on {a.trials} fresh {a.unit} (seed {a.seed}).",
        "A trial is correct when every trigger from index 2 x len(target) on is. A target passes "
        "when the 95% interval of its rate of correct trials lies at or above 90%, and fails when "
        "it lies below.",
    ]


def switch_test(config: EvolutionConfig, champion: _core.Network, seed: int) -> dict[str, Any]:
    """The paper's Fig. 5 test for every ordered pair of targets, on :data:`SWITCH_TRIALS` fresh
    trials of ``seed`` each: the first target for ``SWITCH_AFTER`` triggers, then the
    second without a reset. ``{"switch_test": {...}}``, or ``{}`` with one target."""
    if len(target_list(config)) < 2:
        return {}
    table = switch_table(config, champion, SWITCH_TRIALS, seed)
    return {"switch_test": {"switch_after": SWITCH_AFTER, "trials": SWITCH_TRIALS, "pairs": [
        {"first": s.first, "second": s.second, "settled": s.settled,
         "median_triggers": s.median_triggers, "settled_after": list(s.settled_after)}
        for s in table]}}


def switch_lines(test: dict[str, Any]) -> list[str]:
    """The switch test as a table: for each pair, the trials that settled on the second target,
    and the median triggers after the switch they needed."""
    pairs = test["pairs"]
    names = list(dict.fromkeys(p["first"] for p in pairs))
    cell = {(p["first"], p["second"]): p for p in pairs}

    def text(p: dict[str, Any]) -> str:
        median = "-" if p["median_triggers"] is None else f"{p['median_triggers']:g}"
        return f"{p['settled']}/{test['trials']} ({median})"

    corner = "from \\ to"
    width = 2 + max(len(corner), *(len(text(p)) for p in pairs), *(len(n) + 1 for n in names))
    lines = [f"switch test: {test['switch_after']} triggers of one target, then another without a "
             f"reset; trials that settled on the new target, right from then on for at least "
             f"{SWITCH_HOLD} triggers (median triggers needed), {test['trials']} fresh "
             "trials each",
             f"{corner:>{width}}" + "".join(f"{n + '*':>{width}}" for n in names)]
    for a in names:
        lines.append(f"{a + '*':>{width}}" + "".join(
            f"{'-' if a == b else text(cell[(a, b)]):>{width}}" for b in names))
    return lines


def fig5_pair(targets: list[str]) -> tuple[str, str]:
    """The two targets of Fig. 5: the paper's (01)* then 0* when the task has both, otherwise the
    last target then the first.

    >>> fig5_pair(["0", "1", "01", "10"])
    ('01', '0')
    >>> fig5_pair(["0", "1"])
    ('1', '0')
    """
    if "01" in targets and "0" in targets:
        return "01", "0"
    return targets[-1], targets[0]


def draw(run: RunDir, config: EvolutionConfig, seed: int, *, animate: bool = False) -> list[str]:
    """``dnnevo plot`` for a ``sequence`` run: Fig. 4 (a trial of each target) and, with two or
    more targets, Fig. 5 (the switch test, on :func:`fig5_pair`)."""

    champion = run.read_best(config, run.read_config()[1])
    targets = target_list(config)
    fig, axes = plot.subplots(len(targets), 1, figsize=(9, 2.6 * len(targets)),
                             layout="constrained", squeeze=False)
    for k, (target, ax) in enumerate(zip(targets, axes[:, 0], strict=True)):
        record = run_trial(config, champion, target, timings(config, seed, 0, k))
        plot_trial(record, ax=ax, title=f"{target}* positive trial")
    save_figure(fig, run.path / "fig4-trials.png")
    plot.close(fig)
    written = ["fig4-trials.png"]
    if len(targets) >= 2:
        first, second = fig5_pair(targets)
        timing = timings(config, seed, 0, 0) + timings(config, seed, 0, 1)
        a, b, needed = switch_trial(config, champion, first, second, timing)
        fig, ax = plot.subplots(figsize=(11, 3), layout="constrained")
        plot_trial(a, ax=ax, follow=b, title=(
            f"{first}* for {SWITCH_AFTER} triggers, then {second}* without reset "
            f"({'settled after ' + str(needed) + ' trigger(s)' if needed is not None else 'never settled'})"))
        save_figure(fig, run.path / "fig5-switch.png")
        plot.close(fig)
        written.append("fig5-switch.png")
    return written


def rate_column(a: Assessment) -> tuple[str, dict[str, str]] | None:
    """The mean trial performance P of each target, beside its rate."""
    return "mean P", {f"{t}*": f"{p:.3f}" for t, p in a.details["mean_performance"].items()}


def overall(a: Assessment) -> str:
    """The verdict line: every target must pass."""
    failing = [r.name for r in a.judged if r.verdict == "fail"]
    open_ = [r.name for r in a.judged if r.verdict == "undecided"]
    why = {"pass": "every target passes",
           "fail": f"{', '.join(failing)} {'fails' if len(failing) == 1 else 'fail'}; every target must pass",
           "undecided": f"no target fails, but {', '.join(open_)} {'is' if len(open_) == 1 else 'are'} undecided"}
    return f"overall: {a.verdict} ({why[a.verdict]})"


def assess_extra(config: EvolutionConfig, champion: _core.Network, seed: int) -> dict[str, Any]:
    """The switch test (:func:`switch_test`)."""
    return switch_test(config, champion, seed)


def extra_lines(extra: dict[str, Any]) -> list[str]:
    """The switch test's table, when it ran."""
    return switch_lines(extra["switch_test"]) if "switch_test" in extra else []


def recorded_trials(config: EvolutionConfig, net: _core.Network, *,
                    seed: int) -> list[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
    """One trial per target drawn from ``seed``, each as (firing rates (T, N), inputs (T, 2):
    trigger and reinforcement), for the dynamical analysis."""
    out = []
    for k, target in enumerate(target_list(config)):
        r = run_trial(config, net, target, timings(config, seed, 0, k))
        out.append((r.outputs, np.column_stack([r.trigger, r.reinforcement])))
    return out


def plot_trial(
    record: TrialRecord,
    ax: Axes | None = None,
    *,
    follow: TrialRecord | None = None,
    title: str | None = None,
) -> Axes:
    """The paper's Fig. 4/5: trigger and reinforcement inputs and the output neuron over time,
    with each trigger's expected bit. ``follow`` appends a second trial run without a reset."""
    ax = plot.axes(ax)
    records = [record] if follow is None else [record, follow]
    trigger = np.concatenate([r.trigger for r in records])
    reinforcement = np.concatenate([r.reinforcement for r in records])
    output = np.concatenate([r.output for r in records])
    t = np.arange(len(output))
    ax.fill_between(t, 0, trigger, step="pre", color="0.85", label="trigger")
    ax.plot(t, reinforcement, drawstyle="steps-pre", color="tab:green", label="reinforcement")
    ax.plot(t, output, color="tab:red", label="output f(v0)")
    ax.axhline(0.5, color="0.5", lw=0.6, ls=":")
    starts = np.flatnonzero(np.diff(np.concatenate([[0.0], trigger])) > 0)
    bits = np.concatenate([r.targets for r in records])
    for s, bit in zip(starts, bits, strict=False):
        ax.text(float(s) + 5, 1.05, str(bit), ha="center", fontsize=8)
    if follow is not None:
        ax.axvline(len(record.output), color="k", lw=0.8, ls="--")
    ax.set_ylim(-0.05, 1.15)
    ax.set_xlim(0, len(t))
    ax.set_xlabel("time step")
    ax.legend(loc="center right", fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return ax
