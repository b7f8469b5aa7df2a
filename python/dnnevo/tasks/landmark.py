"""Landmark recognition (paper §3): recorded robot trials and the assessment, robot-like or not,
for networks evolved on the ``landmark`` task.

A trial (see ``crates/tasks/src/landmark/mod.rs``): a Nomad-200-like robot starts at a random
pose in a 6 m x 5 m room, finds a wall and follows it counter-clockwise; its left sonar's range
``d`` feeds the network as ``min(1, 0.5 / d)`` every 0.1 s. After 45 s the classifier neuron's
output ``f`` is read: ``f < 0.5`` means landmark 1 (two crates pushed together), else landmark 2
(the crates 0.6 m apart).

Success rule: at least 95% of fresh trials classified right. ``robot_like=True`` adds sonar
noise, specular misses and a jittered room: our stand-in for the paper's real-robot test.

>>> from dnnevo.tasks import landmark
>>> world = landmark.default_world(2)
>>> world["room"], len(world["boxes"])
([6.0, 5.0], 2)
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.tasks._checks import bounded_count, nonnegative, task_params
from dnnevo.config import EvolutionConfig
from dnnevo.errors import InvalidArgumentError

__all__ = ["Record", "assess", "cast_rays", "default_world", "record"]


@dataclass(frozen=True)
class Record:
    """One trial, step by step (arrays of length T; ``outputs`` is (T, N), ``poses`` (T, 3) as
    x, y, heading, ``echoes`` (T, 2) with NaN where nothing echoed)."""

    landmark: int
    world: dict[str, Any]
    input: npt.NDArray[np.float64]
    range: npt.NDArray[np.float64]
    poses: npt.NDArray[np.float64]
    echoes: npt.NDArray[np.float64]
    outputs: npt.NDArray[np.float64]
    classification: float


def _params(config: EvolutionConfig) -> str:
    return task_params(config, "landmark")


def _landmark(n: int) -> int:
    if n not in (1, 2) or isinstance(n, bool):
        raise InvalidArgumentError(f"landmark is {n!r}; it must be 1 or 2")
    return n


def record(
    config: EvolutionConfig, net: _core.Network, landmark: int, *, seed: int = 0, trial: int = 0,
    robot_like: bool = False,
) -> Record:
    """Runs ``net`` through fresh trial ``trial`` of ``seed`` with ``landmark`` (1 or 2)."""
    _landmark(landmark)
    d = json.loads(_core.landmark_record(_params(config), net, nonnegative("landmark", landmark),
                                         nonnegative("seed", seed), nonnegative("trial", trial), robot_like))
    s = d["sensing"]
    echoes = np.array([[np.nan, np.nan] if p is None else p for p in s["echoes"]], dtype=float)
    return Record(
        landmark=s["landmark"],
        world=s["world"],
        input=np.array(s["input"], dtype=float),
        range=np.array(s["range"], dtype=float),
        poses=np.array(s["poses"], dtype=float).reshape(-1, 3),
        echoes=echoes.reshape(-1, 2),
        outputs=np.array(d["outputs"], dtype=float).reshape(len(s["input"]), -1),
        classification=d["classification"],
    )


def assess(
    config: EvolutionConfig, net: _core.Network, per_landmark: int, seed: int, *,
    robot_like: bool = False,
) -> dict[str, Any]:
    """Judges ``net`` on ``per_landmark`` fresh trials of each landmark: ``{"confusion"
    (rows: true landmark 1, 2; columns: answer 1, 2), "rate", "success", "trials"}``."""
    return json.loads(_core.landmark_assess(_params(config), net, bounded_count("per_landmark", per_landmark),
                                            nonnegative("seed", seed), robot_like))


def default_world(n: int) -> dict[str, Any]:
    """The shipped world of landmark ``n`` (1 or 2) as a dict (room, boxes, start region); pass
    a changed copy as ``task_params["landmark1"]`` or ``["landmark2"]``."""
    result: dict[str, Any] = json.loads(_core.sim2d_landmark_world(_landmark(n)))
    return result


def cast_rays(
    world: dict[str, Any], origins: npt.ArrayLike, directions: npt.ArrayLike, max_distance: float = 6.5
) -> npt.NDArray[np.float64]:
    """Distance along each ray (rows of the (K, 2) ``origins`` and ``directions``) to the
    nearest wall or box of ``world``, or ``max_distance`` when nothing is nearer."""
    o = np.ascontiguousarray(origins, dtype=float)
    d = np.ascontiguousarray(directions, dtype=float)
    if o.ndim != 2 or o.shape[1:] != (2,) or o.shape != d.shape:
        raise InvalidArgumentError(
            f"origins has shape {o.shape} and directions {d.shape}; both must be (K, 2)")
    return _core.sim2d_cast_rays(json.dumps(world), o, d, float(max_distance))
