"""Figures. Each function draws on ``ax`` (a new figure when None) and returns the Axes.

matplotlib is imported here only, so ``import dnnevo`` stays light.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from dnnevo.sequence import TrialRecord

__all__ = ["plot_fitness", "plot_sequence_trial"]


def _axes(ax: Axes | None) -> Axes:
    if ax is not None:
        return ax
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    _, ax = plt.subplots(figsize=(7, 4), layout="constrained")
    return ax


def plot_fitness(
    history: Mapping[str, npt.ArrayLike], ax: Axes | None = None, *, title: str | None = None
) -> Axes:
    """Best and mean fitness over generations, with a ±1 std band around the mean."""
    ax = _axes(ax)
    gen = np.asarray(history["generation"])
    best, mean, std = (np.asarray(history[k]) for k in ("best", "mean", "std"))
    ax.fill_between(gen, mean - std, mean + std, color="tab:blue", alpha=0.2, label="mean ± std")
    ax.plot(gen, mean, color="tab:blue", label="mean")
    ax.plot(gen, best, color="tab:red", label="best")
    ax.set_xlabel("generation")
    ax.set_ylabel("fitness")
    ax.set_xlim(gen.min(initial=0), max(gen.max(initial=1), 1))
    ax.legend(loc="lower right")
    if title:
        ax.set_title(title)
    return ax


def plot_sequence_trial(
    record: TrialRecord,
    ax: Axes | None = None,
    *,
    follow: TrialRecord | None = None,
    title: str | None = None,
) -> Axes:
    """The paper's Fig. 4/5: trigger and reinforcement inputs and the output neuron over time,
    with each trigger's expected bit. ``follow`` appends a second trial run without a reset."""
    ax = _axes(ax)
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
        ax.text(s + 5, 1.05, str(bit), ha="center", fontsize=8)
    if follow is not None:
        ax.axvline(len(record.output), color="k", lw=0.8, ls="--")
    ax.set_ylim(-0.05, 1.15)
    ax.set_xlim(0, len(t))
    ax.set_xlabel("time step")
    ax.legend(loc="center right", fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return ax
