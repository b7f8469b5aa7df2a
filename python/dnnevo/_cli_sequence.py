"""The ``dnnevo`` command's sequence-learning parts: the first lines of ``evaluate`` and its
switch test, and ``plot`` for ``sequence`` runs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from dnnevo import _core, sequence
from dnnevo.assess import Assessment
from dnnevo.config import EvolutionConfig
from dnnevo.rundir import RunDir, save_figure


def _targets(config: EvolutionConfig) -> list[str]:
    return list(config.task_params.get("targets", ["0", "1"]))


def preface(where: Path, a: Assessment) -> list[str]:
    """What ``evaluate`` ran, and the rule it judges by."""
    return [
        f"{where}: champion on {a.trials} fresh {a.unit} (seed {a.seed}).",
        "A trial is correct when every trigger from index 2 x len(target) on is. A target passes "
        "when the 95% interval of its rate of correct trials lies at or above 90%, and fails when "
        "it lies below.",
    ]


def switch_test(config: EvolutionConfig, champion: _core.Network, seed: int) -> dict[str, Any]:
    """The paper's Fig. 5 test on the timings of trials 0 and 1 of ``seed``: the last target for
    8 triggers, then the first without a reset. ``{"switch_test": {...}}``, or ``{}`` with one
    target."""
    targets = _targets(config)
    if len(targets) < 2:
        return {}
    timing = sequence.timings(config, seed, 0, 0) + sequence.timings(config, seed, 0, 1)
    _, _, needed = sequence.switch_trial(config, champion, targets[-1], targets[0], timing)
    return {"switch_test": {"first": targets[-1], "second": targets[0], "switch_after": 8,
                            "settled_after": needed}}


def switch_line(test: dict[str, Any]) -> str:
    """The switch test in words."""
    needed = test["settled_after"]
    after = "never settled" if needed is None else f"settled after {needed} trigger(s)"
    return (f"switch test ({test['first']}* for {test['switch_after']} triggers, then {test['second']}* "
            f"without reset): {after}")


def plot(run: RunDir, config: EvolutionConfig, seed: int) -> list[str]:
    """``dnnevo plot`` for a ``sequence`` run: Fig. 4 (a trial of each target) and, with two or
    more targets, Fig. 5 (the switch test)."""
    import matplotlib.pyplot as plt

    from dnnevo.plot import plot_sequence_trial

    champion = run.read_best(config, run.read_config()[1])
    targets = _targets(config)
    fig, axes = plt.subplots(len(targets), 1, figsize=(9, 2.6 * len(targets)),
                             layout="constrained", squeeze=False)
    for k, (target, ax) in enumerate(zip(targets, axes[:, 0], strict=True)):
        record = sequence.run_trial(config, champion, target, sequence.timings(config, seed, 0, k))
        plot_sequence_trial(record, ax=ax, title=f"{target}* positive trial")
    save_figure(fig, run.path / "fig4-trials.png")
    plt.close(fig)
    written = ["fig4-trials.png"]
    if len(targets) >= 2:
        timing = sequence.timings(config, seed, 0, 0) + sequence.timings(config, seed, 0, 1)
        a, b, needed = sequence.switch_trial(config, champion, targets[-1], targets[0], timing)
        fig, ax = plt.subplots(figsize=(11, 3), layout="constrained")
        plot_sequence_trial(a, ax=ax, follow=b, title=(
            f"{targets[-1]}* for 8 triggers, then {targets[0]}* without reset "
            f"({'settled after ' + str(needed) + ' trigger(s)' if needed is not None else 'never settled'})"))
        save_figure(fig, run.path / "fig5-switch.png")
        plt.close(fig)
        written.append("fig5-switch.png")
    return written
