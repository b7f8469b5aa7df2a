"""Bounds for a classifier of one input stream: simple features of the stream, the best
single-threshold rule on one of them (a lower bound a network should beat) and logistic regression
on all of them (an observer that sees the whole trial, an upper reference). NumPy only.

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

__all__ = ["FEATURES", "Logistic", "Threshold", "features", "fit_logistic", "fit_threshold"]

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
