"""Beer and Gallagher's (1992) legged agent with one leg, the classic test of central and
reflexive pattern generators, written with the closed-loop protocol
(:class:`~dnnevo.closedloop.Environment`) as a user would write a task.

A body moves along a line on one leg of length 15, hinged to the body. Three
motor neurons drive it: the foot is down while neuron 0 fires above 0.5; neurons 1 and 2 give
forward and backward swing forces of up to 0.05 each. With the foot down, the difference of
the two pushes the body (velocity up to 6), but only while the leg lies within its limits of
±30 degrees, or pushes back towards them; the leg's angle then follows the planted foot. With the
foot up, the body stops, and the same forces swing the leg: its angular velocity changes by
``0.5 (backward - forward)`` per unit time, up to ±1, and stops at the limits. A foot left more than 20 behind the
body makes it unstable: it stops. The model and its constants are those of Beer's LeggedAgent
(Beer, Chiel and Gallagher 1999, *Evolution and analysis of model CPGs for walking*, J. Comput.
Neurosci. 7), including its change that makes the limits one-way constraints for a supporting
leg.

The network may sense the leg's angle (``angle / 30 degrees``, so -1 to 1 within the limits);
with ``sensor=False`` the input is 0 throughout: a leg cut off from its sensor. An episode lasts
220 units of time in steps of ``dt`` (0.1 by default; integrate the networks with the same
step, ``dt=0.1, substeps=1``); its return is the body's average velocity, the distance walked
divided by 220.

:func:`optimal_velocity` runs the hand-designed best controller of the model (plant the foot at
the forward limit, push with full force, lift it once the foot trails the body by more than 20,
swing forward at full speed): the upper bound an evolved walker is measured against. An episode
*walks* (:meth:`LeggedWalker.success`) when its average velocity is at least half that bound.

>>> import dnnevo
>>> from dnnevo.classic import LeggedWalker
>>> from dnnevo.classic.walker import optimal_velocity
>>> from dnnevo.closedloop import rollout
>>> env = LeggedWalker()
>>> result = rollout([dnnevo.Network.random(5, 1, seed=0)], env, max_steps=env.steps, dt=0.1,
...                  substeps=1)
>>> bool(result.returns[0, 0] < 0.5 * optimal_velocity())   # a random network does not walk
True
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.closedloop.loop import rollout
from dnnevo.errors import InvalidArgumentError

__all__ = ["LeggedWalker", "gait", "optimal_velocity", "velocities"]

LEG_LENGTH = 15.0
MAX_FORCE = 0.05
ANGLE_LIMIT = math.pi / 6
MAX_VELOCITY = 6.0
MAX_TORQUE = 0.5
MAX_OMEGA = 1.0
UNSTABLE = 20.0
"""How far the foot may trail the body before the body stops."""
DURATION = 220.0
FOOT, FORWARD, BACKWARD = 0, 1, 2
"""The motor neurons."""
WALKING = 0.5
"""The fraction of :func:`optimal_velocity` an episode needs to count as walking."""


class LeggedWalker:
    """The one-legged walker; see the module docs.

    ``start="forward"`` starts every episode with the leg at its forward limit, foot up;
    ``"random"`` draws each episode's starting angle uniformly within the limits (the same for
    every network).
    """

    success_rate = 0.9
    """The fraction of episodes that must walk."""
    observation_size = 1
    """The leg's angle (0 throughout with ``sensor=False``)."""

    def __init__(self, *, sensor: bool = True, start: str = "forward", dt: float = 0.1) -> None:
        if start not in ("forward", "random"):
            raise InvalidArgumentError(f"start is {start!r}; expected 'forward' or 'random'")
        if isinstance(dt, bool) or not isinstance(dt, float | int) or not 0 < dt <= 1:
            raise InvalidArgumentError(f"dt is {dt!r}; expected a number in (0, 1]")
        self.sensor = bool(sensor)
        self.start = start
        self.dt = float(dt)

    @property
    def steps(self) -> int:
        """Control steps in every episode: 220 units of time."""
        return round(DURATION / self.dt)

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator
              ) -> npt.NDArray[np.float64]:
        """Every body at 0 and at rest, its foot up."""
        rows = len(episodes)
        if self.start == "random":
            count = int(episodes.max()) + 1 if rows else 0
            self.angle = rng.uniform(-ANGLE_LIMIT, ANGLE_LIMIT, count)[episodes]
        else:
            self.angle = np.full(rows, ANGLE_LIMIT)
        self.x = np.zeros(rows)
        self.velocity = np.zeros(rows)
        self.omega = np.zeros(rows)
        self.foot_down = np.zeros(rows, dtype=bool)
        self.foot_x = LEG_LENGTH * np.sin(self.angle)
        self.foot_y = LEG_LENGTH * np.cos(self.angle)  # above the hip, as in the model
        self.t = 0
        return self._sense()

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
        """One step of the body and leg; the last step pays the average velocity."""
        forward = rates[:, FORWARD] * MAX_FORCE
        backward = rates[:, BACKWARD] * MAX_FORCE
        self._move(rates[:, FOOT] > 0.5, forward, backward)
        self.t += 1
        done = np.full(len(self.x), self.t >= self.steps)
        reward = self.x / DURATION if self.t >= self.steps else np.zeros(len(self.x))
        return self._sense(), reward, done

    def _move(self, down: npt.NDArray[np.bool_], forward: npt.NDArray[np.float64],
              backward: npt.NDArray[np.float64]) -> None:
        dt, angle = self.dt, self.angle
        self.foot_down = down
        self.omega[down] = 0.0
        push = forward - backward
        within = (angle >= -ANGLE_LIMIT) & (angle <= ANGLE_LIMIT)
        towards = ((angle < -ANGLE_LIMIT) & (push < 0)) | ((angle > ANGLE_LIMIT) & (push > 0))
        force = np.where(down & (within | towards), push, 0.0)
        self.velocity = np.clip(self.velocity + dt * force, -MAX_VELOCITY, MAX_VELOCITY)
        self.x = self.x + dt * self.velocity
        # A planted foot stays; the leg's angle follows it.
        planted = np.arctan2(self.foot_x - self.x, self.foot_y)
        # A lifted foot swings with the leg; the body stops.
        omega = np.clip(self.omega + dt * MAX_TORQUE * (backward - forward), -MAX_OMEGA, MAX_OMEGA)
        swung = angle + dt * omega
        stopped = (swung < -ANGLE_LIMIT) | (swung > ANGLE_LIMIT)
        swung = np.clip(swung, -ANGLE_LIMIT, ANGLE_LIMIT)
        omega[stopped] = 0.0
        self.omega = np.where(down, (planted - angle) / dt, omega)
        self.angle = np.where(down, planted, swung)
        self.velocity[~down] = 0.0
        self.foot_x = np.where(down, self.foot_x, self.x + LEG_LENGTH * np.sin(swung))
        self.foot_y = np.where(down, self.foot_y, LEG_LENGTH * np.cos(swung))
        self.velocity[self.x - self.foot_x > UNSTABLE] = 0.0

    def success(self, returns: npt.NDArray[np.float64], lengths: npt.NDArray[np.int64]
                ) -> npt.NDArray[np.bool_]:
        """Which episodes walked: an average velocity of at least half the optimal one."""
        return np.asarray(returns >= WALKING * optimal_velocity(self.dt))

    def _sense(self) -> npt.NDArray[np.float64]:
        if not self.sensor:
            return np.zeros((len(self.angle), 1))
        return (self.angle / ANGLE_LIMIT)[:, None]


