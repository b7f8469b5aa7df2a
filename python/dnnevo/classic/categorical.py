"""Beer's categorical perception: catch the falling circles, avoid the falling diamonds, written
with the closed-loop protocol (:class:`~dnnevo.closedloop.Environment`) as a user would write a
task.

An agent, a disc of diameter 30 at the bottom of a 400-wide world, moves left and right. An
object, a circle of diameter 30 or a diamond of side 30, falls straight down towards it at a
speed of 3, from 275 above the agent, starting within 50 of the agent's line to either side. The
agent sees it through seven rays, each 220 long, spread evenly over a visual angle of 30 degrees
about the vertical; a ray that meets the object gives its sensor ``1 - d / 220``, ``d`` the
distance along the ray from the agent's edge, and 0 otherwise. The agent's velocity is
``5 (f_right - f_left)``, the difference of two motor neurons' firing rates. This is the task of
Beer (1996) and Beer (2003), *The dynamics of active categorical perception in an evolved model
agent*, Adaptive Behavior 11(4), with dnnevo's network (every neuron reads every sensor through
its sensor weights) in place of Beer's layered one; Beer injects ``10`` times this sensor value,
and dnnevo's sensor weights (up to 16) scale it instead.

An episode ends when the object has fallen to the agent's height. Its return is Beer's
performance: with ``d`` the horizontal distance between their centres, clipped at 45,
``1 - d / 45`` for a circle (caught in the middle scores 1) and ``d / 45`` for a diamond.

An episode is *classified correctly* (:meth:`CategoricalPerception.success`) when a circle lands
on the agent (their centres closer than 15 + 15) and a diamond does not (closer than 15 plus
its half-width, 21.2, counts as landing). A network succeeds when it classifies at least
:attr:`~CategoricalPerception.success_rate` of its episodes correctly.

The world moves by ``dt`` time units per control step; integrate the networks with the same
step (``dt=0.1, substeps=1`` in :class:`~dnnevo.closedloop.ClosedLoop` or
:func:`~dnnevo.closedloop.rollout` for the default). :attr:`CategoricalPerception.steps` control
steps end every episode.

>>> import dnnevo
>>> from dnnevo.classic import CategoricalPerception
>>> from dnnevo.closedloop import rollout
>>> env = CategoricalPerception(start="grid")
>>> net = dnnevo.Network.random(7, 7, seed=0)
>>> result = rollout([net], env, episodes=4, max_steps=env.steps, dt=0.1, substeps=1)
>>> result.lengths[0].tolist()
[917, 917, 917, 917]
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.closedloop.loop import rollout
from dnnevo.errors import InvalidArgumentError

__all__ = ["CategoricalPerception", "grid_accuracy", "paths", "ray_distances"]

WIDTH = 400.0
AGENT_RADIUS = 15.0
CIRCLE_RADIUS = 15.0
DIAMOND_HALF_WIDTH = 30.0 / math.sqrt(2.0)
"""Half the diagonal of a diamond of side 30: its half-width and half-height."""
HEIGHT = 275.0
FALL_SPEED = 3.0
MAX_OFFSET = 50.0
RAYS = 7
RAY_LENGTH = 220.0
VISUAL_ANGLE = math.pi / 6
MOTOR_GAIN = 5.0
CLIP = 45.0

CIRCLE, DIAMOND = 0, 1
RAY_ANGLES = np.linspace(-VISUAL_ANGLE / 2, VISUAL_ANGLE / 2, RAYS)
"""Each ray's angle from the vertical, left to right (radians)."""

GRID_OFFSETS = 101
"""Offsets per shape in the ``"grid"`` start when a rollout has no other count to go by: 101
evenly spaced over ±50, every whole unit."""


_SIN, _COS = np.sin(RAY_ANGLES), np.cos(RAY_ANGLES)
_REACH = AGENT_RADIUS + RAY_LENGTH + max(CIRCLE_RADIUS, DIAMOND_HALF_WIDTH)
"""No ray reaches an object whose centre is higher than this above the agent's."""


