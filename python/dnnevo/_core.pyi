"""Type stubs for the native module ``dnnevo._core`` (checked by ``mypy.stubtest``)."""

from collections.abc import Callable, Mapping, Sequence
from os import PathLike
from typing import Any, Literal, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "LANDMARK_SUCCESS_RATE",
    "LANES",
    "MAX_COUNT",
    "NAV1D_SUCCESS_RATE",
    "SEQUENCE_SUCCESS_FRACTION",
    "MUTATION_SCALE",
    "RETRY_STARTS",
    "STABILITIES",
    "RUN_DEFAULTS",
    "STEP_CHECK_FINER",
    "Batch",
    "Evolution",
    "Fleet",
    "Network",
    "RunConfig",
    "SequenceTask",
    "SequenceRecord",
    "Nav1dTask",
    "LandmarkTask",
    "Nav1dCondition",
    "Nav1dRecord",
    "LandmarkRecord",
    "Trace",
    "Equilibrium",
    "Cycle",
    "Event",
    "CycleEnd",
    "CycleBranch",
    "Bifurcation",
    "__version__",
    "apply_simd_env",
    "build_info",
    "use_kernel",
    "analysis_bifurcation",
    "analysis_cycles",
    "analysis_equilibria",
    "condition_seed",
    "process_threads",
    "compose",
    "decode",
    "encode",
    "evaluate",
    "run_population",
    "nav1d_system_assess",
    "nav1d_system_record",
    "sim2d_cast_rays",
    "sim2d_landmark_world",
    "task_names",
]

__version__: str
LANES: int
RUN_DEFAULTS: str
MAX_COUNT: int
MUTATION_SCALE: float
RETRY_STARTS: int
STABILITIES: list[str]
STEP_CHECK_FINER: int
SEQUENCE_SUCCESS_FRACTION: float
NAV1D_SUCCESS_RATE: float
LANDMARK_SUCCESS_RATE: float

_Array = npt.NDArray[np.float64]
_Method = Literal["euler", "rk4"]
_Precision = Literal["f64", "f32"]

@final
class Trace:
    """States, outputs and inputs after each input row, and the time at the end of each row."""

    @property
    def states(self) -> _Array: ...
    @property
    def outputs(self) -> _Array: ...
    @property
    def inputs(self) -> _Array: ...
    @property
    def time(self) -> _Array: ...

