"""Wander without touching anything: the obstacle avoidance of Floreano and Mondada (1994),
*Automatic creation of an autonomous agent*, written with :class:`~dnnevo.robots.RobotWorld` as
a user would write a 2-D robot task.

The robot starts anywhere in the room, facing anywhere, and drives for :attr:`Avoid.steps`
steps of 0.1 s (30 s by default) with its ring of eight sonars as inputs. Each step pays
``(forward * straight - contact) / steps``: ``forward`` is the mean wheel speed as a fraction of
the top speed (0 when reversing), ``straight`` is ``1 - |v_right - v_left| / (2 max_speed)``,
and ``contact`` is 1 when a wall or box stopped the robot. A return is at most 1 (full speed
ahead all along, which no room allows).

An episode succeeds (:meth:`Avoid.success`) when the robot touched nothing and drove at least
:attr:`Avoid.min_distance` metres forwards (7.5 m by default: a quarter of top speed on average;
driving backwards counts against it, turning on the spot does not count). A network succeeds
when :attr:`Avoid.success_rate` of its episodes do.

>>> import dnnevo
>>> from dnnevo.closedloop import rollout
>>> from dnnevo.robots import Avoid
>>> env = Avoid(steps=100)
>>> result = rollout([dnnevo.Network.random(4, 8, seed=1)], env, episodes=3, max_steps=env.steps)
>>> result.lengths.tolist(), env.success(result.returns[0], result.lengths[0]).shape
([[100, 100, 100]], (3,))
"""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo.errors import InvalidArgumentError
from dnnevo.robots.world import RobotWorld

__all__ = ["Avoid"]


class Avoid(RobotWorld):
    """Drive fast and straight, touching nothing; see the module docs. ``steps`` is the
    episode's length and ``min_distance`` (metres) the path a successful episode drives, by
    default a quarter of what top speed would cover. Every other argument is
    :class:`RobotWorld`'s."""

    success_rate = 0.9
    """The fraction of episodes in which a network must succeed."""

    def __init__(self, world: str | PathLike[str] | Mapping[str, Any] = "landmark1", *,
                 steps: int = 300, min_distance: float | None = None, **settings: Any) -> None:
        super().__init__(world, **settings)
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            raise InvalidArgumentError(f"steps is {steps!r}; expected a whole number >= 1")
        self.steps = steps
        duration = steps * self.settings["dt"]
        if min_distance is None:
            min_distance = 0.25 * self.max_speed * duration
        if isinstance(min_distance, bool) or not isinstance(min_distance, float | int) \
                or not min_distance >= 0:
            raise InvalidArgumentError(f"min_distance is {min_distance!r}; expected metres >= 0")
        self.min_distance = float(min_distance)

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator
              ) -> npt.NDArray[np.float64]:
        obs = super().reset(episodes, rng)
        self.touched = np.zeros(len(episodes), dtype=bool)
        """Which rows' robots touched a wall or box during the episode."""
        self.distance = np.zeros(len(episodes))
        """How far each row's robot drove forwards, in metres (backwards counts against it)."""
        self._pose = self.fleet.poses
        return obs

    def reward(self, active: npt.NDArray[np.bool_]) -> npt.NDArray[np.float64]:
        """``(forward * straight - contact) / steps`` for the step just taken."""
        left, right = self.wheels[:, 0], self.wheels[:, 1]
        forward = np.clip((left + right) / (2.0 * self.max_speed), 0.0, 1.0)
        straight = 1.0 - np.abs(right - left) / (2.0 * self.max_speed)
        contact = self.fleet.contacts & active
        self.touched |= contact
        pose = self.fleet.poses
        # The step's displacement along its mean heading: the robot's own forward motion.
        turn = np.mod(pose[:, 2] - self._pose[:, 2] + np.pi, 2.0 * np.pi) - np.pi
        heading = self._pose[:, 2] + 0.5 * turn
        moved = pose[:, :2] - self._pose[:, :2]
        ahead = moved[:, 0] * np.cos(heading) + moved[:, 1] * np.sin(heading)
        self.distance += np.where(active, ahead, 0.0)
        self._pose = pose
        return (forward * straight - contact) / self.steps

    def done(self, active: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
        """Every episode ends after :attr:`steps` steps."""
        return np.full(self.fleet.rows, self.t >= self.steps)

    def success(self, returns: npt.NDArray[np.float64], lengths: npt.NDArray[np.int64]
                ) -> npt.NDArray[np.bool_]:
        """Which episodes of the last rollout ran to the end, touching nothing and driving at
        least :attr:`min_distance` forwards."""
        return np.asarray(~self.touched & (self.distance >= self.min_distance)
                          & (lengths >= self.steps))
