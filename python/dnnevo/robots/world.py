"""A 2-D robot world as a closed-loop task (:class:`~dnnevo.closedloop.Environment`): each
network drives a robot's two wheels with its firing rates, and the robot's sensors are its next
inputs. One robot per row, all of them stepped together in Rust (``dnnevo._core.Fleet``).

:class:`RobotWorld` does the robot part: the world from a file, the wheels, the sensors and the
random starts. A task is a subclass that says what is rewarded and when an episode ends, in
NumPy over all rows at once, as :class:`~dnnevo.robots.Avoid` does::

    class Visit(RobotWorld):
        def reward(self, active):
            return (self.fleet.poses[:, 0] > 4.0).astype(float)  # a point per step at x > 4

>>> import dnnevo
>>> from dnnevo.closedloop import rollout
>>> from dnnevo.robots import RobotWorld
>>> env = RobotWorld("landmark1", sonar={"angles_deg": [-45, 0, 45]})
>>> env.observation_size
3
>>> result = rollout([dnnevo.Network.random(4, 3, seed=0)], env, episodes=2, max_steps=50)
>>> result.lengths.tolist()
[[50, 50]]
"""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.closedloop.environment import check_neurons
from dnnevo.errors import InvalidArgumentError

__all__ = ["D0", "WORLDS", "RobotWorld", "world_of", "world_text"]

WORLDS = {"landmark1": 1, "landmark2": 2}
"""The built-in worlds by name: the two rooms of the landmark experiment (docs/worlds.md)."""

D0 = 0.5
"""A sonar reading's input is ``min(1, D0 / range)``, as in the landmark task: 1 nearer than
0.5 m, falling as ``1 / range`` beyond."""


def world_of(world: str | PathLike[str] | Mapping[str, Any]) -> str | dict[str, Any]:
    """A world for :class:`dnnevo._core.Fleet`: a built-in world's name (:data:`WORLDS`) as a
    dict, a world file (a path ending in ``.toml``) as its text, a dict as it is."""
    if isinstance(world, Mapping):
        return dict(world)
    if isinstance(world, str) and world in WORLDS:
        return _core.sim2d_landmark_world(WORLDS[world])
    if isinstance(world, PathLike) or (isinstance(world, str) and world.endswith(".toml")):
        return world_text(world)
    hint = ""
    if isinstance(world, str) and Path(world).suffix:
        hint = f" (a world file's name ends in .toml, not {Path(world).suffix})"
    raise InvalidArgumentError(f"world is {world!r}; expected one of {', '.join(map(repr, WORLDS))}, "
                               f"a world file (a path ending in .toml) or a dict{hint}")