@final
class Network:
    """A continuous-time recurrent neural network of N neurons and M sensors::

        tau_i dv_i/dt = -v_i + sum_j weights[i][j] f(v_j - theta_j) + sum_k sensor_weights[i][k] I_k

    with the firing rate ``f(x) = 1 / (1 + exp(-x))`` (mind the sign: ``f(v - theta)``, where
    Beer-lab code often writes ``sigma(v + bias)``). The attributes are read-only copies: to
    change a weight, build a new network."""

    def __new__(
        cls,
        tau: npt.ArrayLike,
        theta: npt.ArrayLike,
        weights: npt.ArrayLike,
        sensor_weights: npt.ArrayLike,
        state: npt.ArrayLike | None = None,
    ) -> Network: ...
    @staticmethod
    def from_genome(genes: npt.ArrayLike, *, size: int, n_inputs: int) -> Network:
        """The network that the genome ``genes`` (G,) encodes, its state zero: one block per
        neuron, in order, of its ``tau``, its ``theta``, its M sensor weights and its N incoming
        weights (``weights[i][:]``), so G = N (2 + M + N), in model units, as dnnevo's genetic
        algorithm evolves them; the inverse of :meth:`genome`, for an optimiser of your own.

        >>> net = Network.from_genome([1.0, 0.0, 0.5, 2.0], size=1, n_inputs=1)
        >>> net.tau.tolist(), net.sensor_weights.tolist(), net.weights.tolist()
        ([1.0], [[0.5]], [[2.0]])
        >>> Network.from_genome(net.genome(), size=1, n_inputs=1) == net
        True
        """
    def genome(self) -> _Array:
        """The network's genome, shape (G,) (its state is not part of it); see
        :meth:`from_genome`."""
    @staticmethod
    def random(
        size: int,
        n_inputs: int,
        *,
        seed: int,
        ranges: Mapping[str, Sequence[float]] | Any | None = None,
    ) -> Network:
        """A network with every parameter uniform in its range (``ranges``: a dict of
        ``[low, high]`` pairs by kind, ``tau``, ``theta``, ``weights`` and ``sensor_weights``, or a
        ``dnnevo.Ranges``; a kind left out keeps its default), drawn from ``seed``."""
    @property
    def size(self) -> int: ...
    @property
    def n_inputs(self) -> int: ...
    @property
    def tau(self) -> _Array: ...
    @property
    def theta(self) -> _Array: ...
    @property
    def weights(self) -> _Array: ...
    @property
    def sensor_weights(self) -> _Array: ...
    @property
    def state(self) -> _Array: ...
    @property
    def outputs(self) -> _Array: ...
    @property
    def meta(self) -> dict[str, Any]: ...
    @property
    def integrator(self) -> dict[str, Any] | None:
        """How the network is meant to be run, ``{"method", "dt", "substeps"}``, from the file or
        dict it was read from; None if it had none (``save(integrator=...)`` writes one into the
        file, not into this network). ``run`` does not read it: ``net.run(inputs,
        **net.integrator)`` does (with ``precision=net.meta["precision"]`` for a champion
        evolved in f32)."""
    def reset(self, state: npt.ArrayLike | None = None) -> None: ...
    def run(
        self,
        inputs: npt.ArrayLike,
        *,
        dt: float = 0.1,
        substeps: int = 1,
        method: _Method = "euler",
        precision: _Precision = "f64",
    ) -> Trace:
        """Integrates through the rows of ``inputs`` (T, M), each held for ``substeps`` steps of
        ``dt``, and keeps the final state. ``precision="f32"`` computes in single precision, with
        the bits of ``run_population(..., precision="f32")`` for this network: parameters,
        state and inputs rounded to float32 once, the trace's states and outputs (and the state
        kept) float32 values widened to float64."""
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str) -> Network: ...
    def to_dict(self) -> dict[str, Any]: ...
    @staticmethod
    def from_dict(d: Mapping[str, Any]) -> Network: ...
    def save(
        self,
        path: str | PathLike[str],
        *,
        meta: Mapping[str, Any] | None = None,
        integrator: dict[str, Any] | None = None,
    ) -> None:
        """Writes the network file atomically; ``meta`` entries are added to the network's own,
        and ``integrator`` (``{"method", "dt", "substeps"}``, all three) replaces its own."""
    @staticmethod
    def load(path: str | PathLike[str]) -> Network: ...
    def copy(self) -> Network: ...
    def __copy__(self) -> Network: ...
    def __deepcopy__(self, memo: Any) -> Network: ...
    def __reduce__(self) -> tuple[Any, ...]: ...
    def __eq__(self, other: object, /) -> bool: ...

def build_info() -> dict[str, Any]:
    """This build's version and git commit (``"unknown"`` outside a checkout; ``+changes`` when
    the tree had uncommitted changes), the CPU's architecture and SIMD features, the kernels it can run
    ("portable", "avx2", "avx512", "neon") and the one in use.

    >>> import dnnevo
    >>> info = dnnevo.build_info()
    >>> info["kernel"] in info["kernels"]
    True
    """

def use_kernel(name: str) -> None:
    """Makes later integrations use kernel ``name``; results do not change, only the speed.
    Raises InvalidArgumentError for an unknown name or a kernel this CPU cannot run."""

def apply_simd_env() -> None: ...
def compose(a: Network, b: Network, *, cross_scale: float = 0.0, seed: int = 0, member: int = 0) -> Network: ...
def run_population(
    networks: Sequence[Network] | Mapping[str, npt.ArrayLike],
    inputs: npt.ArrayLike,
    *,
    dt: float = 0.1,
    substeps: int = 1,
    method: _Method = "euler",
    record: bool = True,
    precision: _Precision = "f64",
) -> _Array:
    """Integrates P networks of the same N and M together: the states after every input row
    (P, T, N) with ``record``, else the final states (P, N). ``precision="f32"`` computes in
    single precision (parameters and inputs rounded to float32 once, states float32
    throughout, returned widened to float64); "f64", the default, is the reference. Any other
    precision is an InvalidArgumentError (a ValueError)."""

