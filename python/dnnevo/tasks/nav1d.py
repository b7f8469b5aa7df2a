"""One-dimensional navigation (paper §4): trial conditions, recorded chains of trials, the
success assessment, and the integrated system of §4.2, for networks evolved on the ``nav1d`` task.

The world (see ``crates/tasks/src/nav1d/world.rs`` and ``docs/nav1d.md``): a point agent on
[-20, 20] starts at 0 and moves at ``dx/dt = f(v_R) - f(v_L)``; the goal is at one end; a landmark
of width 4 is centred at ±10, on the goal's side (landmark-near) or the other side
(landmark-far). A trial ends at either end or after 1000 time steps, and 50 time steps of
reinforcement (1 if the goal was reached) follow. The agent moves and its sensors are read at
every Euler step of the network (``task_params.world = "continuous"``, the default), or once per
time step (``"stepped"``, dnnevo's world before; kept for comparison).

Success rule: on fresh conditions, at least 95% of the scored trials are done right (the goal
reached, or the environment classified right: ``f(v_C) >= 0.5`` means landmark-near).

>>> import dnnevo
>>> from dnnevo.tasks import nav1d
>>> from dnnevo import presets
>>> config = presets.get("nav1d-far")
>>> a, b = nav1d.cases(config)[:2]
>>> (a.environment, a.goal, a.landmark, b.goal, b.landmark)
('far', 'left', 10.0, 'right', -10.0)
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core, plot
from dnnevo._checks import bounded_count, builtin, nonnegative
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError
from dnnevo.evaluation import assessment
from dnnevo.evaluation.assessment import INDEPENDENT, Assessment, Rate, combine
from dnnevo.runs import RunDir, save_figure
from dnnevo.tasks.defaults import assess_extra, extra_lines, overall, rate_column


if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = [
    "ANALYSIS_CONDITIONS",
    "DEFAULT_TRIALS",
    "INPUT_NAMES",
    "MAIN_INPUT",
    "OUTPUT_NEURON",
    "NAME",
    "ROBOT_LIKE",
    "THRESHOLD",
    "UNIT",
    "Condition",
    "Part",
    "Record",
    "assess",
    "cases",
    "chains",
    "draw",
    "draw_system",
    "assess_extra",
    "extra_lines",
    "fresh_chains",
    "goal_rate_table",
    "goal_rates",
    "judge",
    "load_part",
    "overall",
    "params",
    "preface",
    "rate_column",
    "record",
    "recorded_trials",
    "scored_trials",
    "system_assess",
    "system_record",
]

NAME = "nav1d"
"""The task's name in a config."""

THRESHOLD: float = _core.NAV1D_SUCCESS_RATE
"""The fraction of scored trials that must be right: the core's own number
(``NAV1D_SUCCESS_RATE`` of the binding)."""

DEFAULT_TRIALS = 1000
"""``dnnevo assess``'s default: chains of trials (the slowest objective's take 0.2 s on one
core)."""

UNIT = "chains"
"""What a trial count counts."""

ROBOT_LIKE = False
"""One-dimensional navigation has no robot-like test."""

INPUT_NAMES = ["landmark", "reinforcement"]
"""The network's inputs, in order, as the analysis names them."""

ANALYSIS_CONDITIONS: dict[str, list[float]] = {"off": [0.0, 0.0], "landmark": [1.0, 0.0], "reinforcement": [0.0, 1.0]}
"""The constant input conditions ``dnnevo analyze`` finds the attractors of, by default (a network
    without the reinforcement input uses the first value of each)."""

MAIN_INPUT = 0
"""The input a bifurcation sweep varies by default: the one the task's behaviour turns on."""

OUTPUT_NEURON = 2
"""The neuron whose firing rate is the task's answer (``task_params.classifier`` overrides it)."""

CASES = (("far", "left"), ("far", "right"), ("near", "left"), ("near", "right"))
"""The paper's Fig. 2 environments A, B, C and D, in that order."""


Condition = _core.Nav1dCondition
"""One trial's world: ``Condition(environment, goal, start, landmark)`` with environment
``"far"``/``"near"``, goal ``"left"``/``"right"``, the agent's start and the landmark's centre."""

Record = _core.Nav1dRecord
"""A chain of trials, time step by time step, as the core records it (arrays of length T;
``outputs`` is (T, N); per trial ``conditions``, ``reached`` and ``classification``).

Time steps are counted from the start of each trial's moving phase and of its reinforcement
period; a moving phase that ends inside a time step ends with that partial time step. ``x`` and
``outputs`` are taken at the end of each time step, ``landmark`` is the fraction of its Euler
steps on the landmark (0 or 1 in the stepped world). Outcomes (``reached``, ``classification``)
come from every Euler step, not from these samples; ``classification`` is NaN for a network
without a classifier."""


