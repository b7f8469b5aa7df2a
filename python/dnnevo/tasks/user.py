"""A user's closed-loop task (``config.task = "python:module.Class"``, see
:mod:`dnnevo.closedloop.named`) as a :class:`~dnnevo.tasks.protocol.Task`, so that ``dnnevo
assess`` judges its champions as it judges the built-in tasks'.

The success rule is the task's own: its class defines ``success_rate``, the fraction of fresh
episodes that must succeed, and ``success(returns, lengths)``, which says which episodes
succeeded from their returns and lengths (one value per row of the last rollout: shape (E,),
one network's episodes, when a champion is judged; every network's rows when a run validates
its candidates). The
fresh episodes are drawn with ``purpose="evaluate"``, which no run draws from.

``dnnevo analyze`` analyses a Python task whose class declares what it needs, an
:class:`~dnnevo.tasks.protocol.Analysis` as its ``analysis`` attribute (:func:`analysed`); its
real trials are fresh episodes recorded step by step (:func:`record`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, cast

import numpy as np
import numpy.typing as npt

from dnnevo import _core, plot
from dnnevo.closedloop import named
from dnnevo.closedloop.loop import observations, read_only
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError
from dnnevo.evaluation.assessment import INDEPENDENT, Assessment, rate
from dnnevo.runs import RunDir, save_figure
from dnnevo.tasks.defaults import assess_extra, extra_lines, overall, rate_column
from dnnevo.tasks.protocol import Analysis, View

__all__ = ["DEFAULT_TRIALS", "Episode", "UserTask", "analysed", "record"]

_Array = npt.NDArray[np.float64]

#: ``dnnevo assess``'s default count of fresh episodes.
DEFAULT_TRIALS = 200

#: Fresh episodes that ``dnnevo plot`` draws (:meth:`UserTask.draw`).
DRAWN_EPISODES = 3


class UserTask:
    """The :class:`~dnnevo.tasks.protocol.Task` of the Python task ``name``. Making one imports
    nothing; judging imports the task's module."""

    DEFAULT_TRIALS = DEFAULT_TRIALS
    UNIT = "episodes"
    ROBOT_LIKE = False
    INPUT_NAMES: list[str] = []
    ANALYSIS_CONDITIONS: dict[str, list[float]] = {}
    MAIN_INPUT = 0
    OUTPUT_NEURON = 0
    ANALYSIS_VIEWS: Sequence[View] = ()
    analysis: Analysis | None = None
    """The class's analysis declaration, once :func:`analysed` has read it."""

    rate_column = staticmethod(rate_column)
    overall = staticmethod(overall)
    assess_extra = staticmethod(assess_extra)
    extra_lines = staticmethod(extra_lines)

    def __init__(self, name: str) -> None:
        self.NAME = name
        self.THRESHOLD = float("nan")  # the class's success_rate, known once judged

    def judge(self, config: EvolutionConfig, net: _core.Network, trials: int, seed: int, *,
              robot_like: bool = False) -> Assessment:
        """``net`` on ``trials`` fresh episodes drawn from ``seed``, by the class's rule."""
        ok, self.THRESHOLD, result = named.closed_loop(config).judged(net, trials, seed, "evaluate")
        overall_rate = rate("episodes", int(ok.sum()), trials, threshold=self.THRESHOLD)
        return Assessment(
            task=config.task, trials=trials, unit=self.UNIT, seed=seed, rates=[overall_rate],
            verdict=overall_rate.verdict or "undecided", method=INDEPENDENT,
            details={"mean_return": float(result.returns.mean()),
                     "mean_length": float(result.lengths.mean()),
                     "all_alike": bool(trials > 1 and np.ptp(result.returns) == 0
                                       and np.ptp(result.lengths) == 0)},
        )

    def preface(self, where: Path, a: Assessment) -> list[str]:
        """What ``assess`` ran, and the episodes' mean return and length; a warning when every
        episode gave the same return and length, as the episodes of a task that draws nothing
        from ``rng`` do: they are then one trial repeated, and the interval, which counts them as
        independent, is too narrow."""
        d = a.details
        lines = [f"{where}: champion on {a.trials} fresh episodes (seed {a.seed}); mean return "
                 f"{d['mean_return']:.4g}, mean length {d['mean_length']:.1f} steps."]
        if d.get("all_alike"):
            lines.append(f"note: all {a.trials} episodes gave the same return and length, as a task that "
                         "draws nothing from rng gives (or one whose episodes all end alike); if it is "
                         "such a task they are one trial repeated, and the interval below, which counts "
                         "them as independent, is too narrow (docs/closed-loop.md)")
        return lines

    def draw(self, run: RunDir, config: EvolutionConfig, seed: int, *,
             animate: bool = False) -> list[str]:
        """``episodes.png``: the champion on the first :data:`DRAWN_EPISODES` of the fresh
        episodes that :meth:`judge` draws from ``seed``, one panel each: every observation (named
        as the class's analysis declaration names it) and the reward at each step, each scaled
        onto its band with its range in the label, and every neuron's firing rate over the
        episode, with the episode's return and length. For robots in a world (a
        :class:`~dnnevo.robots.RobotWorld`), ``paths.png`` too: the room and each episode's
        path, and the pursuers'. Imports the task's module."""
        champion = run.read_best(config, run.read_config()[1])
        worlds: list[dict[str, Any]] = []
        episodes = record(config, champion, DRAWN_EPISODES, seed=seed,
                          probe=lambda env: _robot_state(env, worlds))
        fig, axes = plot.subplots(1, len(episodes), figsize=(4.5 * len(episodes), 1.5 + 0.6 * (
            config.n_inputs + config.size)), layout="constrained", squeeze=False)
        names = _input_names(config)
        for e, (ax, ep) in enumerate(zip(axes[0], episodes, strict=True)):
            shown = {}
            traces = [(names[k] if names else f"input {k}", ep.inputs[:, k]) for k in range(ep.inputs.shape[1])]
            for name, x in [*traces, ("reward", np.asarray(ep.rewards, dtype=float))]:
                low, high = float(x.min()), float(x.max())
                span = high - low
                shown[f"{name} [{low:.3g}, {high:.3g}]"] = (x - low) / span if span > 0 else x * 0 + 0.5
            plot.plot_traces(shown, ep.outputs, ax, title=(
                f"episode {e}: return {np.cumsum(ep.rewards)[-1]:.4g}, {len(ep.rewards)} steps"))
        fig.suptitle(f"{run.path.name}: the champion on fresh episodes (seed {seed})", fontsize=10)
        save_figure(fig, run.path / "episodes.png")
        plot.close(fig)
        if not worlds:
            return ["episodes.png"]
        fig, axes = plot.subplots(1, len(episodes), figsize=(4.5 * len(episodes), 4.2),
                                  layout="constrained", squeeze=False)
        for e, (ax, ep) in enumerate(zip(axes[0], episodes, strict=True)):
            plot.plot_paths(worlds[0], ep.probed("pose"), ax, pursuers=ep.probed("pursuers"), title=(
                f"episode {e}: return {np.cumsum(ep.rewards)[-1]:.4g}, {len(ep.rewards)} steps"))
        axes[0, 0].legend(loc="upper left", fontsize=8, framealpha=0.9)
        fig.suptitle(f"{run.path.name}: the champion's robot on fresh episodes (seed {seed}; "
                     "circle: start, square: end)", fontsize=10)
        save_figure(fig, run.path / "paths.png")
        plot.close(fig)
        return ["episodes.png", "paths.png"]

    def recorded_trials(self, config: EvolutionConfig, net: _core.Network, *,
                        seed: int) -> list[tuple[_Array, _Array]]:
        """The first :attr:`Analysis.episodes` of the fresh episodes :meth:`judge` draws from
        ``seed``, recorded (:func:`record`); a task read without :func:`analysed` has none."""
        if self.analysis is None:
            raise ConfigError(_refusal(config.task))
        return [(e.outputs, e.inputs) for e in record(config, net, self.analysis.episodes, seed=seed)]