@final
class Batch:
    """P networks times E replicas, stepped together one time step per call."""

    def __new__(
        cls,
        networks: Sequence[Network] | Mapping[str, npt.ArrayLike],
        *,
        replicas: int = 1,
        rows: int | None = None,
        dt: float = 0.1,
        substeps: int = 1,
        method: _Method = "euler",
        precision: _Precision = "f64",
    ) -> Batch: ...
    @property
    def rows(self) -> int: ...
    @property
    def networks(self) -> int: ...
    @property
    def replicas(self) -> int: ...
    @property
    def size(self) -> int: ...
    @property
    def n_inputs(self) -> int: ...
    @property
    def precision(self) -> _Precision: ...
    @property
    def integrator(self) -> dict[str, Any]: ...
    @property
    def states(self) -> _Array: ...
    @property
    def rates(self) -> _Array: ...
    def step(
        self,
        inputs: npt.ArrayLike,
        *,
        active: npt.ArrayLike | None = None,
        out: _Array | None = None,
    ) -> _Array: ...
    def reset(self, rows: npt.ArrayLike | None = None) -> None: ...
    def set_states(self, states: npt.ArrayLike, rows: npt.ArrayLike | None = None) -> None: ...
    @property
    def network_of(self) -> npt.NDArray[np.int64]: ...
    def assign(self, rows: npt.ArrayLike, networks: npt.ArrayLike) -> None: ...
    def __len__(self) -> int: ...

def condition_seed(seed: int, generation: int, purpose: Literal["trial", "validate", "evaluate"] = "trial") -> int:
    """The first word of dnnevo's random stream (seed, generation, purpose): the seed of a
    Python task's conditions."""

def process_threads(threads: int | None = None) -> int:
    """The number of threads of the process's shared pool (Batch, robot fleets, calls without
    ``threads``); with ``threads``, sized to that many first, which takes only before its first
    use."""

# -- a run's settings and the GA ------------------------------------------------------------

@final
class RunConfig:
    """A run's settings, parsed and validated once by the core (``EvolutionConfig.native``)."""

    def __new__(cls, config: str) -> RunConfig: ...
    @property
    def task(self) -> str: ...
    def to_json(self) -> str: ...
    def builtin(self) -> SequenceTask | Nav1dTask | LandmarkTask: ...
    def __reduce__(self) -> tuple[Any, ...]: ...

@final
class Evolution:
    """The GA state behind ``dnnevo.GeneticAlgorithm``."""

    def __new__(
        cls,
        config: RunConfig,
        seed: int,
        seeds: Sequence[Network] | None = None,
    ) -> Evolution: ...
    @property
    def generation(self) -> int: ...
    @property
    def seed(self) -> int: ...
    @property
    def genome_length(self) -> int: ...
    @property
    def champion_fitness(self) -> float | None: ...
    def genomes(self) -> _Array: ...
    def networks(self) -> list[Network]: ...
    def tell(
        self,
        fitness: npt.ArrayLike,
        validate: Callable[[list[Network]], tuple[npt.ArrayLike, npt.ArrayLike]] | None = None,
    ) -> dict[str, float]: ...
    def step(self, threads: int | None = None) -> tuple[dict[str, float], _Array]: ...
    def champion_success(self, seed: int) -> bool | None: ...
    def champion(self) -> tuple[Network, float, int] | None: ...
    def champion_validation(self) -> tuple[float, float] | None: ...
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(text: str, config: RunConfig) -> Evolution: ...

def evaluate(
    config: RunConfig,
    population: npt.ArrayLike | Sequence[Network],
    *,
    generation: int,
    seed: int,
    threads: int | None = None,
) -> _Array: ...
def task_names() -> list[str]: ...

# -- the sequence-learning task ---------------------------------------------------------------

@final
class SequenceTask:
    """The sequence-learning task of a ``RunConfig`` (``RunConfig.builtin()``)."""

    def params(self) -> dict[str, Any]: ...
    @property
    def layout(self) -> tuple[int, int]: ...
    def timings(self, seed: int, generation: int, trial: int) -> list[tuple[int, int]]: ...
    def fresh_timings(self, seed: int, trial: int) -> list[tuple[int, int]]: ...
    def trial_order(self, seed: int, generation: int) -> list[int]: ...
    def trial(
        self, net: Network, pattern: str, timing: Sequence[tuple[int, int]], reset: bool = True
    ) -> SequenceRecord: ...
    def assess(self, net: Network, trials_per_target: int, seed: int) -> dict[str, Any]: ...

