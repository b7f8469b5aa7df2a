"""Figures. Each function draws on ``ax`` (a new figure when None) and returns the Axes.

matplotlib is imported here only, so ``import dnnevo`` stays light.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from dnnevo.errors import InvalidArgumentError, with_article

if TYPE_CHECKING:
    from matplotlib.axes import Axes


__all__ = ["axes", "close", "columns", "plot_fitness", "plot_fitness_seeds", "plot_paths", "plot_room",
           "plot_traces", "pyplot", "subplots"]


def pyplot() -> Any:
    """matplotlib's pyplot, on the non-interactive Agg backend unless one was chosen. The one
    place dnnevo imports it, and only when a figure is drawn: it takes about half a second, which
    ``import dnnevo`` and every command that draws nothing should not pay."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def subplots(*args: Any, **kwargs: Any) -> Any:
    """``pyplot.subplots(*args, **kwargs)``: a new figure and its Axes."""
    return pyplot().subplots(*args, **kwargs)


def close(fig: Any) -> None:
    """Frees a figure that was saved."""
    pyplot().close(fig)


def axes(ax: Axes | None) -> Axes:
    """``ax``, or the Axes of a new 7 x 4 in figure when None."""
    if ax is not None:
        return ax
    _, ax = subplots(figsize=(7, 4), layout="constrained")
    return ax


def columns(history: Mapping[str, npt.ArrayLike], names: tuple[str, ...]) -> list[npt.NDArray[Any]]:
    """The arrays ``history[name]`` for each of ``names``, as :attr:`EvolutionResult.history
    <dnnevo.EvolutionResult.history>` holds them; a missing one is an
    :class:`~dnnevo.InvalidArgumentError` that lists what is needed.

    >>> columns({"best": [1.0]}, ("generation", "best"))
    Traceback (most recent call last):
    ...
    dnnevo.errors.InvalidArgumentError: history has no 'generation'; it needs the columns generation, best, as EvolutionResult.history has them
    """
    if not isinstance(history, Mapping):
        raise InvalidArgumentError(f"history is {with_article(type(history).__name__)}; expected a mapping of "
                                   "columns, as EvolutionResult.history (result.history) is")
    for name in names:
        if name not in history:
            raise InvalidArgumentError(f"history has no {name!r}; it needs the columns "
                                       f"{', '.join(names)}, as EvolutionResult.history has them")
    return [np.asarray(history[name]) for name in names]


def plot_fitness(
    history: Mapping[str, npt.ArrayLike], ax: Axes | None = None, *, title: str | None = None
) -> Axes:
    """Best and mean fitness over generations, with a ±1 std band around the mean: ``history``
    has the columns generation, best, mean and std (:attr:`dnnevo.EvolutionResult.history`)."""
    ax = axes(ax)
    gen, best, mean, std = columns(history, ("generation", "best", "mean", "std"))
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


def plot_fitness_seeds(
    histories: Mapping[int, Mapping[str, npt.ArrayLike]], ax: Axes | None = None, *, title: str | None = None
) -> Axes:
    """The best fitness over generations of several runs, one line per seed (solid), with each
    run's mean fitness (dotted, same colour): each history has the columns generation, best and
    mean (:attr:`dnnevo.EvolutionResult.history`)."""
    ax = axes(ax)
    for i, (seed, h) in enumerate(sorted(histories.items())):
        gen, best, mean = columns(h, ("generation", "best", "mean"))
        colour = f"C{i % 10}"
        ax.plot(gen, best, color=colour, lw=1.2, label=f"seed {seed}")
        ax.plot(gen, mean, color=colour, lw=0.8, ls=":")
    ax.set_xlabel("generation")
    ax.set_ylabel("fitness (solid: best, dotted: mean)")
    if len(histories) <= 10:
        ax.legend(loc="lower right", fontsize="small")
    if title:
        ax.set_title(title)
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
    out = np.asarray(outputs, dtype=float)
    if out.ndim != 2:
        raise InvalidArgumentError(f"outputs has shape {out.shape}; expected (T, N)")
    series = [(name, np.asarray(v, dtype=float), "tab:green") for name, v in inputs.items()]
    for name, v, _ in series:
        if v.shape != (out.shape[0],):
            raise InvalidArgumentError(f"inputs[{name!r}] has shape {v.shape}; expected ({out.shape[0]},), one "
                                       "value per row of outputs")
    if labels is not None and len(labels) != out.shape[1]:
        raise InvalidArgumentError(f"labels has {len(labels)} names; expected N = {out.shape[1]}, one per neuron")
    ax = axes(ax)
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


