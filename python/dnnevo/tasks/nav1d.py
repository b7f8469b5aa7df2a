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
>>> from dnnevo.experiments import presets
>>> config = presets.get("nav1d-far")
>>> a, b = nav1d.cases(config)[:2]
>>> (a.environment, a.goal, a.landmark, b.goal, b.landmark)
('far', 'left', 10.0, 'right', -10.0)
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.tasks._checks import bounded_count, nonnegative, task_params
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError

__all__ = [
    "Condition",
    "Part",
    "Record",
    "assess",
    "cases",
    "chains",
    "fresh_chains",
    "goal_rates",
    "load_part",
    "record",
    "system_assess",
    "system_record",
]

CASES = (("far", "left"), ("far", "right"), ("near", "left"), ("near", "right"))
"""The paper's Fig. 2 environments A, B, C and D, in that order."""


@dataclass(frozen=True)
class Condition:
    """One trial's world: environment ``"far"``/``"near"``, goal ``"left"``/``"right"``, the
    agent's start and the landmark's centre."""

    environment: str
    goal: str
    start: float
    landmark: float


@dataclass(frozen=True)
class Record:
    """A chain of trials, time step by time step (arrays of length T; ``outputs`` is (T, N)).

    Time steps are counted from the start of each trial's moving phase and of its reinforcement
    period; a moving phase that ends inside a time step ends with that partial time step. ``x``
    and ``outputs`` are taken at the end of each time step, ``landmark`` is the fraction of its
    Euler steps on the landmark (0 or 1 in the stepped world). Outcomes (``reached``,
    ``classification``) come from every Euler step, not from these samples."""

    conditions: list[Condition]
    x: npt.NDArray[np.float64]
    landmark: npt.NDArray[np.float64]
    reinforcement: npt.NDArray[np.float64]
    outputs: npt.NDArray[np.float64]
    trial: npt.NDArray[np.int64]
    moving: npt.NDArray[np.bool_]
    reached: list[bool]
    classification: list[float]
    final_state: npt.NDArray[np.float64]


@dataclass(frozen=True)
class Part:
    """One subnetwork of the integrated system: the config it was evolved with, and itself."""

    config: EvolutionConfig
    network: _core.Network


def _params(config: EvolutionConfig) -> str:
    return task_params(config, "nav1d")


def _conditions(items: list[dict[str, Any]]) -> list[Condition]:
    return [Condition(**c) for c in items]


def _to_json(conditions: Sequence[Condition]) -> str:
    return json.dumps([asdict(c) for c in conditions])


def cases(config: EvolutionConfig) -> list[Condition]:
    """The four exact environment and goal cases of Fig. 2 (A: far/left, B: far/right, C:
    near/left, D: near/right), with the config's geometry."""
    params = _params(config)
    return [Condition(**json.loads(_core.nav1d_exact(params, e, g))) for e, g in CASES]


def chain_len(config: EvolutionConfig) -> int:
    """Trials per chain of the config's success check: ``trials_per_environment`` for a
    ``single`` (or chained ``goal``) task, whose state carries from trial to trial, else 1."""
    return _core.nav1d_chain_len(_params(config))


def chains(config: EvolutionConfig, seed: int, generation: int) -> list[list[Condition]]:
    """The chains of trials every individual of ``generation`` ran."""
    return [_conditions(c) for c in json.loads(
        _core.nav1d_chains(_params(config), nonnegative("seed", seed), nonnegative("generation", generation)))]


def fresh_chains(config: EvolutionConfig, count: int, trials: int, seed: int) -> list[list[Condition]]:
    """``count`` fresh chains of ``trials`` trials, each in a random environment of the config's
    ``environments``, each trial with a random goal side."""
    return [_conditions(c) for c in json.loads(
        _core.nav1d_fresh_chains(_params(config), bounded_count("count", count), bounded_count("trials", trials),
                                 nonnegative("seed", seed)))]


def _record(d: dict[str, Any]) -> Record:
    return Record(
        conditions=_conditions(d["conditions"]),
        x=np.array(d["x"], dtype=float),
        landmark=np.array(d["landmark"], dtype=float),
        reinforcement=np.array(d["reinforcement"], dtype=float),
        outputs=np.array(d["outputs"], dtype=float).reshape(len(d["x"]), len(d["final_state"])),
        trial=np.array(d["trial"], dtype=np.int64),
        moving=np.array(d["moving"], dtype=bool),
        reached=list(d["reached"]),
        classification=[float("nan") if c is None else c for c in d["classification"]],
        final_state=np.array(d["final_state"], dtype=float),
    )


def record(
    config: EvolutionConfig, net: _core.Network, conditions: Sequence[Condition], *, reset: bool = True
) -> Record:
    """Runs ``net`` through a chain of trials (its state persisting between them), recorded;
    with ``reset=False`` it starts from ``net.state``."""
    return _record(json.loads(_core.nav1d_record(_params(config), net, _to_json(conditions), reset)))


def assess(config: EvolutionConfig, net: _core.Network, count: int, seed: int) -> dict[str, Any]:
    """Judges ``net`` on ``count`` fresh chains: ``{"rate", "success", "episodes", ...}``."""
    return json.loads(_core.nav1d_assess(_params(config), net, bounded_count("count", count), nonnegative("seed", seed)))


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
    from dnnevo.runs.rundir import RunDir

    where = f"{role} {run_dir}" if role else str(run_dir)
    run = RunDir(Path(run_dir))
    config, table = run.read_config()
    try:
        _params(config)
    except ConfigError as e:
        raise ConfigError(f"{where}: {e}") from None
    return Part(config, run.read_best(config, table))


def _parts(classifier: Part, far: Part, near: Part) -> list[tuple[str, _core.Network]]:
    return [(_params(p.config), p.network) for p in (classifier, far, near)]


def system_assess(
    classifier: Part, far: Part, near: Part, *, environments: int = 100, trials: int = 5,
    seed: int = 0, persist_state: bool = True,
) -> dict[str, Any]:
    """The integrated system on fresh environments: the classifier drives trial 1, its output
    picks the far or near network for trials 2..``trials``, whose state persists from trial to
    trial (reset each trial with ``persist_state=False``). Returns ``{"goal_rate",
    "classification_rate", "episodes"}``; see :func:`goal_rates` for the breakdown."""
    c, f, n = _parts(classifier, far, near)
    return json.loads(_core.nav1d_system_assess(
        c, f, n, bounded_count("environments", environments), bounded_count("trials", trials),
        nonnegative("seed", seed), persist_state))


def system_record(
    classifier: Part, far: Part, near: Part, conditions: Sequence[Condition], *,
    persist_state: bool = True,
) -> tuple[Record, Record, str]:
    """One environment of the integrated system, recorded: the classifier's trial, the picked
    network's trials, and which it picked (``"far"`` or ``"near"``)."""
    c, f, n = _parts(classifier, far, near)
    d = json.loads(_core.nav1d_system_record(c, f, n, _to_json(conditions), persist_state))
    return _record(d["first"]), _record(d["rest"]), d["chosen"]