@final
class SequenceRecord:
    """One sequence trial, step by step (length T) and trigger by trigger."""

    @property
    def target(self) -> str: ...
    @property
    def trigger(self) -> _Array: ...
    @property
    def reinforcement(self) -> _Array: ...
    @property
    def output(self) -> _Array: ...
    @property
    def outputs(self) -> _Array: ...
    @property
    def targets(self) -> npt.NDArray[np.int64]: ...
    @property
    def r(self) -> _Array: ...
    @property
    def mean_output(self) -> _Array: ...
    @property
    def trigger_correct(self) -> npt.NDArray[np.bool_]: ...
    @property
    def final_state(self) -> _Array: ...

# -- the one-dimensional navigation task ------------------------------------------------------

@final
class Nav1dTask:
    """The one-dimensional navigation task of a ``RunConfig`` (``RunConfig.builtin()``)."""

    def params(self) -> dict[str, Any]: ...
    @property
    def layout(self) -> tuple[int, int]: ...
    @property
    def chain_len(self) -> int: ...
    def chains(self, seed: int, generation: int) -> list[list[Nav1dCondition]]: ...
    def fresh_chains(self, count: int, trials: int, seed: int) -> list[list[Nav1dCondition]]: ...
    def exact(self, environment: str, goal: str) -> Nav1dCondition: ...
    def record(
        self, net: Network, conditions: Sequence[Nav1dCondition], reset: bool = True
    ) -> Nav1dRecord: ...
    def assess(self, net: Network, chains: int, seed: int) -> dict[str, Any]: ...

@final
class Nav1dCondition:
    """One trial's world."""

    def __new__(cls, environment: str, goal: str, start: float, landmark: float) -> Nav1dCondition: ...
    @property
    def environment(self) -> str: ...
    @property
    def goal(self) -> str: ...
    @property
    def start(self) -> float: ...
    @property
    def landmark(self) -> float: ...
    def __eq__(self, other: object, /) -> bool: ...
    def __hash__(self) -> int: ...
    def __reduce__(self) -> tuple[Any, ...]: ...

@final
class Nav1dRecord:
    """A chain of trials, step by step (length T) and trial by trial."""

    @property
    def conditions(self) -> list[Nav1dCondition]: ...
    @property
    def x(self) -> _Array: ...
    @property
    def landmark(self) -> _Array: ...
    @property
    def reinforcement(self) -> _Array: ...
    @property
    def outputs(self) -> _Array: ...
    @property
    def trial(self) -> npt.NDArray[np.int64]: ...
    @property
    def moving(self) -> npt.NDArray[np.bool_]: ...
    @property
    def reached(self) -> list[bool]: ...
    @property
    def classification(self) -> list[float]: ...
    @property
    def final_state(self) -> _Array: ...

def nav1d_system_assess(
    classifier: tuple[Nav1dTask, Network],
    far: tuple[Nav1dTask, Network],
    near: tuple[Nav1dTask, Network],
    environments: int,
    trials: int,
    seed: int,
    persist_state: bool = True,
) -> dict[str, Any]: ...
def nav1d_system_record(
    classifier: tuple[Nav1dTask, Network],
    far: tuple[Nav1dTask, Network],
    near: tuple[Nav1dTask, Network],
    conditions: Sequence[Nav1dCondition],
    persist_state: bool = True,
) -> tuple[Nav1dRecord, Nav1dRecord, str]: ...

# -- the landmark-recognition task and its 2-D world -------------------------------------------

@final
class LandmarkTask:
    """The landmark-recognition task of a ``RunConfig`` (``RunConfig.builtin()``)."""

    def params(self) -> dict[str, Any]: ...
    @property
    def layout(self) -> tuple[int, int]: ...
    def record(
        self, net: Network, landmark: int, seed: int, trial: int, robot_like: bool = False
    ) -> LandmarkRecord: ...
    def assess(
        self, net: Network, per_landmark: int, seed: int, robot_like: bool = False
    ) -> dict[str, Any]: ...

@final
class LandmarkRecord:
    """One landmark trial, step by step (length T)."""

    @property
    def landmark(self) -> int: ...
    @property
    def world(self) -> dict[str, Any]: ...
    @property
    def input(self) -> _Array: ...
    @property
    def range(self) -> _Array: ...
    @property
    def poses(self) -> _Array: ...
    @property
    def echoes(self) -> _Array: ...
    @property
    def outputs(self) -> _Array: ...
    @property
    def classification(self) -> float: ...

def sim2d_cast_rays(
    world: dict[str, Any], origins: npt.ArrayLike, directions: npt.ArrayLike, max_distance: float
) -> npt.NDArray[np.float64]: ...
def sim2d_landmark_world(n: int) -> dict[str, Any]: ...