def _robot_state(env: Any, worlds: list[dict[str, Any]]) -> dict[str, npt.ArrayLike]:
    """What ``paths.png`` draws of an environment with robots in a world (a ``fleet``, as
    :class:`~dnnevo.robots.RobotWorld` has): every row's pose and its pursuers', its world kept
    in ``worlds``; nothing of any other environment."""
    fleet = getattr(env, "fleet", None)
    if not isinstance(fleet, _core.Fleet):
        return {}
    if not worlds:
        worlds.append(dict(env.fleet.world))
    return {"pose": fleet.poses, "pursuers": fleet.pursuers}


def _refusal(task: str) -> str:
    return (f"task {task!r} has no analysis defaults; its class must declare them as "
            "analysis = dnnevo.tasks.protocol.Analysis(input_names=..., conditions=..., "
            "main_input=..., output_neuron=...) (docs/analysis.md)")


def _input_names(config: EvolutionConfig) -> list[str] | None:
    """The inputs' names that the class's analysis declaration gives, for the figures; None
    without one, or with one that :func:`analysed` refuses (``dnnevo analyze`` says why)."""
    if getattr(named.environment_class(config.task), "analysis", None) is None:
        return None
    try:
        return list(analysed(config).INPUT_NAMES)
    except ConfigError:
        return None