def world_text(path: str | PathLike[str]) -> str:
    """The text of the world file at ``path``: ``FileNotFoundError`` when there is none, an
    :class:`~dnnevo.errors.InvalidArgumentError` naming it when it cannot be read or is not
    UTF-8 text."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FileNotFoundError(f"world file {path} does not exist") from None
    except OSError as e:
        raise InvalidArgumentError(f"world file {path} cannot be read: {e.strerror}") from None
    except UnicodeDecodeError as e:
        raise InvalidArgumentError(f"world file {path} is not UTF-8 text (byte {e.start}): a "
                                   "world file is TOML") from None


def _neuron(name: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 0:
        raise InvalidArgumentError(f"{name} is {value!r}; expected a neuron index >= 0")
    return int(value)


class RobotWorld:
    """Robots in a 2-D world, one per row: a closed-loop task without a goal (every reward is 0,
    and an episode ends only when a pursuer captures its robot). Subclass it and override
    :meth:`reward` and :meth:`done` to make a task.

    ``world`` is a built-in world's name (:data:`WORLDS`), a world file (docs/worlds.md) or a
    dict. ``robot``, ``sonar``, ``pursuers`` and ``sectors`` are dicts of settings; anything left
    out keeps its default (docs/robots.md lists them all). Neurons ``left`` and ``right`` drive
    the wheels: a wheel's speed is ``max_speed * (2 * rate - 1)``, full speed backwards at rate
    0 and forwards at rate 1.

    Each step, :meth:`step` moves every running robot and its pursuers for ``dt`` seconds, then
    calls :meth:`observe`, :meth:`reward` and :meth:`done`, in this order. They read the rows'
    state from :attr:`fleet` (``poses``, ``contacts``, ``captured``, ``ranges``, ``sectors``,
    ``pursuers``), the wheel speeds just used from :attr:`wheels`, and the step count from
    :attr:`t`.
    """

    observation_size: int = 8
    """The sensors: one per sonar, then one per pursuer sector (8 with the default settings;
    each instance counts its own)."""

    def __init__(self, world: str | PathLike[str] | Mapping[str, Any] = "landmark1", *,
                 dt: float = 0.1, robot: Mapping[str, Any] | None = None,
                 sonar: Mapping[str, Any] | None = None,
                 pursuers: Mapping[str, Any] | None = None,
                 sectors: Mapping[str, Any] | None = None, start_clearance: float = 0.05,
                 left: int = 0, right: int = 1) -> None:
        settings: dict[str, Any] = {"dt": dt, "start_clearance": start_clearance}
        for name, section in (("robot", robot), ("sonar", sonar), ("pursuers", pursuers),
                              ("sectors", sectors)):
            if section is not None:
                if not isinstance(section, Mapping):
                    raise InvalidArgumentError(f"{name} is {section!r}; expected a dict of settings")
                settings[name] = dict(section)
        try:
            self.fleet = _core.Fleet(world_of(world), settings)
        except InvalidArgumentError as e:
            file = isinstance(world, PathLike) or isinstance(world, str) and world.endswith(".toml")
            if file and str(e).startswith("world file: "):  # the core parsed its text, not the file
                raise InvalidArgumentError(f"world file {world}: {str(e).removeprefix('world file: ')}") from None
            raise
        """The rows' robots, pursuers and readings (``dnnevo._core.Fleet``)."""
        self.world: dict[str, Any] = self.fleet.world
        """The world, as a dict."""
        self.settings: dict[str, Any] = self.fleet.settings
        """Every setting, defaults filled in."""
        self.left, self.right = _neuron("left", left), _neuron("right", right)
        if self.left == self.right:
            raise InvalidArgumentError(f"left and right are both neuron {left}; they must differ")
        self.max_speed: float = self.settings["robot"]["max_speed"]
        self.observation_size = len(self.settings["sonar"]["angles_deg"]) + self.settings["sectors"]["count"]

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator
              ) -> npt.NDArray[np.float64]:
        """Starts every row at its episode's random start (the robot, then its pursuers, each
        clear of walls and boxes; drawn from a seed taken from ``rng`` and the episode number,
        so every network meets the same starts) and returns the first observations."""
        self.fleet.reset(episodes, int(rng.integers(2**63)))
        self.t = 0
        """Steps since the reset."""
        self.wheels = np.zeros((len(episodes), 2))
        """The wheel speeds of the last step (B, 2), left and right, in m/s."""
        return self.observe()

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
        """Drives every running robot with its network's rates for one step; returns
        ``(observe(), reward(active), done(active))``."""
        check_neurons(rates, (self.left, self.right), f"{type(self).__name__}'s wheels (left, right)")
        self.wheels = self.max_speed * (2.0 * rates[:, (self.left, self.right)] - 1.0)
        self.fleet.step(self.wheels, active)
        self.t += 1
        return self.observe(), self.reward(active), self.done(active)

    def observe(self) -> npt.NDArray[np.float64]:
        """The networks' inputs (B, M): each sonar as ``min(1, D0 / range)`` (:data:`D0`), then
        each pursuer sector as ``1 - gap / range`` (0 with no pursuer in range, 1 touching)."""
        sonar = np.minimum(1.0, D0 / self.fleet.ranges)
        if not self.settings["sectors"]["count"]:
            return sonar
        near = 1.0 - self.fleet.sectors / self.settings["sectors"]["range"]
        return np.concatenate([sonar, near], axis=1)

    def reward(self, active: npt.NDArray[np.bool_]) -> npt.NDArray[np.float64]:
        """Each row's reward for the step just taken (B,): 0 here; a task overrides it."""
        return np.zeros(self.fleet.rows)

    def done(self, active: npt.NDArray[np.bool_]) -> npt.NDArray[np.bool_]:
        """Which rows' episodes ended at this step (B,): here those whose robot a pursuer
        captured."""
        return np.asarray(self.fleet.captured)
