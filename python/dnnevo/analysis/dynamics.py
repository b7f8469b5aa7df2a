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
The numerical work is in Rust (``ctrnn::analysis``); this module turns its results into
dataclasses. The analysis is of the continuous-time system; tasks integrate it with Euler steps
(``dnnevo assess --dt-check`` tells whether a champion's behaviour depends on the step).

>>> import dnnevo
>>> net = dnnevo.Network(tau=[1.0], theta=[4.0], weights=[[8.0]], sensor_weights=[[1.0]])
>>> len(limit_cycles(net, [0.0]))  # one neuron cannot oscillate
0
"""


from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.errors import InvalidArgumentError

__all__ = ["RETRY_STARTS", "STABILITIES", "Attractors", "Bifurcation", "Cycle", "CycleBranch", "CycleEnd",
           "Equilibrium", "Event", "attractors", "bifurcation", "equilibria", "limit_cycles",
           "settles_to", "vector_field"]

STABILITIES = ("stable_node", "stable_focus", "saddle", "unstable_node", "unstable_focus", "non_hyperbolic")
"""The stability classes, from the eigenvalues of the Jacobian: every real part negative (a node
if every eigenvalue is real, else a focus), mixed signs (saddle), every real part positive, or
some real part 0 within 1e-9 relative (non-hyperbolic: linearisation does not decide)."""

_Array = npt.NDArray[np.float64]


def _complex(pairs: Sequence[Sequence[float | None]]) -> npt.NDArray[np.complex128]:
    return np.array([complex(math.nan if re is None else re, im or 0.0) for re, im in pairs], dtype=complex)


def _pairs(z: npt.NDArray[np.complex128]) -> list[list[float]]:
    return [[float(c.real), float(c.imag)] for c in z]


@dataclass(frozen=True)
class Equilibrium:
    """One equilibrium and its linear stability."""

    state: _Array
    """The state v (length N)."""
    outputs: _Array
    """The firing rates ``f(v - theta)`` there."""
    eigenvalues: npt.NDArray[np.complex128]
    """Eigenvalues of the Jacobian of ``dv/dt``, largest real part first."""
    stability: str
    """One of :data:`STABILITIES`."""
    unstable_dimensions: int
    """How many eigenvalues have a positive real part."""
    time_scale: float | None
    """``1 / min |Re lambda|``: how long the slowest direction takes to approach (or leave) by a
    factor e. None when non-hyperbolic."""
    residual: float
    """``max_i tau_i |dv_i/dt|`` there (at most the search's tolerance)."""

    @property
    def stable(self) -> bool:
        """Whether nearby states approach it (a stable node or focus)."""
        return self.stability in ("stable_node", "stable_focus")

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Equilibrium:
        """From the JSON form the Rust core returns."""
        return cls(np.array(d["state"], dtype=float), np.array(d["outputs"], dtype=float),
                   _complex(d["eigenvalues"]), d["stability"], int(d["unstable_dimensions"]),
                   d["time_scale"], float(d["residual"]))

    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types (eigenvalues as ``[re, im]`` pairs)."""
        return {"state": self.state.tolist(), "outputs": self.outputs.tolist(),
                "eigenvalues": _pairs(self.eigenvalues), "stability": self.stability,
                "unstable_dimensions": self.unstable_dimensions, "time_scale": self.time_scale,
                "residual": self.residual}


@dataclass(frozen=True)
class Cycle:
    """One attracting limit cycle."""

    period: float
    crossings: int
    """Upward crossings of the Poincaré section per period (1 for a simple loop)."""
    section_neuron: int
    amplitude: _Array
    """Per neuron, max minus min of the state over one period."""
    mean_outputs: _Array
    output_range: _Array
    """Per neuron, the lowest and highest firing rate over one period, shape (N, 2)."""
    multipliers: npt.NDArray[np.complex128]
    """Floquet multipliers, largest modulus first; one of them is 1 (along the orbit)."""
    max_multiplier: float
    """The largest modulus other than the trivial multiplier: below 1 for a stable cycle, and the
    factor by which a perturbation shrinks per period."""
    stable: bool
    orbit: _Array
    """States along one period, shape (K, N)."""

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Cycle:
        """From the JSON form the Rust core returns."""
        return cls(float(d["period"]), int(d["crossings"]), int(d["section_neuron"]),
                   np.array(d["amplitude"], dtype=float), np.array(d["mean_outputs"], dtype=float),
                   np.array(d["output_range"], dtype=float).reshape(-1, 2), _complex(d["multipliers"]), float(d["max_multiplier"]), bool(d["stable"]),
                   np.array(d["orbit"], dtype=float))

    def to_dict(self, *, orbit: bool = True) -> dict[str, Any]:
        """As plain JSON types; ``orbit=False`` leaves the orbit out."""
        d: dict[str, Any] = {"period": self.period, "crossings": self.crossings,
                             "section_neuron": self.section_neuron, "amplitude": self.amplitude.tolist(),
                             "mean_outputs": self.mean_outputs.tolist(), "output_range": self.output_range.tolist(),
                             "multipliers": _pairs(self.multipliers), "max_multiplier": self.max_multiplier,
                             "stable": self.stable}
        if orbit:
            d["orbit"] = self.orbit.tolist()
        return d


@dataclass(frozen=True)
class Event:
    """A fold or Hopf point of a sweep."""

    kind: str
    """``"fold"`` or ``"hopf"``."""
    value: float
    """The input value where it happens."""
    state: _Array
    """The equilibrium there: two events at nearly the same value are told apart by it (two
    folds at one value are two different pairs of equilibria meeting)."""
    eigenvalue: complex
    """The critical eigenvalue: real and near 0 (fold), or near ``i omega`` (Hopf)."""
    outputs: _Array = field(default_factory=lambda: np.zeros(0))
    """The firing rates ``f(v - theta)`` at ``state``."""

    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types."""
        return {"kind": self.kind, "value": self.value, "state": self.state.tolist(),
                "outputs": self.outputs.tolist(), "eigenvalue": [self.eigenvalue.real, self.eigenvalue.imag]}


@dataclass(frozen=True)
class CycleEnd:
    """Where a cycle branch appears or disappears in a sweep."""

    kind: str
    """``"hopf"`` (the cycle shrinks onto an equilibrium at a Hopf point of the sweep) or
    ``"lost"`` (it stops being found: a fold of cycles, a homoclinic orbit, or a change the search
    missed)."""
    value: float
    """The input value of the end: the Hopf point's, or the last value (by bisection) where the
    cycle was still found."""
    with_cycle: float
    """The swept value next to the end where the cycle was found."""
    without_cycle: float
    """The swept value next to the end, on the other side, where it was not."""
    period: float
    """The period at the end: ``2 pi / omega`` of a Hopf point's eigenvalues ``±i omega``, or the
    last cycle the bisection found. A lost cycle whose period grows towards its end ends at a
    homoclinic orbit or a saddle-node on the cycle; one whose period stays finite, at a fold of
    cycles."""

    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types."""
        return {"kind": self.kind, "value": self.value, "with_cycle": self.with_cycle,
                "without_cycle": self.without_cycle, "period": self.period}

    @classmethod
    def from_dict(cls, d: dict[str, Any] | None) -> CycleEnd | None:
        """From the JSON form the Rust core returns (None stays None)."""
        if d is None:
            return None
        return cls(d["kind"], float(d["value"]), float(d["with_cycle"]), float(d["without_cycle"]),
                   float(d["period"]))


@dataclass(frozen=True)
class CycleBranch:
    """One attracting cycle followed across consecutive swept values."""

    id: int
    first: int
    """Index of the first swept value with the cycle."""
    last: int
    """Index of the last swept value with the cycle."""
    start: CycleEnd | None
    """Where it appears (in sweep order), None if it is there at the first value."""
    end: CycleEnd | None
    """Where it disappears, None if it is there at the last value."""

    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types."""
        return {"id": self.id, "first": self.first, "last": self.last,
                "start": self.start.to_dict() if self.start else None,
                "end": self.end.to_dict() if self.end else None}


@dataclass(frozen=True)
class Bifurcation:
    """A sweep of input ``index``: the equilibria at each value and the events between them."""

    index: int
    input: _Array
    """The other inputs' values (entry ``index`` is swept)."""
    values: _Array
    equilibria: list[list[Equilibrium]]
    events: list[Event]
    cycles: list[list[Cycle]] = field(default_factory=list)
    """The attracting cycles at each value (empty lists unless the sweep searched for them)."""
    cycle_branch: list[list[int]] = field(default_factory=list)
    """The branch id of each cycle, parallel to ``cycles``: an index into ``branches``."""
    branches: list[CycleBranch] = field(default_factory=list)
    """The cycles followed across values, by id."""
    retried: list[float] = field(default_factory=list)
    """The values where the first search found an even number of equilibria and searched again
    with :data:`RETRY_STARTS` (or the sweep's ``retry_starts``) starts."""

    @property
    def even(self) -> list[float]:
        """The values where the count of equilibria is still even: some were missed there."""
        return [float(v) for v, row in zip(self.values, self.equilibria, strict=True) if len(row) % 2 == 0]

    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types (cycles without their orbits)."""
        return {"index": self.index, "input": self.input.tolist(), "values": self.values.tolist(),
                "equilibria": [[e.to_dict() for e in row] for row in self.equilibria],
                "cycles": [[c.to_dict(orbit=False) for c in row] for row in self.cycles],
                "cycle_branch": self.cycle_branch, "branches": [b.to_dict() for b in self.branches],
                "events": [e.to_dict() for e in self.events], "retried": self.retried, "even": self.even}


def _input(net: _core.Network, value: npt.ArrayLike | None) -> list[float]:
    if value is None:
        return [0.0] * net.n_inputs
    arr = np.asarray(value, dtype=float).reshape(-1)
    if arr.shape != (net.n_inputs,):
        raise InvalidArgumentError(f"input has {arr.size} values; this network has {net.n_inputs} sensors, "
                                   f"so it needs {net.n_inputs}")
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
    found = _core.analysis_equilibria(net, _input(net, input), starts=starts, tolerance=tolerance,
                                     distinct=distinct, max_iterations=max_iterations, seed=seed,
                                     retry_starts=retry_starts)
    return [Equilibrium.from_dict(d) for d in found]


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
    found = _core.analysis_cycles(net, _input(net, input), starts=starts, steps_per_tau=steps_per_tau,
                                 transient=transient, window=window, tolerance=tolerance,
                                 orbit_points=orbit_points, seed=seed)
    return [Cycle.from_dict(d) for d in found]


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
    base = _input(net, input)
    d = _core.analysis_bifurcation(net, base, index, start, stop, steps=steps, starts=starts,
                                   seed=seed, cycle_starts=cycle_starts, retry_starts=retry_starts)
    events = [Event(e["kind"], float(e["value"]), np.array(e["state"], dtype=float),
                    complex(*(math.nan if x is None else x for x in e["eigenvalue"])),
                    np.array(e["outputs"], dtype=float))
              for e in d["events"]]
    return Bifurcation(int(d["input"]), np.array(base), np.array(d["values"], dtype=float),
                       [[Equilibrium.from_dict(e) for e in row] for row in d["equilibria"]], events,
                       [[Cycle.from_dict(c) for c in row] for row in d["cycles"]],
                       [[int(k) for k in row] for row in d["cycle_branch"]],
                       [CycleBranch(int(b["id"]), int(b["first"]), int(b["last"]), CycleEnd.from_dict(b["start"]),
                                    CycleEnd.from_dict(b["end"])) for b in d["branches"]],
                       [float(v) for v in d["retried"]])


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
    v = np.asarray(states, dtype=float).reshape(-1, net.size)
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
