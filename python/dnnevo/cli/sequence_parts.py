"""The ``dnnevo`` command's sequence-learning parts: the first lines of ``evaluate`` and its
switch test, and ``plot`` for ``sequence`` runs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from dnnevo import _core
from dnnevo.tasks import sequence
from dnnevo.evaluation.assessment import Assessment
from dnnevo.config import EvolutionConfig
from dnnevo.runs.rundir import RunDir, save_figure


SWITCH_TRIALS = 20
"""Fresh trials per ordered pair of targets in ``evaluate``'s switch test."""


def preface(where: Path, a: Assessment) -> list[str]:
    """What ``evaluate`` ran, and the rule it judges by."""
    return [
        f"{where}: champion on {a.trials} fresh {a.unit} (seed {a.seed}).",
        "A trial is correct when every trigger from index 2 x len(target) on is. A target passes "
        "when the 95% interval of its rate of correct trials lies at or above 90%, and fails when "
        "it lies below.",
    ]


def switch_test(config: EvolutionConfig, champion: _core.Network, seed: int) -> dict[str, Any]:
    """The paper's Fig. 5 test for every ordered pair of targets, on :data:`SWITCH_TRIALS` fresh
    trials of ``seed`` each: the first target for ``sequence.SWITCH_AFTER`` triggers, then the
    second without a reset. ``{"switch_test": {...}}``, or ``{}`` with one target."""
    if len(sequence.target_list(config)) < 2:
        return {}
    table = sequence.switch_table(config, champion, SWITCH_TRIALS, seed)
    return {"switch_test": {"switch_after": sequence.SWITCH_AFTER, "trials": SWITCH_TRIALS, "pairs": [
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
             f"{sequence.SWITCH_HOLD} triggers (median triggers needed), {test['trials']} fresh "
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


def plot(run: RunDir, config: EvolutionConfig, seed: int) -> list[str]:
    """``dnnevo plot`` for a ``sequence`` run: Fig. 4 (a trial of each target) and, with two or
    more targets, Fig. 5 (the switch test, on :func:`fig5_pair`)."""
    import matplotlib.pyplot as plt

    from dnnevo.plot import plot_sequence_trial

    champion = run.read_best(config, run.read_config()[1])
    targets = sequence.target_list(config)
    fig, axes = plt.subplots(len(targets), 1, figsize=(9, 2.6 * len(targets)),
                             layout="constrained", squeeze=False)
    for k, (target, ax) in enumerate(zip(targets, axes[:, 0], strict=True)):
        record = sequence.run_trial(config, champion, target, sequence.timings(config, seed, 0, k))
        plot_sequence_trial(record, ax=ax, title=f"{target}* positive trial")
    save_figure(fig, run.path / "fig4-trials.png")
    plt.close(fig)
    written = ["fig4-trials.png"]
    if len(targets) >= 2:
        first, second = fig5_pair(targets)
        timing = sequence.timings(config, seed, 0, 0) + sequence.timings(config, seed, 0, 1)
        a, b, needed = sequence.switch_trial(config, champion, first, second, timing)
        fig, ax = plt.subplots(figsize=(11, 3), layout="constrained")
        plot_sequence_trial(a, ax=ax, follow=b, title=(
            f"{first}* for {sequence.SWITCH_AFTER} triggers, then {second}* without reset "
            f"({'settled after ' + str(needed) + ' trigger(s)' if needed is not None else 'never settled'})"))
        save_figure(fig, run.path / "fig5-switch.png")
        plt.close(fig)
        written.append("fig5-switch.png")
    return written
