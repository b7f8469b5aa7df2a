"""Reactive navigation (Yamauchi and Beer 1994, §3.2, after Yamauchi 1993): "a hand-designed DNN
was used in combination with algorithms for detecting static and cyclic behavior to allow a
robot to navigate to a destination while avoiding obstacles", written with
:class:`~dnnevo.robots.RobotWorld`.

The paper gives no details; these are dnnevo's (docs/reactive-navigation.md says why):

- **Worlds** (:data:`WORLDS`): world files (docs/worlds.md) with two keys more, ``goal = [x, y]``
  and ``goal_radius``, shipped in ``dnnevo/robots/data``: an open room, a U-shaped trap and a
  cul-de-sac.
- **Sensors** (11 inputs): the ring of eight sonars (``min(1, 0.5 / range)``); a destination
  sensor of two inputs, the bearing ``b`` of the goal from the robot's heading (counter-clockwise
  positive, in ``(-pi, pi]``) as ``max(0, b) / pi`` (goal on the left) and ``max(0, -b) / pi``
  (on the right), computed from the robot's pose as perfect odometry would; and the
  **frustration** input, +1 or -1 while the detectors make the robot escape (bending right or
  left), else 0 (always 0 without detectors).
- **Trial**: :attr:`Navigate.steps` steps of 0.1 s (120 s by default); it ends when the robot's
  centre comes within ``goal_radius`` of the goal (**success**).
- **Fitness** (for an evolved comparison): the progress towards the goal, ``(d_start - d_end) /
  d_start`` summed step by step, plus 1 on arrival, less ``contact_penalty`` times the fraction of
  the trial's steps in which a wall or box stopped the robot.
- **Detectors** (:class:`Detectors`, on with ``detectors=True``): **static** (:func:`stuck`) fires
  when every position of the last 3 s lies within 0.2 m of the current one; **cyclic**
  (:func:`looping`) when the robot comes back within 0.3 m of where it was 6 to 30 s before.
  When one fires, the frustration input turns on and bends the path right, until the robot is
  nearer the goal than it ever was before (by 0.1 m), or
  for at most 40 s; the detectors then start again with an empty memory. An escape that is
  itself stuck (the static detector, watching the escape's own track) is replaced by one to the
  other side.

:func:`navigator` is the hand-designed network, loaded from ``dnnevo/robots/data/navigator.json``;
:func:`design` builds the same network from the documented weights. :func:`hand_designed` runs it
on fresh starts of a world, with or without the detectors, and counts its arrivals: the paper's
own experiment, which ``examples/reactive_navigation.py`` and the ``reactive-navigation-hand``
job of ``dnnevo reproduce`` both run.

>>> from dnnevo.closedloop import rollout
>>> from dnnevo.robots import Navigate
>>> env = Navigate("open-room", steps=300)
>>> env.observation_size
11
>>> result = rollout([navigator()], env, episodes=4, max_steps=env.steps, **INTEGRATOR)
>>> env.success(result.returns[0], result.lengths[0]).tolist()
[True, True, True, True]
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from os import PathLike
from typing import Any, TypedDict

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.closedloop import rollout
from dnnevo.errors import InvalidArgumentError
from dnnevo.robots.world import D0, RobotWorld, world_text

__all__ = ["INTEGRATOR", "WORLDS", "Integration", "Detectors", "Navigate", "bearing", "design", "destination",
           "hand_designed", "looping", "navigation_world", "navigator", "stuck"]

class Integration(TypedDict):
    """How a network is integrated: the keyword arguments of :func:`dnnevo.closedloop.rollout`."""

    dt: float
    substeps: int
    method: str


INTEGRATOR: Integration = {"dt": 0.02, "substeps": 5, "method": "euler"}
"""How the hand-designed network is integrated: five Euler steps of 0.02 per world step of 0.1 s,
so that the network's time is in seconds and its time constants (0.2 s) are ten Euler steps."""