@dataclass(frozen=True)
class Part:
    """One subnetwork of the integrated system: the config it was evolved with, and itself."""

    config: EvolutionConfig
    network: _core.Network


def _task(config: EvolutionConfig) -> _core.Nav1dTask:
    return builtin(config, NAME, _core.Nav1dTask)


def params(config: EvolutionConfig) -> dict[str, Any]:
    """The config's task settings with every default filled in, as the core reads them."""
    return _task(config).params()


def cases(config: EvolutionConfig) -> list[Condition]:
    """The four exact environment and goal cases of Fig. 2 (A: far/left, B: far/right, C:
    near/left, D: near/right), with the config's geometry."""
    task = _task(config)
    return [task.exact(e, g) for e, g in CASES]


def chain_len(config: EvolutionConfig) -> int:
    """Trials per chain of the config's success check: ``trials_per_environment`` for a
    ``single`` (or chained ``goal``) task, whose state carries from trial to trial, else 1."""
    return _task(config).chain_len


def chains(config: EvolutionConfig, seed: int, generation: int) -> list[list[Condition]]:
    """The chains of trials every individual of ``generation`` ran."""
    return _task(config).chains(nonnegative("seed", seed), nonnegative("generation", generation))


def fresh_chains(config: EvolutionConfig, count: int, trials: int, seed: int) -> list[list[Condition]]:
    """``count`` fresh chains of ``trials`` trials, each in a random environment of the config's
    ``environments``, each trial with a random goal side."""
    return _task(config).fresh_chains(bounded_count("count", count), bounded_count("trials", trials),
                                      nonnegative("seed", seed))


def record(
    config: EvolutionConfig, net: _core.Network, conditions: Sequence[Condition], *, reset: bool = True
) -> Record:
    """Runs ``net`` through a chain of trials (its state persisting between them), recorded;
    with ``reset=False`` it starts from ``net.state``."""
    return _task(config).record(net, list(conditions), reset)


def assess(config: EvolutionConfig, net: _core.Network, count: int, seed: int) -> dict[str, Any]:
    """Judges ``net`` on ``count`` fresh chains: ``{"rate", "success", "episodes", ...}``."""
    return _task(config).assess(net, bounded_count("count", count), nonnegative("seed", seed))


def goal_rates(episodes: Sequence[dict[str, Any]]) -> dict[str, npt.NDArray[np.float64]]:
    """The fraction of trials that reached the goal, by environment type (``"far"``,
    ``"near"``, ``"all"``) and trial index: an array of length k for each."""
    return _by_environment(episodes, lambda e: e["reached"])


def classifier_rates(episodes: Sequence[dict[str, Any]]) -> dict[str, npt.NDArray[np.float64]]:
    """The fraction of trials after which the classifier named the environment right
    (``f(v_C) >= 0.5`` exactly in landmark-near chains, read at the end of the trial's
    reinforcement period), by environment type and trial index, as :func:`goal_rates`."""
    return _by_environment(episodes, lambda e: [(c is not None and c >= 0.5) == (e["environment"] == "near")
                                                 for c in e["classification"]])


def _by_environment(episodes: Sequence[dict[str, Any]],
                    row: Callable[[dict[str, Any]], Sequence[bool]]) -> dict[str, npt.NDArray[np.float64]]:
    """The mean of ``row(episode)`` over the episodes of each environment type and of all."""
    out = {}
    for env in ("far", "near", "all"):
        rows = [row(e) for e in episodes if env in ("all", e["environment"])]
        out[env] = np.array(rows, dtype=float).mean(axis=0) if rows else np.array([])
    return out


def load_part(run_dir: str | Path, role: str | None = None) -> Part:
    """The config and champion of a ``nav1d`` run folder; ``role`` (e.g. ``"--far"``) names the
    folder in errors."""
    where = f"{role} {run_dir}" if role else str(run_dir)
    run = RunDir(Path(run_dir))
    config, table = run.read_config()
    try:
        _task(config)
    except ConfigError as e:
        raise ConfigError(f"{where}: {e}") from None
    return Part(config, run.read_best(config, table))


def _parts(classifier: Part, far: Part, near: Part) -> list[tuple[_core.Nav1dTask, _core.Network]]:
    return [(_task(p.config), p.network) for p in (classifier, far, near)]


