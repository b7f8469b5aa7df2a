"""Predator avoidance (Yamauchi and Beer 1994, §3.2, after Yamauchi 1993): "DNNs were evolved to
allow a robot to escape from moving pursuers while avoiding static obstacles", written with
:class:`~dnnevo.robots.RobotWorld`.

The paper gives no details; these are dnnevo's (docs/paper.md, "Predator avoidance", says why):

- **Arena** (:data:`ARENA`): an 8 m x 6 m room with three boxes, one of them turned.
- **Pursuers** (:data:`PURSUERS`): two, each starting at least 3 m from the robot, driving at
  0.4 m/s (the robot's wheels reach 1 m/s) and turning at most 1.5 rad/s towards the robot by
  pure pursuit, going round a box that blocks them (``detour``); one whose centre comes within
  0.5 m of the robot's (about touching) catches it.
- **Sensors**: the ring of eight sonars (``min(1, 0.5 / range)``) and a pursuer sensor of four
  sectors (front, left, back, right; ``1 - gap / 6.5 m``): 12 inputs.
- **Trial**: :attr:`Pursuit.steps` steps of 0.1 s (45 s by default); capture ends it.
- **Fitness**: each step survived pays ``(1 - contact_penalty * contact) / steps``, where
  ``contact`` is 1 when a wall or box stopped the robot in that step; the step of a capture
  pays nothing. A return is the fraction of the trial survived, less the fraction spent
  pressed against something: 1 at best.
- **Success** (:meth:`Pursuit.success`): the robot is never caught, and touches walls or boxes
  in at most ``max_contact`` (2%) of the trial's steps; a network succeeds when
  :attr:`Pursuit.success_rate` (80%) of its episodes do.

:func:`escape` is the hand-written baseline, a policy over the same sensors (flee from the
pursuers, turn from obstacles), and :func:`drive` runs any such policy through the task on the
episodes a network's rollout would meet.

>>> import dnnevo
>>> from dnnevo.closedloop import rollout
>>> from dnnevo.robots import Pursuit
>>> env = Pursuit(steps=100)
>>> env.observation_size
12
>>> result = rollout([dnnevo.Network.random(6, 12, seed=1)], env, episodes=3, max_steps=env.steps)
>>> result.returns.shape, env.success(result.returns[0], result.lengths[0]).shape
((1, 3), (3,))
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from os import PathLike
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.closedloop.loop import Rollout
from dnnevo.errors import InvalidArgumentError
from dnnevo.robots.world import D0, RobotWorld

__all__ = ["ARENA", "PURSUERS", "SECTORS", "TRANSFER", "Pursuit", "drive", "escape"]

ARENA: dict[str, Any] = {
    "room": [8.0, 6.0],
    "start": {"min": [0.4, 0.4], "max": [7.6, 5.6]},
    "boxes": [
        {"center": [2.5, 2.0], "size": [1.0, 1.0], "angle_deg": 0.0},
        {"center": [5.5, 4.0], "size": [1.0, 1.0], "angle_deg": 0.0},
        {"center": [5.5, 1.5], "size": [0.6, 1.2], "angle_deg": 30.0},
    ],
}
"""The training arena: an 8 m x 6 m room (a third larger than the landmark rooms, so that a
robot has room to run) with three boxes to run round and to hide behind."""

PURSUERS: dict[str, Any] = {"count": 2, "speed": 0.4, "max_turn_rate": 1.5, "capture_radius": 0.5,
                            "min_start_distance": 3.0, "detour": True}
"""The pursuers of :class:`Pursuit` (a dict given as ``pursuers`` changes only its keys)."""

SECTORS: dict[str, Any] = {"count": 4, "range": 6.5}
"""The pursuer sensor of :class:`Pursuit`: four sectors reaching 6.5 m, as far as the sonars."""

TRANSFER: dict[str, Any] = {
    "world": {
        "room": [7.0, 7.0],
        "start": {"min": [0.4, 0.4], "max": [6.6, 6.6]},
        "boxes": [
            {"center": [2.0, 5.0], "size": [1.4, 0.5], "angle_deg": 0.0},
            {"center": [5.0, 5.2], "size": [0.7, 0.7], "angle_deg": 45.0},
            {"center": [3.5, 3.0], "size": [0.5, 1.5], "angle_deg": 0.0},
            {"center": [5.5, 1.8], "size": [0.8, 0.8], "angle_deg": 15.0},
        ],
    },
    "pursuers": {"speed": 0.45, "max_turn_rate": 2.5},
    "sonar": {"noise_sd": 0.05},
    "sector_noise_sd": 0.2,
}
"""A world training never saw, for the transfer test: ``Pursuit(**TRANSFER)`` is a square 7 m
room with four other boxes, pursuers 12% faster that turn two thirds faster, 5 cm of Gaussian
noise on every sonar range and 20 cm on the pursuer sensor's gaps."""