WORLDS = ("open-room", "u-trap", "cul-de-sac")
"""The shipped navigation worlds, by name (``dnnevo/robots/data/NAME.toml``)."""


def _data(name: str) -> Any:
    return resources.files("dnnevo.robots").joinpath("data", name)


def navigation_world(world: str | PathLike[str] | Mapping[str, Any]
                     ) -> tuple[dict[str, Any], tuple[float, float], float | None]:
    """A navigation world as ``(world, goal, goal_radius)``: ``world`` is a shipped world's name
    (:data:`WORLDS`), a world file (a path ending in ``.toml``) or a dict, each holding ``goal =
    [x, y]`` and, optionally, ``goal_radius`` besides what a world file holds (docs/worlds.md).
    The returned world is without them; the radius is None when it is not given."""
    if isinstance(world, Mapping):
        doc = dict(world)
    else:
        if isinstance(world, str) and world in WORLDS:
            text = _data(f"{world}.toml").read_text(encoding="utf-8")
            where = world
        elif isinstance(world, PathLike) or (isinstance(world, str) and world.endswith(".toml")):
            text = world_text(world)
            where = str(world)
        else:
            raise InvalidArgumentError(f"world is {world!r}; expected one of "
                                       f"{', '.join(map(repr, WORLDS))}, a world file (a path ending "
                                       "in .toml) or a dict")
        try:
            doc = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise InvalidArgumentError(f"world file {where}: {e}") from None
    goal = doc.pop("goal", None)
    if not (isinstance(goal, list | tuple) and len(goal) == 2
            and all(isinstance(g, int | float) and not isinstance(g, bool) and np.isfinite(g) for g in goal)):
        raise InvalidArgumentError(f"goal is {goal!r}; a navigation world needs goal = [x, y], in metres")
    radius = doc.pop("goal_radius", None)
    if radius is not None:
        radius = _number("goal_radius", radius, 0.0)
    return doc, (float(goal[0]), float(goal[1])), radius


def _number(name: str, value: Any, low: float, high: float = float("inf"), *, open_low: bool = False) -> float:
    ok = (not isinstance(value, bool) and isinstance(value, int | float | np.integer | np.floating)
          and (low < value if open_low else low <= value) and value <= high)
    if not ok:
        lo = "(" if open_low else "["
        raise InvalidArgumentError(f"{name} is {value!r}; expected a number in {lo}{low:g}, {high:g}]")
    return float(value)


