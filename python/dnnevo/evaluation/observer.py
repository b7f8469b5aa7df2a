"""Bounds for a classifier of one input stream: simple features of the stream, the best
single-threshold rule on one of them (a lower bound a network should beat) and logistic regression
on all of them (an observer that sees the whole trial, an upper reference). For trials drawn from
several conditions at once, a stream's :func:`profile` (its features, distribution and time
course) and the nearest fitted trial (:func:`fit_nearest`) ask whether any rule, not only a linear
one, tells the classes apart in every condition. NumPy only.

Both are fitted on one set of trials and judged on another: :func:`fit_threshold` and
:func:`fit_logistic` see only the fitting set's features and labels.

>>> import numpy as np
>>> x = np.array([[0.0], [1.0], [2.0], [3.0]]); y = np.array([0, 0, 1, 1])
>>> rule = fit_threshold(x, y)
>>> rule.predict(x).tolist(), rule.feature, rule.threshold
([0, 0, 1, 1], 0, 1.5)
>>> model = fit_logistic(x, y)
>>> model.predict(np.array([[0.2], [2.8]])).tolist()
[0, 1]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

__all__ = ["FEATURES", "Logistic", "Nearest", "Threshold", "features", "fit_logistic", "fit_nearest",
           "fit_threshold", "profile"]

FEATURES = ["mean", "sd", "max", "fraction near", "near episodes", "longest near run",
            "mean near run"]
"""The names of :func:`features`' columns, in order."""


def features(stream: npt.ArrayLike, near: float) -> npt.NDArray[np.float64]:
    """The features of one trial's input ``stream`` (length T), in :data:`FEATURES`' order: its
    mean, standard deviation and maximum, the fraction of steps above ``near``, the number of
    episodes above it (runs of consecutive steps), the longest and the mean run, in steps (0 when
    there is none).

    >>> features([0, 1, 1, 0, 1, 0], 0.5).tolist()
    [0.5, 0.5, 1.0, 0.5, 2.0, 2.0, 1.5]
    """
    x = np.asarray(stream, dtype=float)
    above = np.concatenate([[False], x > near, [False]])
    edges = np.flatnonzero(np.diff(above.astype(np.int8)))
    runs = edges[1::2] - edges[0::2]
    return np.array([x.mean(), x.std(), x.max(), (x > near).mean(), len(runs),
                     runs.max() if len(runs) else 0.0, runs.mean() if len(runs) else 0.0])


