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

    from dnnevo.landmark import Record as LandmarkRecord
    from dnnevo.nav1d import Record as Nav1dRecord
    from dnnevo.sequence import TrialRecord

__all__ = ["plot_fitness", "plot_landmark_world", "plot_nav1d_path", "plot_nav1d_traces", "plot_sequence_trial", "plot_traces"]


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


def plot_nav1d_path(
    record: Nav1dRecord,
    ax: Axes | None = None,
    *,
    half_length: float = 20.0,
    landmark_width: float = 4.0,
    title: str | None = None,
) -> Axes:
    """The paper's Fig. 2: the agent's position over time in a chain of trials, with each
    trial's landmark (shaded) and goal (a star at its end) marked, and trial boundaries dashed."""
    ax = _axes(ax)
    t = np.arange(1, len(record.x) + 1)
    x = np.where(record.moving, record.x, np.nan)
    ax.plot(t, x, color="tab:blue", lw=1.4, label="agent x(t)")
    bounds = np.flatnonzero(np.diff(record.trial)) + 1
    edges = np.concatenate([[0], bounds, [len(t)]])
    for k, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        if k >= len(record.conditions):
            break
        c = record.conditions[k]
        ax.fill_between([a, b], c.landmark - landmark_width / 2, c.landmark + landmark_width / 2,
                        color="tab:orange", alpha=0.3, lw=0, label="landmark" if k == 0 else None)
        goal = half_length if c.goal == "right" else -half_length
        reached = k < len(record.reached) and record.reached[k]
        ax.plot([b if reached else a], [goal], marker="*", ms=11, ls="none",
                color="tab:green" if reached else "tab:red",
                label=("goal" if k == 0 else None))
        if k:
            ax.axvline(a, color="k", lw=0.6, ls="--")
    ax.axhline(half_length, color="0.4", lw=0.8)
    ax.axhline(-half_length, color="0.4", lw=0.8)
    ax.set_ylim(-1.1 * half_length, 1.1 * half_length)
    ax.set_xlim(0, len(t))
    ax.set_xlabel("time step")
    ax.set_ylabel("position x")
    ax.legend(loc="lower right", fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return ax


def plot_traces(
    inputs: Mapping[str, npt.ArrayLike],
    outputs: npt.ArrayLike,
    ax: Axes | None = None,
    *,
    labels: list[str] | None = None,
    highlight: int | None = None,
    title: str | None = None,
) -> Axes:
    """Stacked traces in the style of the paper's Figs. 1 and 3: each input, then each neuron's
    firing rate (columns of the (T, N) ``outputs``), one band per trace, all on [0, 1]. The band of
    neuron ``highlight`` gets a 0.5 line."""
    ax = _axes(ax)
    out = np.asarray(outputs, dtype=float)
    series = [(name, np.asarray(v, dtype=float), "tab:green") for name, v in inputs.items()]
    names = labels or [f"neuron {i}" for i in range(out.shape[1])]
    series += [(names[i], out[:, i], "tab:red" if i == highlight else "tab:blue")
               for i in range(out.shape[1])]
    t = np.arange(1, out.shape[0] + 1)
    ticks = []
    for row, (name, y, color) in enumerate(series):
        base = (len(series) - 1 - row) * 1.3
        ax.plot(t, base + y, color=color, lw=1.1)
        ax.axhline(base, color="0.85", lw=0.5)
        if row >= len(inputs) and row - len(inputs) == highlight:
            ax.axhline(base + 0.5, color="0.3", lw=0.7, ls=":")
        ticks.append((base + 0.5, name))
    ax.set_yticks([p for p, _ in ticks], [n for _, n in ticks], fontsize=8)
    ax.set_xlim(0, len(t))
    ax.set_xlabel("time step")
    if title:
        ax.set_title(title, fontsize=10)
    return ax


def plot_nav1d_traces(
    record: Nav1dRecord, ax: Axes | None = None, *, classifier: int = 2,
    motors: tuple[int, int] = (0, 1), title: str | None = None,
) -> Axes:
    """The paper's Fig. 3: landmark and reinforcement inputs and every neuron's output over a
    trial, with the classifier's 0.5 line."""
    n = record.outputs.shape[1]
    labels = [f"neuron {i}" for i in range(n)]
    labels[motors[0]] = f"left motor ({motors[0]})"
    labels[motors[1]] = f"right motor ({motors[1]})"
    if classifier < n:
        labels[classifier] = f"classifier ({classifier})"
    return plot_traces({"landmark": record.landmark, "reinforcement": record.reinforcement},
                       record.outputs, ax, labels=labels, highlight=classifier if classifier < n else None,
                       title=title)


def plot_landmark_world(
    record: LandmarkRecord, ax: Axes | None = None, *, title: str | None = None
) -> Axes:
    """A top-down view of a landmark trial: the room's walls, the boxes, the robot's path (start
    marked) and where the sonar's echoes landed."""
    from matplotlib.patches import Rectangle

    ax = _axes(ax)
    w, h = record.world["room"]
    ax.add_patch(Rectangle((0, 0), w, h, fill=False, lw=2.5, color="0.2"))
    for box in record.world["boxes"]:
        (cx, cy), (sx, sy) = box["center"], box["size"]
        ax.add_patch(Rectangle((cx - sx / 2, cy - sy / 2), sx, sy, angle=box.get("angle_deg", 0.0),
                               rotation_point="center", color="tab:brown", alpha=0.8))
    ax.plot(record.poses[:, 0], record.poses[:, 1], color="tab:blue", lw=1.2, label="robot path")
    ax.plot(*record.poses[0, :2], marker="o", color="tab:blue", ls="none", label="start")
    hit = ~np.isnan(record.echoes[:, 0])
    ax.scatter(record.echoes[hit, 0], record.echoes[hit, 1], s=4, color="tab:red", alpha=0.5,
               label="sonar echoes")
    ax.set_xlim(-0.3, w + 0.3)
    ax.set_ylim(-0.3, h + 0.3)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(loc="upper right", fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return ax