def bearing(poses: npt.ArrayLike, goal: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The bearing of ``goal`` (2,) or (B, 2) from each pose (B, 3: x, y, heading): the angle
    from the robot's heading to the goal, counter-clockwise positive, in ``(-pi, pi]``.

    >>> bearing([[0.0, 0.0, 0.0], [0.0, 0.0, np.pi / 2]], [0.0, 1.0]).round(6).tolist()
    [1.570796, 0.0]
    """
    p = np.asarray(poses, dtype=float)
    g = np.asarray(goal, dtype=float)
    angle = np.arctan2(g[..., 1] - p[:, 1], g[..., 0] - p[:, 0]) - p[:, 2]
    return np.asarray(np.pi - np.mod(np.pi - angle, 2.0 * np.pi), dtype=np.float64)


def destination(poses: npt.ArrayLike, goal: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The destination sensor (B, 2): the goal's bearing ``b`` as ``max(0, b) / pi`` (goal on
    the left) and ``max(0, -b) / pi`` (on the right); both 0 with the goal dead ahead, one of
    them 1 with it straight behind.

    >>> destination([[0.0, 0.0, 0.0]], [1.0, 1.0]).round(6).tolist()
    [[0.25, 0.0]]
    """
    b = bearing(poses, goal)
    return np.stack([np.maximum(0.0, b), np.maximum(0.0, -b)], axis=1) / np.pi


def _track(track: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """``track`` as a (B, H, 2) float array, or an :class:`InvalidArgumentError`."""
    t = np.asarray(track, dtype=float)
    if t.ndim != 3 or t.shape[2] != 2:
        raise InvalidArgumentError(f"track has shape {t.shape}; expected (rows, steps, 2)")
    return t


def _at_least_one(name: str, steps: int) -> None:
    """A window of ``steps`` steps must hold at least one: 0 or fewer would call a robot that
    drives straight stuck or looping."""
    if not isinstance(steps, int | np.integer) or isinstance(steps, bool) or steps < 1:
        raise InvalidArgumentError(f"{name} is {steps!r}; it must be an integer >= 1")


def stuck(track: npt.ArrayLike, span: int, distance: float) -> npt.NDArray[np.bool_]:
    """The static detector: which rows of ``track`` (B, H, 2; positions, newest last, NaN where
    none was recorded) have every position of their last ``span`` steps (``span + 1`` entries)
    recorded and within ``distance`` of the newest: the robot has moved less than ``distance``
    in that time."""
    t = _track(track)
    _at_least_one("span", span)
    if t.shape[1] < span + 1:
        return np.zeros(len(t), dtype=bool)
    window = t[:, t.shape[1] - span - 1:]
    gap = np.hypot(window[..., 0] - window[:, -1:, 0], window[..., 1] - window[:, -1:, 1])
    return np.asarray(np.all(gap < distance, axis=1))


def looping(track: npt.ArrayLike, after: int, radius: float) -> npt.NDArray[np.bool_]:
    """The cyclic detector: which rows of ``track`` (B, H, 2; positions, newest last, NaN where
    none was recorded) have come back within ``radius`` of a position recorded at least
    ``after`` steps before the newest (pass the window to look back over as ``track``)."""
    t = _track(track)
    _at_least_one("after", after)
    if t.shape[1] <= after:
        return np.zeros(len(t), dtype=bool)
    old = t[:, :t.shape[1] - after]
    gap = np.hypot(old[..., 0] - t[:, -1:, 0], old[..., 1] - t[:, -1:, 1])
    return np.asarray(np.any(gap < radius, axis=1))


@dataclass(frozen=True)
class Detectors:
    """The static and cyclic detectors and the escape they trigger; times in seconds, lengths
    in metres (docs/reactive-navigation.md says why these values)."""

    static_seconds: float = 3.0
    """The static detector looks back this long..."""
    static_distance: float = 0.2
    """... and fires when the robot stayed within this distance of where it is now."""
    cycle_after: float = 6.0
    """The cyclic detector fires when the robot comes back to where it was at least this long
    ago ..."""
    cycle_window: float = 30.0
    """... and at most this long ago ..."""
    cycle_radius: float = 0.3
    """... within this distance."""
    escape_margin: float = 0.1
    """An escape ends when the robot is this much nearer the goal than it ever was before ..."""
    escape_seconds: float = 40.0
    """... or after this long."""

    def __post_init__(self) -> None:
        for name in ("static_seconds", "static_distance", "cycle_after", "cycle_window",
                     "cycle_radius", "escape_seconds"):
            _number(name, getattr(self, name), 0.0, open_low=True)
        _number("escape_margin", self.escape_margin, 0.0)
        if self.cycle_window <= self.cycle_after:
            raise InvalidArgumentError(f"cycle_window is {self.cycle_window!r}; it must be longer "
                                       f"than cycle_after ({self.cycle_after!r})")


class Navigate(RobotWorld):
    """Reach the goal without touching walls or boxes; see the module docs. ``world`` is a
    navigation world (:func:`navigation_world`); ``goal`` and ``goal_radius`` override the
    world's (``goal_radius`` 0.5 m when neither gives it). ``steps`` is the trial's length,
    ``contact_penalty`` what touching something in every step would cost, and ``detectors``
    True (the default :class:`Detectors`), a :class:`Detectors`, or False (none: the
    frustration input stays 0). Every other argument is :class:`RobotWorld`'s."""

    success_rate = 0.9
    """The fraction of episodes in which a network must reach the goal."""

    def __init__(self, world: str | PathLike[str] | Mapping[str, Any] = "open-room", *,
                 goal: tuple[float, float] | None = None, goal_radius: float | None = None,
                 steps: int = 1200, contact_penalty: float = 1.0,
                 detectors: bool | Detectors = False, **settings: Any) -> None:
        doc, world_goal, world_radius = navigation_world(world)
        super().__init__(doc, **settings)
        if goal is not None:
            _, world_goal, _ = navigation_world({"goal": goal})
        self.goal = np.array(world_goal)
        """The goal, (x, y) in metres."""
        room = self.world["room"]
        if not (0 <= self.goal[0] <= room[0] and 0 <= self.goal[1] <= room[1]):
            raise InvalidArgumentError(f"goal is {self.goal.tolist()}; it must lie in the room "
                                       f"[0, {room[0]:g}] x [0, {room[1]:g}]")
        radius = goal_radius if goal_radius is not None else world_radius
        self.goal_radius = 0.5 if radius is None else _number("goal_radius", radius, 0.0, open_low=True)
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            raise InvalidArgumentError(f"steps is {steps!r}; expected a whole number >= 1")
        self.steps = steps
        self.contact_penalty = _number("contact_penalty", contact_penalty, 0.0)
        if isinstance(detectors, bool):
            self.detectors: Detectors | None = Detectors() if detectors else None
        elif isinstance(detectors, Detectors):
            self.detectors = detectors
        else:
            raise InvalidArgumentError(f"detectors is {detectors!r}; expected True, False or a Detectors")
        self.observation_size = len(self.settings["sonar"]["angles_deg"]) + 3

    def distance(self) -> npt.NDArray[np.float64]:
        """Each row's distance from the robot's centre to the goal, in metres (B,)."""
        p = self.fleet.poses
        return np.asarray(np.hypot(self.goal[0] - p[:, 0], self.goal[1] - p[:, 1]))

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator
              ) -> npt.NDArray[np.float64]:
        b = len(episodes)
        self.arrived = np.zeros(b, dtype=bool)
        """Which rows' robots reached the goal."""
        self.contact_steps = np.zeros(b, dtype=np.int64)
        """How many steps a wall or box stopped each row's robot."""
        self.frustration = np.zeros(b)
        """The frustration input (B,): 0 while a row's robot seeks the goal, +1 or -1 while it
        escapes (bending right or left)."""
        self.escapes = np.zeros(b, dtype=np.int64)
        """How many times the detectors fired in each row (static or cyclic)."""
        self.fired = np.zeros((b, 2), dtype=np.int64)
        """How many times each detector fired in each row: static, then cyclic."""
        self.fleet.reset(episodes, int(rng.integers(2**63)))
        return self._start()

    def place(self, poses: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Puts the rows' robots at ``poses`` (B, 3) after :meth:`reset`, as a new start, and
        returns the first observations: for hand-built starts."""
        self.fleet.place(poses)
        return self._start()

    def _start(self) -> npt.NDArray[np.float64]:
        b = self.fleet.rows
        self.t = 0
        self.wheels = np.zeros((b, 2))
        self.arrived[:] = False
        self.contact_steps[:] = 0
        self.frustration[:] = 0.0
        self.escapes[:] = 0
        self.fired[:] = 0
        self.start_distance = self.distance()
        self._last = self.start_distance
        self.best = self.start_distance.copy()
        """Each row's nearest approach to the goal so far, in metres."""
        if self.detectors is not None:
            dt = self.settings["dt"]
            self._static = max(1, round(self.detectors.static_seconds / dt))
            self._after = max(1, round(self.detectors.cycle_after / dt))
            self._window = max(self._after + 1, round(self.detectors.cycle_window / dt))
            self._escape_steps = max(1, round(self.detectors.escape_seconds / dt))
            self.track = np.full((b, self.steps + 1, 2), np.nan)
            """Each row's positions since its detectors last started (NaN before), step by step."""
            self.track[:, 0] = self.fleet.poses[:, :2]
            self._until = np.zeros(b)
            self._escaping_since = np.zeros(b, dtype=np.int64)
        return self.observe()

    def observe(self) -> npt.NDArray[np.float64]:
        """The sonars (``min(1, 0.5 / range)``), the destination sensor (:func:`destination`)
        and the frustration input."""
        sonar = np.minimum(1.0, D0 / self.fleet.ranges)
        return np.concatenate([sonar, destination(self.fleet.poses, self.goal),
                               self.frustration[:, None]], axis=1)

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
        """:meth:`RobotWorld.step`, with the detectors run after the robots moved, so that the
        observations returned carry the frustration they decided."""
        self.wheels = self.max_speed * (2.0 * rates[:, (self.left, self.right)] - 1.0)
        self.fleet.step(self.wheels, active)
        self.t += 1
        reward, done = self.reward(active), self.done(active)
        if self.detectors is not None:
            self._detect(active & ~done)
        return self.observe(), reward, done

    def _detect(self, running: npt.NDArray[np.bool_]) -> None:
        assert self.detectors is not None
        t, d = self.t, self.distance()
        self.track[:, t] = self.fleet.poses[:, :2]
        escaping = self.frustration != 0
        recent = self.track[:, max(0, t - self._static):t + 1]
        # An escape that is itself stuck is replaced by one to the other side.
        restuck = escaping & running & stuck(recent, self._static, self.detectors.static_distance)
        over = escaping & running & ~restuck & ((d < self._until)
                                                | (t - self._escaping_since >= self._escape_steps))
        if over.any():  # the escape ends; the detectors start again with an empty memory
            self.frustration[over] = 0.0
            self.track[over, :t] = np.nan
        seeking = running & ~escaping
        static = seeking & stuck(recent, self._static, self.detectors.static_distance)
        cyclic = seeking & ~static & looping(self.track[:, max(0, t + 1 - self._window):t + 1],
                                             self._after, self.detectors.cycle_radius)
        fire = static | cyclic | restuck
        if fire.any():
            self.fired[:, 0] += static | restuck
            self.fired[:, 1] += cyclic
            self.escapes += fire
            new = fire & ~escaping
            self.frustration[new] = 1.0
            self.frustration[restuck] = -self.frustration[restuck]
            self._until[new] = self.best[new] - self.detectors.escape_margin
            self._escaping_since[fire] = t
            self.track[fire, :t] = np.nan  # the escape's own track starts here
        self.best = np.minimum(self.best, d)

    def reward(self, active: npt.NDArray[np.bool_]) -> npt.NDArray[np.float64]:
        """The step's progress towards the goal as a fraction of the start's distance, plus 1
        on arrival, less ``contact_penalty / steps`` for a step a wall or box stopped."""
        d = self.distance()
        progress = (self._last - d) / np.maximum(self.start_distance, 1e-9)
        self._last = d
        contact = self.fleet.contacts & active
        self.contact_steps += contact
        arrived = active & ~self.arrived & (d <= self.goal_radius)
        self.arrived |= arrived
        return np.where(active, progress + arrived - self.contact_penalty * contact / self.steps, 0.0)

    def done(self, active: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
        """An episode ends on arrival, or after :attr:`steps` steps."""
        return np.asarray(self.arrived | (self.t >= self.steps))

    def success(self, returns: npt.NDArray[np.float64], lengths: npt.NDArray[np.int64]
                ) -> npt.NDArray[np.bool_]:
        """Which episodes of the last rollout reached the goal."""
        return self.arrived.copy()


def navigator() -> _core.Network:
    """The hand-designed network, from ``dnnevo/robots/data/navigator.json``."""
    return _core.Network.from_json(_data("navigator.json").read_text(encoding="utf-8"))


def design(*, cruise: float = 1.4, goal_gain: float = 4.0, relay_gain: float = 4.0,
           front: float = 1.5, front_turn: float = 2.5, diagonal: float = 3.0, side: float = 2.0,
           frustration_turn: float = 0.7, frustration_block: float = 8.0,
           tau_motor: float = 0.2, tau_relay: float = 0.2) -> _core.Network:
    """The hand-designed network, built from its documented weights (docs/reactive-navigation.md);
    :func:`navigator` loads the same network from the shipped file.

    Neurons: 0 and 1 the left and right motors, 2 and 3 the goal relays (goal on the left, on
    the right). Inputs: the eight sonars (0 ahead, then counter-clockwise every 45 degrees), the
    destination sensor (left, right) and the frustration input."""
    n, m = 4, 11
    tau = np.array([tau_motor, tau_motor, tau_relay, tau_relay])
    theta = np.array([-cruise, -cruise, 0.0, 0.0])
    w = np.zeros((n, n))
    # Goal on the left (relay 2) speeds the right wheel and slows the left: turn towards it.
    w[0, 2], w[1, 2] = -goal_gain, goal_gain
    w[0, 3], w[1, 3] = goal_gain, -goal_gain
    s = np.zeros((n, m))
    # Sonars: 0 ahead, 1 front-left, 2 left, 6 right, 7 front-right.
    s[0, 0], s[1, 0] = -front - front_turn, -front + front_turn   # slow down, turn left
    s[0, 1], s[1, 1] = diagonal, -diagonal                        # obstacle front-left: turn right
    s[0, 7], s[1, 7] = -diagonal, diagonal                        # obstacle front-right: turn left
    s[0, 2], s[1, 2] = side, -side
    s[0, 6], s[1, 6] = -side, side
    s[2, 8], s[3, 9] = relay_gain, relay_gain                     # the destination sensor
    s[2, 10], s[3, 10] = -frustration_block, -frustration_block   # frustration silences the goal
    s[0, 10], s[1, 10] = frustration_turn, -frustration_turn      # ... and bends right (+1) or left (-1)
    return _core.Network(tau, theta, w, s)


def hand_designed(world: str | PathLike[str] | Mapping[str, Any], starts: int, *, seed: int,
                  detectors: bool = False, finer: int = 1, steps: int = 1200) -> dict[str, Any]:
    """The hand-designed network (:func:`navigator`) in ``world`` from ``starts`` fresh start
    poses drawn from ``seed`` (``purpose="evaluate"``: the same starts with and without
    ``detectors``), for trials of ``steps`` steps of 0.1 s; with ``finer`` > 1 the world's and
    the network's steps are ``finer`` times shorter (as many more steps). Returns the world's
    name, ``detectors``, the world's step ``dt`` (s), ``arrived`` (the starts that reached the
    goal), ``starts``, the mean ``time`` to arrive (s; NaN when none did), the fraction of steps
    in ``contact`` with a wall or box, and the ``static`` and ``cyclic`` firings per start.

    >>> r = hand_designed("open-room", 4, seed=7, steps=300)
    >>> (r["arrived"], r["starts"])
    (4, 4)
    """
    _at_least_one("starts", starts)
    _at_least_one("finer", finer)
    _at_least_one("steps", steps)
    env = Navigate(world, detectors=detectors, dt=0.1 / finer, steps=steps * finer)
    r = rollout([navigator()], env, episodes=starts, max_steps=env.steps, seed=seed, purpose="evaluate",
                dt=INTEGRATOR["dt"] / finer, substeps=INTEGRATOR["substeps"], method=INTEGRATOR["method"])
    ok = env.success(r.returns[0], r.lengths[0])
    seconds = r.lengths[0] * env.settings["dt"]
    return {"world": world if isinstance(world, str) else str(world), "detectors": detectors,
            "dt": env.settings["dt"], "arrived": int(ok.sum()), "starts": starts,
            "time": float(seconds[ok].mean()) if ok.any() else float("nan"),
            "contact": float(env.contact_steps.sum() / r.lengths.sum()),
            "static": float(env.fired[:, 0].mean()), "cyclic": float(env.fired[:, 1].mean())}