def system_assess(
    classifier: Part, far: Part, near: Part, *, environments: int = 100, trials: int = 5,
    seed: int = 0, persist_state: bool = True,
) -> dict[str, Any]:
    """The integrated system on fresh environments: the classifier drives trial 1, its output
    picks the far or near network for trials 2..``trials``, whose state persists from trial to
    trial (reset each trial with ``persist_state=False``). Returns ``{"goal_rate",
    "classification_rate", "episodes"}``; see :func:`goal_rates` for the breakdown."""
    c, f, n = _parts(classifier, far, near)
    return _core.nav1d_system_assess(
        c, f, n, bounded_count("environments", environments), bounded_count("trials", trials),
        nonnegative("seed", seed), persist_state)


def system_record(
    classifier: Part, far: Part, near: Part, conditions: Sequence[Condition], *,
    persist_state: bool = True,
) -> tuple[Record, Record, str]:
    """One environment of the integrated system, recorded: the classifier's trial, the picked
    network's trials, and which it picked (``"far"`` or ``"near"``)."""
    c, f, n = _parts(classifier, far, near)
    return _core.nav1d_system_record(c, f, n, list(conditions), persist_state)


def scored_trials(objective: str, episode: dict[str, Any]) -> list[bool]:
    """Whether each scored trial of a nav1d chain was done right, as the task judges it: the
    goal reached (``goal``; trials 2.. with ``single``) or the environment classified right
    (``classify``: ``f(v_C) >= 0.5`` exactly in landmark-near environments)."""
    out = []
    for t, (condition, reached, f) in enumerate(
        zip(episode["conditions"], episode["reached"], episode["classification"], strict=True)
    ):
        if objective == "single" and t == 0:
            continue
        if objective == "classify":
            f = math.nan if f is None else f
            out.append(f >= 0.5 if condition["environment"] == "near" else f < 0.5)
        else:
            out.append(bool(reached))
    return out




def judge(config: EvolutionConfig, net: _core.Network, trials: int, seed: int, *,
          robot_like: bool = False) -> Assessment:
    """``net`` judged on ``trials`` fresh chains drawn from ``seed``: the rate of scored trials
    done right, against :data:`THRESHOLD`. Trials within one chain share the network's state, so
    with several scored trials per chain the interval counts each chain as one observation (the
    worst case; never too narrow)."""
    report = assess(config, net, trials, seed)
    objective = report["objective"]
    scored = [(e["environment"], scored_trials(objective, e)) for e in report["episodes"]]
    per_chain = max(len(s) for _, s in scored)
    if any(len(s) != per_chain for _, s in scored) or per_chain == 0:
        raise ConfigError(f"the nav1d chains score {sorted({len(s) for _, s in scored})} trials each; "
                          "judging needs the same number >= 1 in every chain")
    clustered = per_chain > 1

    def chain_rate(name: str, chains: list[list[bool]], threshold: float | None = None) -> Rate:
        k, n = sum(map(sum, chains)), per_chain * len(chains)
        return assessment.rate(name, k, n, threshold=threshold, effective_n=len(chains) if clustered else n)

    rates = [chain_rate(env, [s for e, s in scored if e == env]) for env in ("far", "near")
             if any(e == env for e, _ in scored)]
    overall_rate = chain_rate("overall", [s for _, s in scored], THRESHOLD)
    if abs(overall_rate.rate - report["rate"]) > 1e-12:
        raise RuntimeError(f"nav1d: the scored trials give {overall_rate.rate} but the task's rate is "
                          f"{report['rate']}; dnnevo.evaluation.assessment and the task disagree on what is scored")
    method = (f"Wilson score interval, 95%, clustered by chain: the {per_chain} scored trials of a "
              "chain share the network's state, so each chain counts as one observation (the "
              "worst case; never too narrow)" if clustered
              else INDEPENDENT + " (one scored trial per chain, each from a reset state)")
    return Assessment(
        task="nav1d", trials=trials, unit=UNIT, seed=seed, rates=[*rates, overall_rate],
        verdict=combine([r.verdict for r in [overall_rate] if r.verdict is not None]), method=method,
        details={"objective": objective, "scored_per_chain": per_chain,
                 "classify_weight": float(params(config)["classify_weight"])}, report=report,
    )


def goal_rate_table(episodes: Sequence[dict[str, Any]], first_scored: int) -> list[str]:
    """Goal rate by environment type and trial index, one line per environment type."""
    return _by_trial(goal_rates(episodes), episodes, first_scored)