def optimal_velocity(dt: float = 0.1) -> float:
    """The average velocity over 220 units of time of the model's best controller, started as
    ``start="forward"`` starts: plant the foot at the forward limit, push forward with full
    force while the leg is within its limits, lift the foot once the foot trails the body by
    more than 20 (where the body stops), and swing the leg forward at full speed."""
    env = LeggedWalker(dt=dt)
    env.reset(np.zeros(1, dtype=np.int64), np.random.default_rng(0))
    for _ in range(env.steps):
        down = env.foot_down.copy()
        if not down[0] and env.angle[0] >= ANGLE_LIMIT:
            down[0] = True
        elif down[0] and env.x[0] - env.foot_x[0] > UNSTABLE:
            down[0] = False
        # Down: full forward push. Up: full backward force, which swings the leg forward.
        full, none = np.array([MAX_FORCE]), np.zeros(1)
        env._move(down, full if down[0] else none, none if down[0] else full)
    return float(env.x[0] / DURATION)


def velocities(net: _core.Network, *, sensor: bool = True, episodes: int = 20,
               dt: float = 0.1, seed: int = 0, method: str = "euler", precision: str = "f64"
               ) -> npt.NDArray[np.float64]:
    """``net``'s average velocity in ``episodes`` episodes from random starting angles drawn
    from ``seed`` with ``purpose="evaluate"`` (fresh, never a training episode), the network
    computing in ``precision``."""
    env = LeggedWalker(sensor=sensor, start="random", dt=dt)
    result = rollout([net], env, episodes=episodes, max_steps=env.steps, dt=dt, substeps=1,
                     method=method, seed=seed, purpose="evaluate", precision=precision)
    return np.asarray(result.returns[0])


class _Traced(LeggedWalker):
    """The walker, keeping each step's angle, foot and position."""

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator
              ) -> npt.NDArray[np.float64]:
        obs = super().reset(episodes, rng)
        self.trace = [(self.angle.copy(), self.foot_down.copy(), self.x.copy())]
        return obs

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
        out = super().step(rates, active)
        self.trace.append((self.angle.copy(), self.foot_down.copy(), self.x.copy()))
        return out


def gait(net: _core.Network, *, sensor: bool = True, dt: float = 0.1, method: str = "euler",
         precision: str = "f64") -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_],
                    npt.NDArray[np.float64]]:
    """One episode of ``net`` from the forward start: time, the leg's angle, whether the foot is
    down, and the body's position, at each step (shape ``(T + 1,)`` each); the network computes
    in ``precision``."""
    env = _Traced(sensor=sensor, dt=dt)
    rollout([net], env, max_steps=env.steps, dt=dt, substeps=1, method=method, precision=precision)
    angle, x = (np.array([step[k][0] for step in env.trace], dtype=np.float64) for k in (0, 2))
    down = np.array([step[1][0] for step in env.trace], dtype=np.bool_)
    return np.asarray(dt * np.arange(len(angle)), dtype=np.float64), angle, down, x
