"""Figures of the analysis: phase portraits with equilibria and cycles, bifurcation diagrams,
lesion tables and basins of attraction. Each draws on ``ax`` (a new figure when None) and returns
the Axes, as :mod:`dnnevo.plot`'s do."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from dnnevo import plot
from dnnevo.analysis.dynamics import Attractors, Bifurcation, vector_field
from dnnevo.analysis.lesions import LesionTable

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from dnnevo._core import Network

__all__ = ["STABILITY_COLORS", "plot_basins", "plot_bifurcation", "plot_lesions", "plot_phase_portrait"]


STABILITY_COLORS = {"stable_node": "tab:blue", "stable_focus": "tab:cyan", "saddle": "tab:orange",
                    "unstable_node": "tab:red", "unstable_focus": "tab:pink", "non_hyperbolic": "0.5"}
"""The colour of each stability class in the analysis figures."""

_MARKERS = "osD^vP*X"


def _sigmoid(x: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    return np.asarray(1.0 / (1.0 + np.exp(-x)))


def plot_phase_portrait(
    attractors: Sequence[Attractors], ax: Axes | None = None, *, net: Network,
    neurons: tuple[int, int] = (0, 1), trajectory: npt.ArrayLike | None = None, title: str | None = None,
) -> Axes:
    """A 2-D projection of the dynamics onto the firing rates of ``neurons``: a real trial's
    ``trajectory`` (firing rates, shape (T, N)) in grey, each input condition's equilibria (one
    marker shape per condition, coloured by stability, filled when stable) and attracting cycles,
    and, for a 2-neuron ``net``, the nullclines of the first condition (solid: neuron i's,
    dashed: neuron j's)."""
    ax = plot.axes(ax)
    Line2D = plot.pyplot().Line2D
    i, j = neurons
    theta = np.asarray(net.theta)
    if trajectory is not None:
        traj = np.asarray(trajectory, dtype=float)
        ax.plot(traj[:, i], traj[:, j], color="0.6", lw=0.7, alpha=0.8, zorder=1)
        ax.plot(traj[0, i], traj[0, j], marker=">", color="0.4", ls="none", zorder=2)
    if net.size == 2 and attractors:
        lo = np.minimum(theta - 12.0, -abs(net.weights).sum(axis=1) - 1.0)
        hi = np.maximum(theta + 12.0, abs(net.weights).sum(axis=1) + 1.0)
        v0, v1 = np.meshgrid(np.linspace(lo[0], hi[0], 300), np.linspace(lo[1], hi[1], 300))
        rate = vector_field(net, attractors[0].input, np.stack([v0, v1], axis=-1))
        x, y = _sigmoid(v0 - theta[0]), _sigmoid(v1 - theta[1])
        if (i, j) == (1, 0):
            x, y = y, x
        ax.contour(x, y, rate[..., i], levels=[0.0], colors="tab:green", linewidths=0.9)
        ax.contour(x, y, rate[..., j], levels=[0.0], colors="tab:purple", linewidths=0.9, linestyles="--")
    handles = []
    if net.size == 2 and attractors:
        first = _condition(attractors[0].label)
        handles += [Line2D([], [], color="tab:green", lw=0.9, label=f"neuron {i}'s nullcline ({first})"),
                    Line2D([], [], color="tab:purple", lw=0.9, ls="--", label=f"neuron {j}'s nullcline ({first})")]
    for k, a in enumerate(attractors):
        marker = _MARKERS[k % len(_MARKERS)]
        # Later conditions' markers are smaller, so that an equilibrium two conditions share
        # shows both markers, one inside the other.
        size = 11.0 * 0.72**k
        for c in a.cycles:
            out = _sigmoid(c.orbit - theta)
            ax.plot(np.append(out[:, i], out[0, i]), np.append(out[:, j], out[0, j]), color="k", lw=1.2,
                    zorder=3)
        for e in a.equilibria:
            color = STABILITY_COLORS[e.stability]
            if k:  # a white ring parts it from an earlier condition's marker beneath
                ax.plot(e.outputs[i], e.outputs[j], marker=marker, ms=size + 1.5, ls="none", zorder=4 + k,
                        color="white")
            ax.plot(e.outputs[i], e.outputs[j], marker=marker, ms=size, ls="none", zorder=4 + k,
                    markeredgecolor=color, markerfacecolor=color if e.stable else "white", markeredgewidth=1.6)
        cyc = f", {len(a.cycles)} cycle{'s' * (len(a.cycles) != 1)}" if a.cycles else ""
        handles.append(Line2D([], [], marker=marker, ls="none", color="0.3", label=f"{_condition(a.label)}{cyc}"))
    seen = {e.stability for a in attractors for e in a.equilibria}
    handles += [Line2D([], [], marker="o", ls="none", color=STABILITY_COLORS[s], label=s.replace("_", " "))
                for s in STABILITY_COLORS if s in seen]
    ax.set_xlim(-0.03, 1.03)
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlabel(f"firing rate of neuron {i}")
    ax.set_ylabel(f"firing rate of neuron {j}")
    ax.legend(handles=handles, loc="best", fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return ax


def _condition(label: str) -> str:
    """A condition's name for a legend: ``input 0,1`` for a label made of the input values (as
    :func:`attractors` makes it), the label itself otherwise (``no input``)."""
    return f"input {label}" if re.fullmatch(r"[-+0-9.e, ]+", label) else label


_CYCLE_COLORS = ["k", "tab:purple", "tab:brown", "tab:olive", "tab:cyan", "tab:pink"]
"""One colour per cycle branch of a bifurcation figure, by id."""


def plot_bifurcation(
    result: Bifurcation, ax: Axes | None = None, *, neuron: int = 0, xlabel: str | None = None,
    title: str | None = None,
) -> Axes:
    """The equilibria's firing rate of ``neuron`` against the swept input, coloured by
    stability; when the sweep searched for cycles, each cycle branch's range of it (lowest to
    highest rate over the orbit) as a band of its own colour, with its ends marked (a star where
    it starts or ends at a Hopf point, a cross where it is lost: a fold of cycles or a homoclinic
    orbit); and the folds (F) and Hopf points (H) marked by dotted lines."""
    ax = plot.axes(ax)
    for s, color in STABILITY_COLORS.items():
        pts = [(v, e.outputs[neuron]) for v, row in zip(result.values, result.equilibria, strict=True)
               for e in row if e.stability == s]
        if pts:
            x, y = np.array(pts).T
            ax.scatter(x, y, s=9, color=color, label=s.replace("_", " "), zorder=3)
    marked: set[str] = set()
    for branch in result.branches:
        color = _CYCLE_COLORS[branch.id % len(_CYCLE_COLORS)]
        pts = [(float(result.values[s]), result.cycles[s][result.cycle_branch[s].index(branch.id)].output_range[neuron])
               for s in range(branch.first, branch.last + 1)]
        x = np.array([v for v, _ in pts])
        lo, hi = np.array([r for _, r in pts]).T
        ax.fill_between(x, lo, hi, color=color, alpha=0.25, lw=0, zorder=1)
        ax.vlines(x[[0, -1]], lo[[0, -1]], hi[[0, -1]], color=color, lw=0.8, zorder=2)
        ax.plot(x, lo, x, hi, color=color, lw=0.8, zorder=2)
        ax.plot([], [], color=color, lw=4, alpha=0.5, label=f"cycle branch {branch.id} (min, max)")
        for end, k in ((branch.start, 0), (branch.end, -1)):
            if end is None:
                continue
            hopf = end.kind == "hopf"
            # A Hopf end sits on its equilibrium; a lost one at the middle of the last range.
            y = next((float(e.outputs[neuron]) for e in result.events
                      if hopf and e.kind == "hopf" and e.value == end.value and e.outputs.size), (lo[k] + hi[k]) / 2)
            label = "cycle ends at a Hopf point" if hopf else "cycle lost (fold of cycles, homoclinic)"
            ax.scatter([end.value], [y], s=40, marker="*" if hopf else "X", color=color,
                       edgecolors="k", linewidths=0.5, zorder=4, label=None if label in marked else label)
            marked.add(label)
    for e in result.events:
        ax.axvline(e.value, color="0.4", lw=0.7, ls=":")
        ax.text(e.value, 1.04, "F" if e.kind == "fold" else "H", ha="center", fontsize=8)
    ax.set_ylim(-0.03, 1.1)
    ax.set_xlim(float(result.values.min()), float(result.values.max()))
    ax.set_xlabel(xlabel or f"input {result.index}")
    ax.set_ylabel(f"firing rate of neuron {neuron} at equilibrium")
    ax.legend(loc="center right", fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return ax


def plot_lesions(table: LesionTable, ax: Axes | None = None, *, title: str | None = None) -> Axes:
    """One bar per lesion: how much the success rate drops (intact minus lesioned); red
    where the lesion changes the verdict."""
    ax = plot.axes(ax)
    names = [x.name for x in table.lesions]
    drops = [x.drop for x in table.lesions]
    colors = ["tab:red" if x.verdict != table.verdict else "tab:blue" for x in table.lesions]
    y = np.arange(len(names))
    ax.barh(y, drops, color=colors)
    ax.set_yticks(y, names, fontsize=7)
    ax.invert_yaxis()
    ax.axvline(0.0, color="k", lw=0.6)
    ax.set_xlabel(f"drop in success rate (intact rate {table.score:.3f}, {table.trials} fresh trials, "
                  f"seed {table.seed})")
    if title:
        ax.set_title(title, fontsize=10)
    return ax


_BASIN_COLORS = ["tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:olive"]


_OUTPUT_COLOR = "tab:red"
"""The neuron's output in :func:`plot_basins`; no input is drawn in it."""
_INPUT_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:gray",
                 "tab:olive", "tab:cyan")
"""The inputs' colours in :func:`plot_basins`: matplotlib's cycle without the output's red."""


def plot_basins(
    outputs: npt.ArrayLike, inputs: Mapping[str, npt.ArrayLike], basins: npt.ArrayLike, ax: Axes | None = None, *,
    labels: Sequence[str], neuron: int = 0, boundaries: Sequence[int] = (), levels: Sequence[float] = (),
    level_label: str = "fold", title: str | None = None,
) -> Axes:
    """A trial over time: the firing rate of ``neuron`` (red) and each input, on a background
    coloured by ``basins[t]``, the index into ``labels`` of the attractor the state at step t
    would settle in if the input were switched off (white where none). ``boundaries`` are the
    steps where a new trial starts; ``levels`` are input values drawn as dotted lines (for example
    the folds of a sweep), labelled ``level_label``."""
    ax = plot.axes(ax)
    b = np.asarray(basins)
    t = np.arange(len(b))
    edges = np.flatnonzero(np.diff(b)) + 1
    for lo, hi in zip(np.concatenate([[0], edges]), np.concatenate([edges, [len(b)]]), strict=True):
        k = int(b[lo])
        if k >= 0:
            ax.axvspan(lo - 0.5, hi - 0.5, color=_BASIN_COLORS[k % len(_BASIN_COLORS)], alpha=0.18, lw=0)
    for k, (name, values) in enumerate(inputs.items()):
        ax.plot(t, np.asarray(values, dtype=float), drawstyle="steps-mid", lw=0.9, label=name,
                color=_INPUT_COLORS[k % len(_INPUT_COLORS)])
    ax.plot(t, np.asarray(outputs, dtype=float)[:, neuron], color=_OUTPUT_COLOR, lw=1.4, label=f"output of neuron {neuron}")
    for x in boundaries:
        ax.axvline(x - 0.5, color="k", lw=0.8, ls="--")
    for k, y in enumerate(levels):
        ax.axhline(y, color="0.3", lw=0.7, ls=":", label=level_label if k == 0 else None)
    handles, _ = ax.get_legend_handles_labels()
    handles += [plot.pyplot().Rectangle((0, 0), 1, 1, color=_BASIN_COLORS[k % len(_BASIN_COLORS)], alpha=0.3, label=f"would settle in {name}")
                for k, name in enumerate(labels)]
    ax.legend(handles=handles, loc="center right", fontsize=7)
    ax.set_xlim(-0.5, len(b) - 0.5)
    ax.set_ylim(-0.05, 1.1)
    ax.set_xlabel("time step")
    if title:
        ax.set_title(title, fontsize=10)
    return ax