def _by_trial(rates: dict[str, Any], episodes: Sequence[dict[str, Any]], first_scored: int) -> list[str]:
    """A table of ``rates`` by environment type and trial index, one line per environment type."""
    k = len(rates["all"])
    lines = [f"{'environment':>12} {'chains':>6}  " + " ".join(f"{'trial ' + str(t + 1):>8}" for t in range(k))]
    for env in ("far", "near", "all"):
        count = sum(1 for e in episodes if env in ("all", e["environment"]))
        if count:
            cells = " ".join(f"{r:>8.1%}" for r in rates[env])
            lines.append(f"{env:>12} {count:>6}  {cells}")
    if first_scored:
        lines.append(f"(trial 1 is for learning; trials {first_scored + 1}.. are scored)")
    return lines


def preface(where: Path, a: Assessment) -> list[str]:
    """What ``assess`` ran on a ``nav1d`` run, and the rates by case (``classify``) or by
    environment type and trial index."""
    objective = a.details["objective"]
    episodes = a.report["episodes"]
    lines = [f"{where}: champion ({objective}) on {a.trials} fresh chains (seed {a.seed})."]
    if objective == "classify":
        lines.append("A trial is right when f(v_C) >= 0.5 exactly in landmark-near environments.")
        lines.append(f"{'environment':>12} {'goal':>6} {'trials':>6} {'right':>7} {'mean f(v_C)':>12}")
        for env, goal in CASES:
            picked = [e for e in episodes if e["environment"] == env
                      and e["conditions"][0]["goal"] == goal]
            if picked:
                f = np.array([np.nan if e["classification"][0] is None else e["classification"][0]
                              for e in picked])
                right = (f >= 0.5) if env == "near" else (f < 0.5)
                lines.append(f"{env:>12} {goal:>6} {len(picked):>6} {right.mean():>7.1%} {f.mean():>12.3f}")
    else:
        lines += goal_rate_table(episodes, 1 if objective == "single" else 0)
    if objective == "single" and a.details.get("classify_weight", 0.0) > 0:
        lines.append("The classifier (shaped by classify_weight): trials after which it names the "
                     "environment right (f(v_C) >= 0.5 exactly in landmark-near chains).")
        lines += _by_trial(classifier_rates(episodes), episodes, 0)
    return lines


def draw(run: RunDir, config: EvolutionConfig, seed: int, *, animate: bool = False) -> list[str]:
    """``dnnevo plot`` for a ``nav1d`` run: Fig. 2 (x(t) in the four cases) and, for a network with
    a classifier, Fig. 3 (its traces in a landmark-near and a landmark-far trial)."""

    champion = run.read_best(config, run.read_config()[1])
    settings = params(config)
    k = settings["trials_per_environment"] if settings["objective"] == "single" else 1
    records = [record(config, champion, [c] * k) for c in cases(config)]
    _fig2(records, settings, f"{run.path.name}: the champion in environments A-D", run.path / "fig2-paths.png")
    written = ["fig2-paths.png"]
    if settings["objective"] in ("classify", "single"):
        classifier = int(settings["classifier"])
        motors = (int(settings["left_motor"]), int(settings["right_motor"]))
        fig, axes = plot.subplots(1, 2, figsize=(12, 4.5), layout="constrained")
        for ax, (env, goal) in zip(axes, [("near", "left"), ("far", "right")], strict=True):
            cond = next(c for c in cases(config) if (c.environment, c.goal) == (env, goal))
            rec = record(config, champion, [cond])
            plot_trial_traces(rec, ax, classifier=classifier, motors=motors, title=(
                f"landmark-{env}, goal {goal}: "
                f"{'reached' if rec.reached[0] else 'missed'}, f(v_C) = {rec.classification[0]:.2f}"))
        save_figure(fig, run.path / "fig3-classifier.png")
        plot.close(fig)
        written.append("fig3-classifier.png")
    return written


def _fig2(records: Sequence[Record | Sequence[Record]], settings: dict[str, Any], title: str, path: Path) -> None:

    fig, axes = plot.subplots(2, 2, figsize=(11, 6.5), layout="constrained", sharey=True)
    for ax, rec, letter in zip(axes.T.flat, records, "ABCD", strict=True):
        c = (rec if isinstance(rec, Record) else rec[0]).conditions[0]
        plot_path(rec, ax, half_length=float(settings["half_length"]),
                        landmark_width=float(settings["landmark_width"]),
                        title=f"{letter}: landmark-{c.environment}, goal {c.goal}")
    fig.suptitle(title)
    save_figure(fig, path)
    plot.close(fig)


