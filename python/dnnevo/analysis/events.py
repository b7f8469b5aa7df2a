"""Event-aligned views: the moments something happens in recorded trials (:func:`onsets`), a
window of each trial cut out around each moment (:func:`aligned`), and the windows' mean with a
spread drawn against the time from the event (:func:`plot_aligned`). It knows no task: a task's
own view (:attr:`dnnevo.tasks.protocol.Analysis.views`) says what the event is.

>>> import numpy as np
>>> from dnnevo.analysis import events
>>> events.onsets(np.array([1, 1, 0, 0, 0, 1, 0, 1], dtype=bool), quiet=3)
[5]
>>> events.aligned(np.arange(6.0), 1, before=2, after=2).tolist()
[nan, 0.0, 1.0, 2.0, 3.0]
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from dnnevo import plot
from dnnevo._checks import nonnegative
from dnnevo.errors import InvalidArgumentError

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["aligned", "onsets", "plot_aligned"]

_Array = npt.NDArray[np.float64]


def onsets(seen: npt.ArrayLike, *, quiet: int) -> list[int]:
    """The steps at which ``seen`` (one bool per time step) turns true after at least ``quiet``
    steps (and at least one) of false. Steps before the record are not known to be false: a
    record that starts true, or turns true before ``quiet`` steps have passed, has no onset
    there."""
    s = np.asarray(seen, dtype=bool)
    if s.ndim != 1:
        raise InvalidArgumentError(f"seen has shape {s.shape}; expected one value per time step")
    nonnegative("quiet", quiet)
    out, unseen = [], 0
    for t, now in enumerate(s.tolist()):
        if now and unseen >= max(quiet, 1):
            out.append(t)
        unseen = 0 if now else unseen + 1
    return out


def aligned(values: npt.ArrayLike, at: int, *, before: int, after: int) -> _Array:
    """The rows ``at - before .. at + after`` of ``values`` (T, ...), NaN where they fall outside
    the record (a trial that ended, or had not begun): shape (before + after + 1, ...)."""
    v = np.asarray(values, dtype=float)
    nonnegative("before", before)
    nonnegative("after", after)
    out = np.full((before + after + 1, *v.shape[1:]), np.nan)
    lo, hi = max(0, at - before), min(len(v), at + after + 1)
    if lo < hi:
        out[lo - (at - before):hi - (at - before)] = v[lo:hi]
    return out


def plot_aligned(t: npt.ArrayLike, windows: npt.ArrayLike, ax: Axes | None = None, *, label: str | None = None,
                 color: str | None = None, min_count: int = 2) -> Axes:
    """The mean over events of ``windows`` (E, W), one window per event on the time axis ``t``
    (W,), with a band of ±1 standard deviation; steps where fewer than ``min_count`` events
    have a value (the others ended) are left out. A dotted line marks the event (t = 0)."""
    ax = plot.axes(ax)
    w = np.asarray(windows, dtype=float)
    x = np.asarray(t, dtype=float)
    count = np.sum(np.isfinite(w), axis=0)
    keep = count >= max(1, min_count)
    mean, sd = np.full(len(x), np.nan), np.full(len(x), np.nan)
    mean[keep] = np.nanmean(w[:, keep], axis=0)
    sd[keep] = np.nanstd(w[:, keep], axis=0)
    line, = ax.plot(x, mean, color=color, lw=1.4, label=label)
    ax.fill_between(x, mean - sd, mean + sd, color=line.get_color(), alpha=0.18, lw=0)
    ax.axvline(0.0, color="0.3", ls=":", lw=1)
    return ax