@dataclass(frozen=True)
class Threshold:
    """``label = 1`` when ``sign * (x[feature] - threshold) > 0``, else 0."""

    feature: int
    threshold: float
    sign: int

    def predict(self, x: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """The labels of the rows of ``x`` (n, features)."""
        column = np.asarray(x, dtype=float)[:, self.feature]
        return (self.sign * (column - self.threshold) > 0).astype(np.int64)


def fit_threshold(x: npt.ArrayLike, y: npt.ArrayLike, columns: list[int] | None = None) -> Threshold:
    """The single-feature rule (over ``columns``, default all) with the fewest errors on ``x``
    (n, features) and labels ``y`` (0 or 1): thresholds halfway between neighbouring values, both
    directions; ties go to the first column, the lower threshold and the sign +1."""
    x, y = np.asarray(x, dtype=float), np.asarray(y).astype(np.int64)
    best: tuple[int, Threshold] | None = None
    for j in range(x.shape[1]) if columns is None else columns:
        values = np.unique(x[:, j])
        cuts = (values[:-1] + values[1:]) / 2 if len(values) > 1 else values
        for cut in cuts:
            for sign in (1, -1):
                rule = Threshold(j, float(cut), sign)
                errors = int(np.sum(rule.predict(x) != y))
                if best is None or errors < best[0]:
                    best = (errors, rule)
    assert best is not None, "x has no columns"
    return best[1]


@dataclass(frozen=True)
class Logistic:
    """Logistic regression on standardized features: ``P(label 1) = sigmoid(w . (x - mu) / sd + b)``."""

    mu: npt.NDArray[np.float64]
    sd: npt.NDArray[np.float64]
    w: npt.NDArray[np.float64]
    b: float

    def probability(self, x: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """P(label 1) for each row of ``x``."""
        z = (np.asarray(x, dtype=float) - self.mu) / self.sd @ self.w + self.b
        return 1.0 / (1.0 + np.exp(-np.clip(z, -500, 500)))

    def predict(self, x: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """The labels of the rows of ``x``: 1 where P(label 1) > 0.5."""
        return (self.probability(x) > 0.5).astype(np.int64)


def fit_logistic(x: npt.ArrayLike, y: npt.ArrayLike, *, ridge: float = 1e-2, steps: int = 50) -> Logistic:
    """Logistic regression of ``y`` (0 or 1) on the columns of ``x`` (n, features), fitted by
    Newton's method on the mean log-loss plus ``ridge / 2`` times the squared weights (not the
    bias), which keeps the weights finite when the classes separate. Columns are standardized on
    ``x`` first (a constant column is left at 0)."""
    x, t = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    mu, sd = x.mean(axis=0), x.std(axis=0)
    sd = np.where(sd > 0, sd, 1.0)
    z = np.column_stack([(x - mu) / sd, np.ones(len(x))])
    beta = np.zeros(z.shape[1])
    penalty = np.full(z.shape[1], ridge)
    penalty[-1] = 0.0
    for _ in range(steps):
        p = 1.0 / (1.0 + np.exp(-np.clip(z @ beta, -500, 500)))
        grad = z.T @ (p - t) / len(t) + penalty * beta
        hess = (z.T * (p * (1 - p))) @ z / len(t) + np.diag(penalty) + 1e-9 * np.eye(len(beta))
        step = np.linalg.solve(hess, grad)
        beta -= step
        if np.max(np.abs(step)) < 1e-10:
            break
    return Logistic(mu, sd, beta[:-1], float(beta[-1]))


PROFILE_QUANTILES = 33
"""Quantiles of the stream in :func:`profile` (its minimum, maximum and 31 between)."""
PROFILE_BINS = 24
"""Equal time bins of the stream in :func:`profile`."""


def profile(stream: npt.ArrayLike, near: float) -> npt.NDArray[np.float64]:
    """A fuller description of one trial's ``stream`` than :func:`features`: those features, the
    stream's :data:`PROFILE_QUANTILES` quantiles (its distribution, whatever its timing) and its
    mean in :data:`PROFILE_BINS` equal time bins (its time course).

    >>> profile(np.arange(48.0), 10.0).shape
    (64,)
    """
    x = np.asarray(stream, dtype=float)
    if x.ndim != 1 or len(x) < PROFILE_BINS:
        raise ValueError(f"the stream has shape {x.shape}; a profile needs one stream of at least "
                         f"{PROFILE_BINS} steps, one per time bin")
    quantiles = np.quantile(x, np.linspace(0.0, 1.0, PROFILE_QUANTILES))
    course = np.array([part.mean() for part in np.array_split(x, PROFILE_BINS)])
    return np.concatenate([features(x, near), quantiles, course])


NEAREST_CHUNK = 16
"""Rows whose distances :meth:`Nearest.predict` computes at once (memory: this many times the
fitted rows times the features)."""


@dataclass(frozen=True)
class Nearest:
    """The label of the nearest fitted trial, in features standardized on the fitted ones."""

    mu: npt.NDArray[np.float64]
    sd: npt.NDArray[np.float64]
    z: npt.NDArray[np.float64]
    y: npt.NDArray[np.int64]

    def predict(self, x: npt.ArrayLike) -> npt.NDArray[np.int64]:
        """The labels of the rows of ``x``: each the label of its nearest fitted row (the first
        of equally near ones)."""
        z = (np.asarray(x, dtype=float) - self.mu) / self.sd
        labels = np.empty(len(z), dtype=np.int64)
        for start in range(0, len(z), NEAREST_CHUNK):  # distances of a chunk of rows at a time
            part = z[start:start + NEAREST_CHUNK]
            distance = ((part[:, None, :] - self.z[None, :, :]) ** 2).sum(axis=-1)
            labels[start:start + len(part)] = self.y[distance.argmin(axis=1)]
        return labels


def fit_nearest(x: npt.ArrayLike, y: npt.ArrayLike) -> Nearest:
    """A nearest-neighbour classifier of the rows of ``x`` (n, features) labelled ``y``: any
    boundary, however bent, that the fitted trials draw. Columns are standardized on ``x`` (a
    constant column is left at 0).

    >>> rule = fit_nearest([[0.0], [1.0], [5.0]], [0, 1, 0])
    >>> rule.predict([[0.9], [4.0]]).tolist()
    [1, 0]
    """
    x = np.asarray(x, dtype=float)
    mu, sd = x.mean(axis=0), x.std(axis=0)
    sd = np.where(sd > 0, sd, 1.0)
    return Nearest(mu, sd, (x - mu) / sd, np.asarray(y, dtype=np.int64))