def analysed(config: EvolutionConfig) -> UserTask:
    """The Python task of ``config`` with its class's :class:`~dnnevo.tasks.protocol.Analysis`
    read into the names ``dnnevo analyze`` uses (:attr:`UserTask.INPUT_NAMES`, ...), checked
    against the run's network; a class that declares none is a one-line
    :class:`~dnnevo.ConfigError` that says what to declare. Imports the task's module."""
    cls = named.environment_class(config.task)
    a = getattr(cls, "analysis", None)
    if not isinstance(a, Analysis):
        raise ConfigError(_refusal(config.task))
    m, where = config.n_inputs, f"{cls.__name__}.analysis"

    def index(name: str, value: Any, n: int, what: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < n:
            raise ConfigError(f"{where}.{name} is {value!r}; the {what} are 0..{n - 1}")
        return value

    if isinstance(a.input_names, str) or not all(isinstance(x, str) for x in a.input_names):
        raise ConfigError(f"{where}.input_names is {a.input_names!r}; expected a list of names")
    if len(a.input_names) != m:
        raise ConfigError(f"{where} names {len(a.input_names)} inputs; the run's network has {m}")
    if not a.conditions:
        raise ConfigError(f"{where} has no conditions; it needs at least one input vector")
    conditions = {}
    for name, v in a.conditions.items():
        try:
            values = [float(x) for x in v]
        except (TypeError, ValueError):
            raise ConfigError(f"{where}: condition {name!r} is {v!r}; expected {m} numbers") from None
        if len(values) != m or not all(math.isfinite(x) for x in values):
            raise ConfigError(f"{where}: condition {name!r} is {v!r}; expected {m} finite numbers, one per input")
        conditions[str(name)] = values
    if m > 0:  # a network without sensors has no input to sweep
        index("main_input", a.main_input, m, "inputs")
    index("output_neuron", a.output_neuron, config.size, "neurons")
    if isinstance(a.episodes, bool) or not isinstance(a.episodes, int) or a.episodes < 1:
        raise ConfigError(f"{where}.episodes is {a.episodes!r}; expected a whole number >= 1")
    task = UserTask(config.task)
    task.analysis = a
    task.INPUT_NAMES = list(a.input_names)
    task.ANALYSIS_CONDITIONS = conditions
    task.MAIN_INPUT, task.OUTPUT_NEURON = a.main_input, a.output_neuron
    task.ANALYSIS_VIEWS = tuple(a.views)
    return task


@dataclass(frozen=True)
class Episode:
    """One recorded episode, one row per time step ``t``: the inputs the network was given, the
    firing rates it answered with, and what ``probe`` read of the environment when the inputs
    were observed (before the step that the rates drive)."""

    inputs: _Array
    """(T, M)."""
    outputs: _Array
    """(T, N)."""
    rewards: _Array
    """(T,): the reward of each step."""
    probes: dict[str, npt.NDArray[Any]]
    """Each probed name's values, (T, ...)."""
    after: dict[str, npt.NDArray[Any]] = field(default_factory=dict)
    """Each probed name's values after the episode's last step, (...): where a robot ended."""

    def probed(self, name: str) -> npt.NDArray[Any]:
        """``name``'s values at every step and after the last, (T + 1, ...)."""
        return np.concatenate([self.probes[name], self.after[name][None]])


Probe = Callable[[Any], dict[str, npt.ArrayLike]]
"""Reads the environment's state: each name's values, one row per episode (B, ...)."""

Shown = Callable[[int, _Array], _Array]
"""What the networks are shown at step ``t`` of the observations (B, M) the environment gave."""


def record(config: EvolutionConfig, net: _core.Network, episodes: int, *, seed: int,
           probe: Probe | None = None, shown: Shown | None = None) -> list[Episode]:
    """``net`` on ``episodes`` fresh episodes of ``config``'s Python task, step by step: the same
    episodes, with the same integration, that :meth:`UserTask.judge` (``dnnevo assess``) draws
    from ``seed`` (``purpose="evaluate"``, which no run draws from), each to its end or to the
    task's ``max_steps``. ``probe`` reads the environment at each step (:class:`Episode`);
    ``shown``, when given, changes what the network is shown (a probe of its own: the
    episodes then differ from the judged ones from the first changed step on)."""
    loop = named.closed_loop(config)
    env, s = loop.env, config.integrator
    max_steps = int(loop.settings["max_steps"])  # type: ignore[call-overload]
    method = cast(Literal["euler", "rk4"], s.method)
    batch = _core.Batch([net], replicas=episodes, dt=s.dt, substeps=s.substeps, method=method,
                        precision=cast(Literal["f64", "f32"], config.precision))
    batch.reset()
    rng = np.random.default_rng(_core.condition_seed(seed, 0, "evaluate"))
    m = batch.n_inputs
    # Checked as a rollout checks them: a task that breaks the protocol is a one-line TaskError.
    obs = np.asarray(observations(env.reset(np.arange(episodes, dtype=np.int64), rng), env, "reset", episodes, m),
                     dtype=float)
    active = np.ones(episodes, dtype=bool)
    lengths = np.full(episodes, max_steps, dtype=np.int64)
    if max_steps < 1:
        raise ConfigError(f"task_params.max_steps is {max_steps}: no step to record")
    rates = np.empty((episodes, batch.size))
    seen_rates, seen_active = read_only(rates), read_only(active)  # the task may not write them
    ins: list[_Array] = []
    outs: list[_Array] = []
    paid: list[_Array] = []
    probed: list[dict[str, npt.NDArray[Any]]] = []
    for t in range(max_steps):
        if shown is not None:
            obs = np.asarray(shown(t, obs), dtype=float)
        batch.step(obs, active=active, out=rates)
        ins.append(obs.copy())
        outs.append(rates.copy())
        if probe is not None:
            probed.append({k: np.array(v) for k, v in probe(env).items()})
        seen, reward, done = env.step(seen_rates, seen_active)
        paid.append(np.array(np.broadcast_to(np.asarray(reward, dtype=float), (episodes,))))
        obs = np.array(observations(seen, env, "step", episodes, m), dtype=float)  # a copy: never the rates
        ended = active & np.asarray(done, dtype=bool)
        lengths[ended] = t + 1
        active &= ~ended
        if not active.any():
            break
    if probe is not None:  # after the last step: an ended row is no longer moved
        probed.append({k: np.array(v) for k, v in probe(env).items()})
    stacked_in, stacked_out, stacked_paid = np.stack(ins, axis=1), np.stack(outs, axis=1), np.stack(paid, axis=1)
    names = probed[0].keys() if probed else ()
    stacked = {k: np.stack([p[k] for p in probed], axis=1) for k in names}
    return [Episode(stacked_in[e, :n], stacked_out[e, :n], stacked_paid[e, :n],
                    {k: v[e, :n] for k, v in stacked.items()}, {k: v[e, n] for k, v in stacked.items()})
            for e, n in enumerate(lengths.tolist())]