def _circle(qx: npt.NDArray[np.float64], qy: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    # |q - t u| = r, so t^2 - 2 b t + |q|^2 - r^2 = 0 with b = q . u.
    b = qx * _SIN + qy * _COS
    disc = b * b - (qx * qx + qy * qy - CIRCLE_RADIUS**2)
    root = np.sqrt(np.maximum(disc, 0.0))
    return np.where((disc >= 0.0) & (b + root >= 0.0), np.maximum(b - root, 0.0), np.inf)


def _diamond(qx: npt.NDArray[np.float64], qy: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    # |px| + |py| <= h at p = t u - q, four half-planes. The rays point up within 15 degrees of
    # vertical (cos > |sin|), so the two lower edges (px - py <= h and -px - py <= h) bound t
    # from below and the two upper ones from above.
    h = DIAMOND_HALF_WIDTH
    enter = np.maximum((h + qx - qy) / (_SIN - _COS), (h - qx - qy) / (-_SIN - _COS))
    leave = np.minimum((h + qx + qy) / (_SIN + _COS), (h - qx + qy) / (_COS - _SIN))
    return np.where((enter <= leave) & (leave >= 0.0), np.maximum(enter, 0.0), np.inf)


def ray_distances(agent: npt.NDArray[np.float64], x: npt.NDArray[np.float64],
                  y: npt.NDArray[np.float64], diamond: npt.NDArray[np.bool_]
                  ) -> npt.NDArray[np.float64]:
    """How far along each ray (from the agent's edge) it meets the object, ``inf`` where it does
    not within the ray's length of 220; shape ``(B, 7)``. The agent's centre is at ``(agent, 0)``, the object's at ``(x, y)``.
    """
    out = np.full((len(agent), RAYS), np.inf)
    seen = y <= _REACH
    for shape, rows in ((_circle, seen & ~diamond), (_diamond, seen & diamond)):
        if rows.any():
            # The object's centre seen from each ray's origin on the agent's edge.
            qx = (x[rows] - agent[rows])[:, None] - AGENT_RADIUS * _SIN
            qy = y[rows][:, None] - AGENT_RADIUS * _COS
            out[rows] = shape(qx, qy)
    out[out > RAY_LENGTH] = np.inf
    return out


def _offsets(start: str, count: int, rng: np.random.Generator) -> npt.NDArray[np.float64]:
    if start == "random":
        return rng.uniform(-MAX_OFFSET, MAX_OFFSET, count)
    return np.linspace(-MAX_OFFSET, MAX_OFFSET, count)


class CategoricalPerception:
    """Beer's categorical perception task; see the module docs.

    Episode ``e`` drops a circle when ``e`` is even and a diamond when it is odd. ``start`` sets
    where: ``"random"`` draws each pair's offset uniformly from ±50 (fresh each generation, the
    same for every network), ``"grid"`` spaces the pairs evenly over ±50 (a rollout of 202
    episodes tries every whole offset with both shapes). The motor neurons are ``left`` and
    ``right``.
    """

    success_rate = 0.9
    """The fraction of episodes a network must classify correctly to succeed."""
    observation_size = RAYS
    """The seven rays."""

    def __init__(self, *, start: str = "random", dt: float = 0.1, left: int = 0,
                 right: int = 1) -> None:
        if start not in ("random", "grid"):
            raise InvalidArgumentError(f"start is {start!r}; expected 'random' or 'grid'")
        if isinstance(dt, bool) or not isinstance(dt, float | int) or not 0 < dt <= 1:
            raise InvalidArgumentError(f"dt is {dt!r}; expected a number in (0, 1]")
        for name, value in (("left", left), ("right", right)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise InvalidArgumentError(f"{name} is {value!r}; expected a neuron index >= 0")
        if left == right:
            raise InvalidArgumentError(f"left and right are both neuron {left}; they must differ")
        self.start = start
        self.dt = float(dt)
        self.left, self.right = left, right

    @property
    def steps(self) -> int:
        """Control steps in every episode: until the object has fallen 275."""
        return math.ceil(HEIGHT / (FALL_SPEED * self.dt) - 1e-9)

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator
              ) -> npt.NDArray[np.float64]:
        """Every agent at 0, every object 275 above it at its episode's offset."""
        pairs = (int(episodes.max()) // 2 + 1) if len(episodes) else 0
        self.diamond = episodes % 2 == DIAMOND
        self.offset = _offsets(self.start, pairs, rng)[episodes // 2]
        self.agent = np.zeros(len(episodes))
        self.x = self.offset.copy()
        self.y = np.full(len(episodes), HEIGHT)
        self.t = 0
        self.landed = np.full(len(episodes), np.nan)
        return self._sense()

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
        """Moves every agent and drops every object by one control step; the episode ends, and
        pays its performance, when the object reaches the agent's height."""
        velocity = MOTOR_GAIN * (rates[:, self.right] - rates[:, self.left])
        limit = WIDTH / 2 - AGENT_RADIUS  # the world's side walls stop the agent
        np.clip(self.agent + velocity * self.dt, -limit, limit, out=self.agent)
        self.t += 1
        self.y = np.full_like(self.y, HEIGHT - FALL_SPEED * self.dt * self.t)
        reward = np.zeros(len(self.agent))
        done = np.zeros(len(self.agent), dtype=bool)
        if self.t >= self.steps:
            done[:] = active
            self.landed = np.where(active, np.abs(self.x - self.agent), self.landed)
            reward = self.performance(self.landed)
        return self._sense(), reward, done

    def performance(self, distance: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        """Beer's score of each episode from the horizontal distance at landing."""
        near = np.minimum(distance, CLIP) / CLIP
        return np.where(self.diamond, near, 1.0 - near)

    def success(self, returns: npt.NDArray[np.float64], lengths: npt.NDArray[np.int64]
                ) -> npt.NDArray[np.bool_]:
        """Which episodes of the last rollout were classified correctly: a circle landed on the
        agent, a diamond did not. An episode cut short before its object landed (a rollout with
        fewer than :attr:`steps` steps) is not classified correctly."""
        reach = AGENT_RADIUS + np.where(self.diamond, DIAMOND_HALF_WIDTH, CIRCLE_RADIUS)
        caught = self.landed < reach
        return np.asarray(np.where(self.diamond, ~caught, caught) & ~np.isnan(self.landed))

    def _sense(self) -> npt.NDArray[np.float64]:
        d = ray_distances(self.agent, self.x, self.y, self.diamond)
        return np.maximum(1.0 - d / RAY_LENGTH, 0.0)  # 0 where a ray meets nothing (d = inf)


def grid_accuracy(net: _core.Network, *, dt: float = 0.1, pairs: int = GRID_OFFSETS,
                  method: str = "euler", precision: str = "f64") -> tuple[int, int, float]:
    """``net`` on every whole offset from -50 to 50 with both shapes (``pairs`` offsets per
    shape): (episodes classified correctly, episodes, mean performance). ``dt`` is the world's
    and the network's step alike; the network computes in ``precision``."""
    env = CategoricalPerception(start="grid", dt=dt)
    result = rollout([net], env, episodes=2 * pairs, max_steps=env.steps, dt=dt, substeps=1,
                     method=method, precision=precision)
    ok = env.success(result.returns[0], result.lengths[0])
    return int(ok.sum()), len(ok), float(result.returns[0].mean())


class _Traced(CategoricalPerception):
    """The task, keeping each step's horizontal offset of the object from the agent."""

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator
              ) -> npt.NDArray[np.float64]:
        obs = super().reset(episodes, rng)
        self.trace = [self.x - self.agent]
        return obs

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
        out = super().step(rates, active)
        self.trace.append(self.x - self.agent)
        return out


def paths(net: _core.Network, *, dt: float = 0.1, pairs: int = 21, method: str = "euler",
          precision: str = "f64") -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
    """``net``'s episodes on the grid of ``pairs`` offsets per shape: the object's height at each
    step (shape ``(T,)``), its horizontal offset from the agent (shape ``(2 pairs, T)``, episode
    ``e`` a circle when even), and which episodes were classified correctly; the network
    computes in ``precision``."""
    env = _Traced(start="grid", dt=dt)
    result = rollout([net], env, episodes=2 * pairs, max_steps=env.steps, dt=dt, substeps=1,
                     method=method, precision=precision)
    height = np.asarray(HEIGHT - FALL_SPEED * dt * np.arange(env.steps + 1), dtype=np.float64)
    ok = env.success(result.returns[0], result.lengths[0])
    return height, np.array(env.trace).T, ok