# -- dynamical analysis -----------------------------------------------------------------------

@final
class Equilibrium:
    """One equilibrium and its linear stability."""

    @property
    def state(self) -> _Array:
        """The state v (length N)."""
    @property
    def outputs(self) -> _Array:
        """The firing rates ``f(v - theta)`` there."""
    @property
    def eigenvalues(self) -> npt.NDArray[np.complex128]:
        """Eigenvalues of the Jacobian of ``dv/dt``, largest real part first."""
    @property
    def stability(self) -> str:
        """One of ``STABILITIES``."""
    @property
    def unstable_dimensions(self) -> int:
        """How many eigenvalues have a positive real part."""
    @property
    def time_scale(self) -> float | None:
        """``1 / min |Re lambda|``: how long the slowest direction takes to approach (or leave) by
        a factor e. None when non-hyperbolic."""
    @property
    def residual(self) -> float:
        """``max_i tau_i |dv_i/dt|`` there (at most the search's tolerance)."""
    @property
    def stable(self) -> bool:
        """Whether nearby states approach it (a stable node or focus)."""
    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types (eigenvalues as ``[re, im]`` pairs)."""

@final
class Cycle:
    """One attracting limit cycle."""

    @property
    def period(self) -> float:
        """The period, in units of simulated time."""
    @property
    def crossings(self) -> int:
        """Upward crossings of the Poincaré section per period (1 for a simple loop)."""
    @property
    def section_neuron(self) -> int:
        """The neuron whose level defines the section."""
    @property
    def amplitude(self) -> _Array:
        """Per neuron, max minus min of the state over one period."""
    @property
    def mean_outputs(self) -> _Array:
        """Per neuron, the mean firing rate over one period."""
    @property
    def output_range(self) -> _Array:
        """Per neuron, the lowest and highest firing rate over one period, shape (N, 2)."""
    @property
    def multipliers(self) -> npt.NDArray[np.complex128]:
        """Floquet multipliers, largest modulus first; one of them is 1 (along the orbit)."""
    @property
    def max_multiplier(self) -> float:
        """The largest modulus other than the trivial multiplier: below 1 for a stable cycle, and
        the factor by which a perturbation shrinks per period."""
    @property
    def stable(self) -> bool:
        """Whether every non-trivial multiplier lies inside the unit circle."""
    @property
    def orbit(self) -> _Array:
        """States along one period, shape (K, N)."""
    def to_dict(self, *, orbit: bool = True) -> dict[str, Any]:
        """As plain JSON types; ``orbit=False`` leaves the orbit out."""

@final
class Event:
    """A fold or Hopf point of a sweep."""

    @property
    def kind(self) -> str:
        """``"fold"`` or ``"hopf"``."""
    @property
    def value(self) -> float:
        """The input value where it happens."""
    @property
    def state(self) -> _Array:
        """The equilibrium there: two events at nearly the same value are told apart by it (two
        folds at one value are two different pairs of equilibria meeting)."""
    @property
    def outputs(self) -> _Array:
        """The firing rates ``f(v - theta)`` at ``state``."""
    @property
    def eigenvalue(self) -> complex:
        """The critical eigenvalue: real and near 0 (fold), or near ``i omega`` (Hopf)."""
    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types."""

@final
class CycleEnd:
    """Where a cycle branch appears or disappears in a sweep."""

    @property
    def kind(self) -> str:
        """``"hopf"`` (the cycle shrinks onto an equilibrium at a Hopf point of the sweep) or
        ``"lost"`` (it stops being found: a fold of cycles, a homoclinic orbit, or a change the
        search missed)."""
    @property
    def value(self) -> float:
        """The input value of the end: the Hopf point's, or the last value (by bisection) where
        the cycle was still found."""
    @property
    def with_cycle(self) -> float:
        """The swept value next to the end where the cycle was found."""
    @property
    def without_cycle(self) -> float:
        """The swept value next to the end, on the other side, where it was not."""
    @property
    def period(self) -> float:
        """The period at the end: ``2 pi / omega`` of a Hopf point's eigenvalues ``±i omega``, or
        the last cycle the bisection found. A lost cycle whose period grows towards its end ends
        at a homoclinic orbit or a saddle-node on the cycle; one whose period stays finite, at a
        fold of cycles."""
    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types."""

@final
class CycleBranch:
    """One attracting cycle followed across consecutive swept values."""

    @property
    def id(self) -> int:
        """Its number, in order of appearance in the sweep (``Bifurcation.cycle_branch`` refers
        to it)."""
    @property
    def first(self) -> int:
        """Index of the first swept value with the cycle."""
    @property
    def last(self) -> int:
        """Index of the last swept value with the cycle."""
    @property
    def start(self) -> CycleEnd | None:
        """Where it appears (in sweep order), None if it is there at the first value."""
    @property
    def end(self) -> CycleEnd | None:
        """Where it disappears, None if it is there at the last value."""
    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types."""