def draw_system(parts: Sequence[Part], trials: int, path: Path, *, persist_state: bool = True) -> None:
    """Fig. 2 of the integrated system of ``parts`` (classifier, far, near): one environment per
    case, ``trials`` trials each, the goal on the same side, written to ``path``."""
    records = []
    for c in cases(parts[0].config):
        first, rest, _ = system_record(parts[0], parts[1], parts[2], [c] * trials,
                                             persist_state=persist_state)
        records.append([first, rest])
    _fig2(records, params(parts[0].config), "integrated system, one environment per case "
          f"({trials} trials, goal on the same side)", path)


def recorded_trials(config: EvolutionConfig, net: _core.Network, *,
                    seed: int) -> list[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
    """One fresh chain drawn from ``seed`` of the task's chain length (:func:`chain_len`: 5
    trials for nav1d-single, whose network learns its environment in trial 1), at least 2, as
    (firing rates (T, N), inputs (T, M): landmark and reinforcement), for the dynamical
    analysis."""
    chain = fresh_chains(config, 1, max(2, chain_len(config)), seed)[0]
    r = record(config, net, chain)
    return [(r.outputs, np.column_stack([r.landmark, r.reinforcement][: net.n_inputs]))]


def plot_path(
    record: Record | Sequence[Record],
    ax: Axes | None = None,
    *,
    half_length: float = 20.0,
    landmark_width: float = 4.0,
    title: str | None = None,
) -> Axes:
    """The paper's Fig. 2: the agent's position over time in a chain of trials, with each
    trial's landmark (shaded) and goal (a star at its end) marked, and trial boundaries dashed.
    ``record`` may be a list of records that follow one another (the integrated system's
    classifier trial, then the picked network's)."""
    parts = [record] if isinstance(record, Record) else list(record)
    ax = plot.axes(ax)
    moving = np.concatenate([p.moving for p in parts])
    x = np.where(moving, np.concatenate([p.x for p in parts]), np.nan)
    offsets = np.cumsum([0] + [len(p.conditions) for p in parts[:-1]])
    trial = np.concatenate([p.trial + k for p, k in zip(parts, offsets, strict=True)])
    conditions = [c for p in parts for c in p.conditions]
    reached_all = [r for p in parts for r in p.reached]
    t = np.arange(1, len(x) + 1)
    ax.plot(t, x, color="tab:blue", lw=1.4, label="agent x(t)")
    bounds = np.flatnonzero(np.diff(trial)) + 1
    edges = np.concatenate([[0], bounds, [len(t)]])
    for k, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        if k >= len(conditions):
            break
        c = conditions[k]
        ax.fill_between([a, b], c.landmark - landmark_width / 2, c.landmark + landmark_width / 2,
                        color="tab:orange", alpha=0.3, lw=0, label="landmark" if k == 0 else None)
        goal = half_length if c.goal == "right" else -half_length
        reached = k < len(reached_all) and reached_all[k]
        ax.plot([b if reached else a], [goal], marker="*", ms=11, ls="none",
                color="tab:green" if reached else "tab:red",
                label=("goal" if k == 0 else None))
        if k:
            ax.axvline(a, color="k", lw=0.6, ls="--")
    ax.axhline(half_length, color="0.4", lw=0.8)
    ax.axhline(-half_length, color="0.4", lw=0.8)
    ax.set_ylim(-1.1 * half_length, 1.1 * half_length)
    ax.set_xlim(0, len(t))
    ax.set_xlabel("time step")
    ax.set_ylabel("position x")
    ax.legend(loc="lower right", fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return ax


def plot_trial_traces(
    record: Record, ax: Axes | None = None, *, classifier: int = 2,
    motors: tuple[int, int] = (0, 1), title: str | None = None,
) -> Axes:
    """The paper's Fig. 3: landmark and reinforcement inputs and every neuron's output over a
    trial, with the classifier's 0.5 line."""
    n = record.outputs.shape[1]
    labels = [f"neuron {i}" for i in range(n)]
    labels[motors[0]] = f"left motor ({motors[0]})"
    labels[motors[1]] = f"right motor ({motors[1]})"
    if classifier < n:
        labels[classifier] = f"classifier ({classifier})"
    return plot.plot_traces({"landmark": record.landmark, "reinforcement": record.reinforcement},
                       record.outputs, ax, labels=labels, highlight=classifier if classifier < n else None,
                       title=title)
