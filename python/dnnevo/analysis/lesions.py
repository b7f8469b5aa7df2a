"""Lesions: a neuron held at a constant output (:func:`clamp`) or a connection removed
(:func:`cut`), and a champion re-scored on fresh trials with each lesion (:func:`lesions`), to see
which parts its success needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core, tasks
from dnnevo._checks import index, nonnegative
from dnnevo.config import EvolutionConfig
from dnnevo.analysis.trials import trial_outputs
from dnnevo.errors import InvalidArgumentError

__all__ = ["CLAMP_LIMIT", "Lesion", "LesionTable", "clamp", "cut", "lesions"]

_Array = npt.NDArray[np.float64]

CLAMP_LIMIT = 1e-9
"""A clamped output is kept this far inside (0, 1), so that its threshold stays finite."""


def clamp(net: _core.Network, neuron: int, output: float) -> _core.Network:
    """``net`` with ``neuron``'s firing rate held at ``output`` for every trial.

    The neuron's incoming weights, self-weight and sensor weights become 0, so ``tau dv/dt = -v``
    keeps its state at ``v = 0``, where it is set (the tasks start every trial there), and its
    threshold becomes ``-logit(output)``, so ``f(0 - theta) = output``. Every other neuron ``j``
    then receives ``w_j,neuron * output`` from it (``weights[j, neuron]``), as the clamp means.
    ``output`` is moved :data:`CLAMP_LIMIT` inside (0, 1) if it lies closer to 0 or 1. The other
    neurons keep their state, so a network lesioned in the middle of a run goes on from where it
    was; ``meta`` (the intact network's task, seed and fitness) is not carried over."""
    i = _neuron(net, "neuron", neuron)
    if not math.isfinite(output) or not 0.0 <= output <= 1.0:
        raise InvalidArgumentError(f"output is {output!r}; a firing rate must be in [0, 1]")
    o = min(max(output, CLAMP_LIMIT), 1.0 - CLAMP_LIMIT)
    weights, sensors, theta, state = net.weights.copy(), net.sensor_weights.copy(), net.theta.copy(), net.state.copy()
    weights[i, :] = 0.0
    sensors[i, :] = 0.0
    theta[i] = -math.log(o / (1.0 - o))
    state[i] = 0.0
    return _core.Network(net.tau, theta, weights, sensors, state)


def cut(net: _core.Network, source: int, target: int) -> _core.Network:
    """``net`` without the connection from neuron ``source`` to neuron ``target``
    (``weights[target, source]`` set to 0). Every neuron keeps its state; ``meta`` is not
    carried over."""
    s, t = _neuron(net, "source", source), _neuron(net, "target", target)
    weights = net.weights.copy()
    weights[t, s] = 0.0
    return _core.Network(net.tau, net.theta, weights, net.sensor_weights, net.state)


def _neuron(net: _core.Network, name: str, k: Any) -> int:
    """``k`` as a neuron index of ``net``: an integer (Python's or NumPy's) in 0..N-1."""
    return index(name, k, net.size, f"this network has {net.size} neurons")


@dataclass(frozen=True)
class Lesion:
    """One lesion and the score it leaves."""

    name: str
    """E.g. ``"clamp 3 at 0.12"`` or ``"cut 2->0"``."""
    kind: str
    """``"clamp"`` or ``"cut"``."""
    neurons: tuple[int, ...]
    """The clamped neuron, or (source, target) of the cut."""
    score: float
    """The lesioned network's score (see :attr:`LesionTable.score`)."""
    drop: float
    """The intact network's score minus this one: how much the part matters."""
    verdict: str


@dataclass(frozen=True)
class LesionTable:
    """Scores after each lesion, on the same fresh trials as the intact network."""

    task: str
    trials: int
    seed: int
    score: float
    """The intact network's score: its lowest judged success rate (the weakest target for
    sequence, the overall rate for landmark and nav1d)."""
    verdict: str
    mean_outputs: _Array
    """Each neuron's mean firing rate over the recorded trials; a clamp holds it there."""
    lesions: list[Lesion] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types."""
        return {"task": self.task, "trials": self.trials, "seed": self.seed, "score": self.score,
                "verdict": self.verdict, "mean_outputs": self.mean_outputs.tolist(),
                "lesions": [{"name": x.name, "kind": x.kind, "neurons": list(x.neurons), "score": x.score,
                             "drop": x.drop, "verdict": x.verdict} for x in self.lesions]}


def _score(a: Any) -> float:
    return float(min(r.rate for r in a.judged))


def lesions(
    config: EvolutionConfig, net: _core.Network, trials: int, *, seed: int, cuts: int | None = None,
    mean_outputs: npt.ArrayLike | None = None,
) -> LesionTable:
    """Re-scores ``net`` with each neuron clamped at its mean output, and with each of its
    ``cuts`` strongest connections (by ``|w|``; default N, 0 for none) cut, on ``trials`` fresh
    trials from ``seed`` (the trials :func:`dnnevo.tasks.assess` draws, the same for every
    lesion). ``mean_outputs`` defaults to the mean over :func:`trial_outputs` of ``seed``."""

    base = tasks.assess(config, net, trials, seed=seed)
    if mean_outputs is None:
        mean = trial_outputs(config, net, seed=seed)[0].mean(axis=0)
    else:
        mean = np.asarray(mean_outputs, dtype=float).reshape(-1)
        if mean.shape != (net.size,):
            raise InvalidArgumentError(f"mean_outputs has {mean.size} values; expected N = {net.size}")
    score = _score(base)
    out: list[Lesion] = []

    def add(name: str, kind: str, neurons: tuple[int, ...], lesioned: _core.Network) -> None:
        a = tasks.assess(config, lesioned, trials, seed=seed)
        out.append(Lesion(name, kind, neurons, _score(a), score - _score(a), a.verdict))

    for i in range(net.size):
        add(f"clamp {i} at {mean[i]:.3g}", "clamp", (i,), clamp(net, i, float(mean[i])))
    w = net.weights
    count = net.size if cuts is None else nonnegative("cuts", cuts)
    order = sorted(((abs(w[t, s]), s, t) for t in range(net.size) for s in range(net.size) if w[t, s] != 0.0),
                   reverse=True)[:count]
    for _, s, t in order:
        add(f"cut {s}->{t}", "cut", (s, t), cut(net, s, t))
    return LesionTable(config.task, trials, seed, score, base.verdict, mean, out)