def _number(name: str, value: Any, low: float, high: float = float("inf")) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating) \
            or not low <= value <= high:
        raise InvalidArgumentError(f"{name} is {value!r}; expected a number in [{low:g}, {high:g}]")
    return float(value)


class Pursuit(RobotWorld):
    """Escape two pursuers without touching walls or boxes; see the module docs. ``steps`` is
    the trial's length, ``contact_penalty`` what a step pressed against something costs (1: as
    much as it would have paid), ``max_contact`` the fraction of the steps a successful episode
    may touch something, and ``sector_noise_sd`` Gaussian noise, in metres, on the pursuer
    sensor's gaps (0 in training). ``pursuers`` and ``sectors`` change only the keys they hold
    of :data:`PURSUERS` and :data:`SECTORS`; every other argument is :class:`RobotWorld`'s."""

    success_rate = 0.8
    """The fraction of episodes in which a network must escape."""

    def __init__(self, world: str | PathLike[str] | Mapping[str, Any] | None = None, *,
                 steps: int = 450, contact_penalty: float = 1.0, max_contact: float = 0.02,
                 sector_noise_sd: float = 0.0, pursuers: Mapping[str, Any] | None = None,
                 sectors: Mapping[str, Any] | None = None, **settings: Any) -> None:
        for name, section in (("pursuers", pursuers), ("sectors", sectors)):
            if section is not None and not isinstance(section, Mapping):
                raise InvalidArgumentError(f"{name} is {section!r}; expected a dict of settings")
        super().__init__(ARENA if world is None else world, pursuers={**PURSUERS, **(pursuers or {})},
                         sectors={**SECTORS, **(sectors or {})}, **settings)
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            raise InvalidArgumentError(f"steps is {steps!r}; expected a whole number >= 1")
        self.steps = steps
        self.contact_penalty = _number("contact_penalty", contact_penalty, 0.0)
        self.max_contact = _number("max_contact", max_contact, 0.0, 1.0)
        self.sector_noise_sd = _number("sector_noise_sd", sector_noise_sd, 0.0)

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator
              ) -> npt.NDArray[np.float64]:
        # Drawn first and always, so that the starts do not depend on whether there is noise.
        self._noise = np.random.default_rng(int(rng.integers(2**63)))
        self.caught = np.zeros(len(episodes), dtype=bool)
        """Which rows' robots a pursuer caught."""
        self.contact_steps = np.zeros(len(episodes), dtype=np.int64)
        """How many steps a wall or box stopped each row's robot."""
        return super().reset(episodes, rng)

    def observe(self) -> npt.NDArray[np.float64]:
        """:meth:`RobotWorld.observe`, with ``sector_noise_sd`` of noise on each sector's gap
        (clipped to ``[0, range]``) when it is not 0."""
        if not self.sector_noise_sd:
            return super().observe()
        reach = self.settings["sectors"]["range"]
        gaps = self.fleet.sectors
        gaps = np.clip(gaps + self._noise.normal(0.0, self.sector_noise_sd, gaps.shape), 0.0, reach)
        sonar = np.minimum(1.0, D0 / self.fleet.ranges)
        return np.concatenate([sonar, 1.0 - gaps / reach], axis=1)

    def reward(self, active: npt.NDArray[np.bool_]) -> npt.NDArray[np.float64]:
        """``(1 - contact_penalty * contact) / steps`` for a step survived, 0 for the step of a
        capture."""
        contact = self.fleet.contacts & active
        caught = self.fleet.captured & active
        self.contact_steps += contact
        self.caught |= caught
        return np.where(caught, 0.0, (1.0 - self.contact_penalty * contact) / self.steps)

    def done(self, active: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
        """An episode ends at a capture, or after :attr:`steps` steps."""
        return np.asarray(self.fleet.captured | (self.t >= self.steps))

    def success(self, returns: npt.NDArray[np.float64], lengths: npt.NDArray[np.int64]
                ) -> npt.NDArray[np.bool_]:
        """Which episodes of the last rollout ran to the end uncaught, touching walls or boxes in
        at most :attr:`max_contact` of the steps."""
        return np.asarray(~self.caught & (lengths >= self.steps)
                          & (self.contact_steps <= self.max_contact * self.steps))


Policy = Callable[[npt.NDArray[np.float64]], npt.NDArray[np.float64]]
"""A controller other than a network: observations (B, M) to firing rates (B, N), of which the
world reads the ``left`` and ``right`` columns."""


def escape(env: RobotWorld, *, obstacle_gain: float = 1.5, turn_gain: float = 3.0) -> Policy:
    """The hand-written escape rule, over ``env``'s own sensors: head away from the pursuers
    and away from near obstacles, at full speed when that heading is ahead.

    Each sector reading ``s`` (0 far, 1 touching) pushes the robot away from its sector's
    direction by ``s**2`` (the nearest pursuer weighs most), each sonar reading ``o`` away from
    its sonar's axis by ``obstacle_gain * o**2``. The robot turns towards the sum at
    ``turn_gain`` times the angle to it (in rad/s) and drives at ``max_speed * cos(angle)``
    (not backwards); with nothing pushing, it drives straight on.
    """
    sonar = np.deg2rad(np.asarray(env.settings["sonar"]["angles_deg"], dtype=float))
    q = int(env.settings["sectors"]["count"])
    sectors = 2.0 * np.pi * np.arange(q) / q
    n_sonar = len(sonar)
    speed, base = env.max_speed, env.settings["robot"]["wheel_base"]
    width = max(env.left, env.right) + 1

    def policy(obs: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        o, s = obs[:, :n_sonar] ** 2, obs[:, n_sonar:n_sonar + q] ** 2
        push_x = -(s @ np.cos(sectors)) - obstacle_gain * (o @ np.cos(sonar))
        push_y = -(s @ np.sin(sectors)) - obstacle_gain * (o @ np.sin(sonar))
        still = np.hypot(push_x, push_y) < 1e-9
        angle = np.where(still, 0.0, np.arctan2(push_y, push_x))
        v = speed * np.clip(np.cos(angle), 0.0, 1.0)
        omega = turn_gain * angle
        wheels = np.stack([v - 0.5 * omega * base, v + 0.5 * omega * base], axis=1)
        rates = np.full((len(obs), width), 0.5)
        rates[:, [env.left, env.right]] = 0.5 * (np.clip(wheels / speed, -1.0, 1.0) + 1.0)
        return rates

    return policy


def drive(policy: Policy, env: RobotWorld, *, episodes: int, max_steps: int, seed: int = 0,
          generation: int = 0, purpose: Literal["trial", "validate", "evaluate"] = "trial") -> Rollout:
    """Runs ``policy`` for ``episodes`` episodes of at most ``max_steps`` steps in ``env``, on
    the same episodes :func:`dnnevo.closedloop.rollout` gives a network with this ``seed``,
    ``generation`` and ``purpose``: one row per episode, the same starts. Returns the
    :class:`~dnnevo.closedloop.Rollout` of one network (shape ``(1, episodes)``)."""
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise InvalidArgumentError(f"episodes is {episodes!r}; expected a whole number >= 1")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 0:
        raise InvalidArgumentError(f"max_steps is {max_steps!r}; expected a whole number >= 0")
    rng = np.random.default_rng(_core.condition_seed(seed, generation, purpose))
    obs = env.reset(np.arange(episodes, dtype=np.int64), rng)
    active = np.ones(episodes, dtype=bool)
    returns = np.zeros(episodes)
    lengths = np.full(episodes, max_steps, dtype=np.int64)
    for t in range(max_steps):
        obs, reward, done = env.step(policy(obs), active)
        returns += np.where(active, reward, 0.0)
        ended = active & done
        lengths[ended] = t + 1
        active &= ~done
        if not active.any():
            break
    return Rollout(returns=returns[None, :], lengths=lengths[None, :])