def plot_room(world: Mapping[str, Any], ax: Axes | None = None) -> Axes:
    """A 2-D world seen from above: its walls and its boxes (a world as a dict, as
    ``RobotWorld.world`` holds it; docs/worlds.md), with equal scales on both axes, in metres."""
    Rectangle = pyplot().Rectangle  # noqa: N806 - matplotlib's class
    ax = axes(ax)
    w, h = world["room"]
    ax.add_patch(Rectangle((0, 0), w, h, fill=False, lw=2, color="k"))
    for b in world.get("boxes", []):
        (cx, cy), (bw, bh), angle = b["center"], b["size"], b.get("angle_deg", 0.0)
        a = np.deg2rad(angle)
        corner = (cx - 0.5 * (bw * np.cos(a) - bh * np.sin(a)), cy - 0.5 * (bw * np.sin(a) + bh * np.cos(a)))
        ax.add_patch(Rectangle(corner, bw, bh, angle=angle, color="0.45"))
    ax.set_xlim(-0.1, w + 0.1)
    ax.set_ylim(-0.1, h + 0.1)
    ax.set_aspect("equal")
    return ax


def plot_paths(world: Mapping[str, Any], robot: npt.ArrayLike, ax: Axes | None = None, *,
               pursuers: npt.ArrayLike | None = None, title: str | None = None) -> Axes:
    """A robot's path through ``world`` (:func:`plot_room`): ``robot`` holds its poses, (T, 3)
    rows of x, y and heading (or (T, 2) positions), ``pursuers`` theirs, (T, K, 3); a circle
    marks each start and a square each end.

    >>> ax = plot_paths({"room": [4.0, 3.0]}, [[1.0, 1.0, 0.0], [2.0, 1.5, 0.3]])
    >>> print(*(round(float(v), 1) for v in ax.get_xlim()))
    -0.1 4.1
    >>> close(ax.figure)
    """
    path = np.asarray(robot, dtype=float)
    if path.ndim != 2 or path.shape[1] not in (2, 3) or len(path) == 0:
        raise InvalidArgumentError(f"robot has shape {path.shape}; expected (T, 3) poses or (T, 2) "
                                   "positions, T >= 1")
    chasers = np.zeros((len(path), 0, 2)) if pursuers is None else np.asarray(pursuers, dtype=float)
    if chasers.ndim != 3 or chasers.shape[0] != len(path) or chasers.shape[2] < 2:
        raise InvalidArgumentError(f"pursuers has shape {chasers.shape}; expected ({len(path)}, K, 3), "
                                   "one row of poses per robot pose")
    ax = plot_room(world, ax)
    ax.plot(path[:, 0], path[:, 1], color="tab:blue", lw=1.5, label="robot")
    ax.plot(*path[0, :2], "o", color="tab:blue", ms=7)
    ax.plot(*path[-1, :2], "s", color="tab:blue", ms=7)
    for k in range(chasers.shape[1]):
        ax.plot(chasers[:, k, 0], chasers[:, k, 1], color="tab:red", lw=1, ls="--",
                label="pursuers" if k == 0 else None)
        ax.plot(*chasers[0, k, :2], "o", color="tab:red", ms=5)
        ax.plot(*chasers[-1, k, :2], "s", color="tab:red", ms=5)
    if title:
        ax.set_title(title, fontsize=9)
    return ax
