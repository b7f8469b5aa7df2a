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

__all__ = ["plot_fitness"]


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