@final
class Bifurcation:
    """A sweep of input ``index``: the equilibria at each value and the events between them."""

    @property
    def index(self) -> int:
        """The index of the swept input."""
    @property
    def input(self) -> _Array:
        """The other inputs' values (entry ``index`` is swept)."""
    @property
    def values(self) -> _Array:
        """The swept values."""
    @property
    def equilibria(self) -> list[list[Equilibrium]]:
        """The equilibria at each value, sorted by state."""
    @property
    def events(self) -> list[Event]:
        """Folds and Hopf points, by input value."""
    @property
    def cycles(self) -> list[list[Cycle]]:
        """The attracting cycles at each value (empty lists unless the sweep searched for them)."""
    @property
    def cycle_branch(self) -> list[list[int]]:
        """The branch id of each cycle, parallel to ``cycles``: an index into ``branches``."""
    @property
    def branches(self) -> list[CycleBranch]:
        """The cycles followed across values, by id."""
    @property
    def retried(self) -> list[float]:
        """The values where the first search found an even number of equilibria and searched
        again with ``RETRY_STARTS`` (or the sweep's ``retry_starts``) starts."""
    @property
    def even(self) -> list[float]:
        """The values where the count of equilibria is still even: some were missed there."""
    def to_dict(self) -> dict[str, Any]:
        """As plain JSON types (cycles without their orbits)."""

def analysis_equilibria(
    net: Network,
    input: Sequence[float],
    *,
    starts: int = 512,
    tolerance: float = 1e-10,
    distinct: float = 1e-06,
    max_iterations: int = 100,
    seed: int = 0,
    retry_starts: int | None = None,
) -> list[Equilibrium]: ...
def analysis_cycles(
    net: Network,
    input: Sequence[float],
    *,
    starts: int = 8,
    steps_per_tau: int = 20,
    transient: float = 100.0,
    window: float = 100.0,
    at_rest: float = 1e-06,
    tolerance: float = 1e-05,
    orbit_points: int = 200,
    seed: int = 1,
) -> list[Cycle]: ...
def analysis_bifurcation(
    net: Network,
    input: Sequence[float],
    index: int,
    start: float,
    stop: float,
    *,
    steps: int = 101,
    starts: int = 128,
    tolerance: float = 1e-10,
    distinct: float = 1e-06,
    max_iterations: int = 100,
    seed: int = 0,
    cycle_starts: int = 0,
    retry_starts: int | None = None,
) -> Bifurcation: ...

# -- robots in a 2-D world, in closed loop ----------------------------------------------------

@final
class Fleet:
    """B robots in one 2-D world, one per row, stepped together (``dnnevo.robots.RobotWorld``)."""

    def __new__(cls, world: str | Mapping[str, Any], settings: Mapping[str, Any] | None = None) -> Fleet: ...
    @property
    def settings(self) -> dict[str, Any]: ...
    @property
    def world(self) -> dict[str, Any]: ...
    @property
    def rows(self) -> int: ...
    def reset(self, episodes: npt.ArrayLike, seed: int) -> None: ...
    def place(self, poses: npt.ArrayLike, pursuers: npt.ArrayLike | None = None) -> None: ...
    def step(self, wheels: npt.ArrayLike, active: npt.ArrayLike | None = None) -> None: ...
    @property
    def poses(self) -> _Array: ...
    @property
    def contacts(self) -> npt.NDArray[np.bool_]: ...
    @property
    def captured(self) -> npt.NDArray[np.bool_]: ...
    @property
    def episodes(self) -> npt.NDArray[np.uint64]: ...
    @property
    def ranges(self) -> _Array: ...
    @property
    def sectors(self) -> _Array: ...
    @property
    def pursuers(self) -> _Array: ...
    def __len__(self) -> int: ...
