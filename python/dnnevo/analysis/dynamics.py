"""The attractors of a network under a constant input, and how an input that changes moves them.

With its sensors held at a constant input vector, a network is an autonomous dynamical system
``tau_i dv_i/dt = -v_i + sum_j w_ij f(v_j - theta_j) + c_i`` (``c = sensor_weights @ input``). Its
behaviour is organised by its attractors, and an input that changes moves, creates or destroys
them (Beer 1995, "On the dynamics of small continuous-time recurrent neural networks"):

- :func:`equilibria`: every equilibrium Newton's method reaches from many starts, with its
  eigenvalues, :data:`STABILITIES` class and slowest time scale;
- :func:`limit_cycles`: attracting limit cycles by long RK4 integration and a Poincaré section,
  with period, amplitude per neuron and Floquet multipliers;
- :func:`bifurcation`: one input swept from ``start`` to ``stop``, the equilibria followed, and
  the folds (an equilibrium pair appears or vanishes) and Hopf points (a complex pair crosses the
  imaginary axis) located; optionally the attracting cycles followed as :class:`CycleBranch` es,
  each with where it appears and disappears;
The numerical work is in Rust (``ctrnn::analysis``), and its results are the core's typed
objects. The analysis is of the continuous-time system; tasks integrate it with Euler steps
(``dnnevo assess --dt-check`` tells whether a champion's behaviour depends on the step).

>>> import dnnevo
>>> net = dnnevo.Network(tau=[1.0], theta=[4.0], weights=[[8.0]], sensor_weights=[[1.0]])
>>> len(limit_cycles(net, [0.0]))  # one neuron cannot oscillate
0
"""


from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo._checks import index as checked_index
from dnnevo.errors import InvalidArgumentError, counted

__all__ = ["RETRY_STARTS", "STABILITIES", "Attractors", "Bifurcation", "Cycle", "CycleBranch", "CycleEnd",
           "Equilibrium", "Event", "attractors", "bifurcation", "equilibria", "limit_cycles",
           "settles_to", "vector_field"]

STABILITIES: tuple[str, ...] = tuple(_core.STABILITIES)
"""The stability classes, from the eigenvalues of the Jacobian: every real part negative (a node
if every eigenvalue is real, else a focus), mixed signs (saddle), every real part positive, or
some real part 0 within 1e-9 relative (non-hyperbolic: linearisation does not decide). The names
come from the Rust core (``ctrnn::analysis::Stability``)."""

_Array = npt.NDArray[np.float64]

# The results are the Rust core's own types, built once from its structs with NumPy arrays for
# their vectors (``crates/dnnevo-py/src/dynamics.rs``); each has ``to_dict()``.
Equilibrium = _core.Equilibrium
Cycle = _core.Cycle
Event = _core.Event
CycleEnd = _core.CycleEnd
CycleBranch = _core.CycleBranch
Bifurcation = _core.Bifurcation


def _input(net: _core.Network, value: npt.ArrayLike | None) -> list[float]:
    if value is None:
        return [0.0] * net.n_inputs
    arr = np.asarray(value, dtype=float).reshape(-1)
    if arr.shape != (net.n_inputs,):
        raise InvalidArgumentError(f"input has {counted(arr.size, 'value')}; this network has "
                                   f"{counted(net.n_inputs, 'sensor')}, so it needs {net.n_inputs}")
    return arr.tolist()


RETRY_STARTS: int = _core.RETRY_STARTS
"""The default ``retry_starts``: a search that finds an even number of equilibria searches
again with this many starts (0.2 s for 10 neurons). The number lives in the Rust core
(``ctrnn::analysis::RETRY_STARTS``)."""


def equilibria(
    net: _core.Network, input: npt.ArrayLike | None = None, *, starts: int = 512, tolerance: float = 1e-10,
    distinct: float = 1e-6, max_iterations: int = 100, seed: int = 0, retry_starts: int | None = None,
) -> list[Equilibrium]:
    """Every equilibrium of ``net`` with its sensors held at ``input`` (default: all 0) that damped
    Newton's method reaches from ``starts`` starting points, sorted by state.

    Starts are output vectors in (0, 1)^N mapped to ``v = weights o + c`` (the box every
    equilibrium lies in), half near the cube's corners. An equilibrium is accepted when
    ``max_i tau_i |dv_i/dt| <= tolerance``; two closer than ``distinct`` in every coordinate are
    one. None is guaranteed for large N: a generic network has an odd number of equilibria, so
    when the count is even the search is repeated with ``retry_starts`` starts (default
    :data:`RETRY_STARTS`; 0 never). A count that is still even means some were missed."""
    return _core.analysis_equilibria(net, _input(net, input), starts=starts, tolerance=tolerance,
                                     distinct=distinct, max_iterations=max_iterations, seed=seed,
                                     retry_starts=retry_starts)


def limit_cycles(
    net: _core.Network, input: npt.ArrayLike | None = None, *, starts: int = 8, steps_per_tau: int = 20,
    transient: float = 100.0, window: float = 100.0, tolerance: float = 1e-5, orbit_points: int = 200,
    seed: int = 1,
) -> list[Cycle]:
    """The attracting limit cycles of ``net`` with its sensors held at ``input``, sorted by period.

    From each of ``starts`` states the network is integrated by RK4 (``steps_per_tau`` steps per
    smallest time constant) for ``transient`` largest time constants, then for up to ``window``
    more while watching the upward crossings of the level halfway between the extremes of the
    neuron that moves most. The orbit is closed when a crossing comes within ``tolerance`` of one
    of the 4 before it. Forward integration finds attracting cycles only."""
    return _core.analysis_cycles(net, _input(net, input), starts=starts, steps_per_tau=steps_per_tau,
                                 transient=transient, window=window, tolerance=tolerance,
                                 orbit_points=orbit_points, seed=seed)


def bifurcation(
    net: _core.Network, index: int, start: float, stop: float, *, input: npt.ArrayLike | None = None,
    steps: int = 101, starts: int = 128, seed: int = 0, cycle_starts: int = 0, retry_starts: int | None = None,
) -> Bifurcation:
    """Sweeps input ``index`` over ``steps`` values from ``start`` to ``stop`` (the other inputs
    held at ``input``, default 0), following the equilibria (each value's search also starts
    from the previous value's equilibria) and locating folds and Hopf points by bisection. With
    ``cycle_starts > 0`` it also searches each value for attracting cycles (the
    :func:`limit_cycles` defaults with that many starts, plus a point of each of the previous
    value's cycles) and follows them as :class:`CycleBranch` es, each with where it appears and
    disappears; that costs about as much as 100 equilibrium searches per value. A value whose
    count of equilibria is even is searched again with ``retry_starts`` starts (as
    :func:`equilibria`); those values are in ``retried``, and those still even in ``even``."""
    k = checked_index("index", index, net.n_inputs, f"this network has {counted(net.n_inputs, 'sensor')}")
    return _core.analysis_bifurcation(net, _input(net, input), k, start, stop, steps=steps, starts=starts,
                                      seed=seed, cycle_starts=cycle_starts, retry_starts=retry_starts)


@dataclass(frozen=True)
class Attractors:
    """The equilibria and attracting cycles of a network under one constant input."""

    label: str
    input: _Array
    equilibria: list[Equilibrium]
    cycles: list[Cycle]

    def to_dict(self, *, orbits: bool = False) -> dict[str, Any]:
        """As plain JSON types; orbits are left out unless ``orbits``."""
        return {"label": self.label, "input": self.input.tolist(),
                "equilibria": [e.to_dict() for e in self.equilibria],
                "cycles": [c.to_dict(orbit=orbits) for c in self.cycles]}


def attractors(net: _core.Network, input: npt.ArrayLike | None = None, label: str = "") -> Attractors:
    """:func:`equilibria` and :func:`limit_cycles` under ``input``, with the default settings.

    A generic network has an odd number of equilibria (their indices add up to 1, since the
    vector field points inward on a large box), so an even count means some were missed: the
    search is then repeated with :data:`RETRY_STARTS` starts (by :func:`equilibria` itself)."""
    values = _input(net, input)
    found = equilibria(net, values)
    return Attractors(label or ",".join(f"{x:g}" for x in values), np.array(values), found,
                      limit_cycles(net, values))


def vector_field(net: _core.Network, input: npt.ArrayLike | None, states: npt.ArrayLike) -> _Array:
    """``dv/dt`` at each state (shape (..., N)) with the sensors held at ``input``, in NumPy (with
    NumPy's exponential; the Rust core's agrees to about 1e-15)."""
    v = np.asarray(states, dtype=float)
    if v.shape[-1:] != (net.size,):
        raise InvalidArgumentError(f"states have shape {v.shape}; the last axis must be N = {net.size}")
    c = net.sensor_weights @ np.asarray(_input(net, input))
    f = 1.0 / (1.0 + np.exp(-(v - net.theta)))
    return np.asarray((-v + f @ net.weights.T + c) / net.tau)


def settles_to(
    net: _core.Network, states: npt.ArrayLike, targets: Sequence[Equilibrium], input: npt.ArrayLike | None = None,
    *, duration: float | None = None, tolerance: float = 1e-2,
) -> npt.NDArray[np.int64]:
    """For each state (rows of ``states``), the index in ``targets`` of the equilibrium it
    reaches when the sensors are then held at ``input`` for ``duration`` (default: 30 largest
    time constants), integrated by RK4 at a step of a fifth of the smallest time constant; -1
    when it ends farther than ``tolerance`` (in firing rate) from every target. With ``input`` off
    and the stable equilibria as ``targets``, this says which attractor holds the state."""
    v = np.asarray(states, dtype=float)
    if v.shape[-1:] != (net.size,) or not np.all(np.isfinite(v)):
        raise InvalidArgumentError(f"states have shape {v.shape}; expected finite values with the last axis "
                                   f"N = {net.size}")
    v = v.reshape(-1, net.size)
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise InvalidArgumentError(f"duration is {duration!r}; expected a time > 0")
    dt = float(np.min(net.tau)) / 5
    steps = int(math.ceil((duration if duration is not None else 30 * float(np.max(net.tau))) / dt))
    u = np.tile(np.asarray(_input(net, input)), (steps, 1))
    goals = np.array([e.outputs for e in targets]).reshape(len(targets), net.size)
    out = np.full(len(v), -1, dtype=np.int64)
    for k, s in enumerate(v):
        n = net.copy()
        n.reset(s)
        end = n.run(u, dt=dt, method="rk4").outputs[-1]
        if len(goals):
            d = np.max(np.abs(goals - end), axis=1)
            if d.min() <= tolerance:
                out[k] = int(np.argmin(d))
    return out
