"""Held-out test worlds for landmark recognition (issue 47): worlds that no run trains or selects
on, in sets of three (:data:`SETS`), each world differing in kind from the others of its set and
from what the varied training it was chosen against changes, so that a champion's rate in them
measures transfer. The first set (:data:`WORLDS`) was chosen against ``landmark-robust``'s
training, the second (:data:`SECOND`) against ``landmark-wide``'s.

Each world is a ``task_params`` overlay; :func:`config` puts one on top of a run's own task
settings (less how it trained, :data:`NOT_CARRIED`, which never changes a fresh trial), and on the
paper's ideal world (the defaults of ``crates/tasks/src/landmark/config.rs``) for a run that keeps
the defaults. Every
number and why it was chosen: ``docs/landmark.md``, "Transfer to held-out worlds".

What ``landmark-robust`` varies in training, per trial (``training.rs``; ``landmark-wide`` varies
the same further, and the room's size and the sonar's axis besides): the whole landmark's
position (+-0.15 m), turn (+-5 deg) and size (+-8%), the follower's speed (+-8%) and wall
distance (+-0.05 m), the sonar's cone (+-8 deg), the trial's length (+-3 s), and the input's
gain (+-15%), offset (+-0.025) and noise (sd 0.015, on the input, not the range). The robot-like
test adds range noise (sd 0.03 m), specular misses beyond 60 deg, each box moved on its own and a
room scaled by up to 5%.

>>> sorted(WORLDS)
['follower', 'room', 'sonar']
>>> WORLDS["follower"].params["sim"]["follower"]["speed"]
0.45
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass
from typing import Any

from dnnevo.config import EvolutionConfig
from dnnevo.errors import InvalidArgumentError
from dnnevo.tasks import landmark

__all__ = ["NOT_CARRIED", "SECOND", "SETS", "TRAINING", "WORLDS", "World", "config", "envelope_edges", "factors", "get",
           "single_factors", "world_set"]


@dataclass(frozen=True)
class World:
    """A held-out world: its name, what it changes and the overlay that makes it."""

    name: str
    changes: str
    """What differs from the training world, in words."""
    params: dict[str, Any]
    """The ``task_params`` the world changes (the run's own settings for everything it leaves
    out: see :func:`config`)."""
    parts: dict[str, dict[str, Any]] = dataclasses.field(default_factory=dict)
    """The factors it changes, each alone: name to the ``task_params`` that change only that
    factor (empty for a world that changes one thing); :func:`single_factors` makes worlds of
    them."""


def _sim(*, follower: dict[str, float] | None = None, sonar: dict[str, Any] | None = None) -> dict[str, Any]:
    """The ``sim`` section with the follower's and the network's sonar's settings given (the core
    fills in the defaults of the rest)."""
    sim: dict[str, Any] = {}
    if follower:
        sim["follower"] = dict(follower)
    if sonar:
        sim["sonars"] = [dict(sonar)]
    return sim


def _room(width: float, height: float, centre: tuple[float, float]) -> dict[str, Any]:
    """Both landmarks in a ``width`` x ``height`` room with their centre at ``centre``: the
    shipped boxes (landmark 1 one 1.2 m x 0.6 m box, landmark 2 two 0.6 m crates 0.6 m apart)
    moved as they are, and the start region 0.4 m from the walls as in the shipped worlds."""
    out = {}
    for n in (1, 2):
        world = landmark.default_world(n)
        dx, dy = centre[0] - 3.0, centre[1] - 2.5  # the shipped landmarks' centre
        boxes = [{**b, "center": [round(b["center"][0] + dx, 9), round(b["center"][1] + dy, 9)]}
                 for b in world["boxes"]]
        out[f"landmark{n}"] = {"room": [width, height], "boxes": boxes,
                               "start": {"min": [0.4, 0.4], "max": [width - 0.4, height - 0.4]}}
    return out


TRAINING = World("training", "the run's own world, unvaried (the paper's ideal world for a run that keeps "
                 "the defaults)", {})
"""The training world itself, for reference: the run's own settings, no variation."""

_FOLLOWER = {"speed": {"speed": 0.45}, "wall distance": {"wall_distance": 0.80},
             "turn rate": {"max_turn_rate": 1.2}}
_SONAR = {"beam": {"cone_deg": 40.0, "rays": 11},  # as many rays per degree as training's
          "axis": {"mount_angle_deg": 75.0}, "range noise": {"noise_sd": 0.05},
          "specular misses": {"specular_max_incidence_deg": 45.0}, "range": {"max_range": 4.0}}


def _all(parts: dict[str, dict[str, Any]]) -> dict[str, Any]:
    return {k: v for part in parts.values() for k, v in part.items()}


WORLDS: dict[str, World] = {w.name: w for w in [
    World("follower",
          "another wall follower: 0.45 m/s (-25%), 0.80 m from the wall (+0.25 m), corners turned at "
          "1.2 rad/s at most (2.0)",
          {"sim": _sim(follower=_all(_FOLLOWER))},
          {name: {"sim": _sim(follower=part)} for name, part in _FOLLOWER.items()}),
    World("sonar",
          "another sonar: a 40 deg cone (25) of 11 rays, its axis 15 deg forward of the side (75 deg), "
          "range noise sd 0.05 m, specular misses beyond 45 deg incidence, 4 m range",
          {"sim": _sim(sonar=_all(_SONAR))},
          {name: {"sim": _sim(sonar=part)} for name, part in _SONAR.items()}),
    World("room",
          "a bigger room, 8 m x 6.5 m (6 x 5), the landmark off-centre at (3.2, 2.6): 2.3-2.6 m from the "
          "left and bottom walls, 3.6-4.2 m from the others (2.1-2.4 m from every wall in training)",
          _room(8.0, 6.5, (3.2, 2.6))),
]}
"""The first set of held-out worlds by name: chosen against ``landmark-robust``'s training."""

_WEAVING = {"damping": {"angle_gain": 0.3}, "corners": {"corner_distance": 0.9}}
# A cone within landmark-wide's (25 +- 15 deg), with as many rays per degree as training's.
_LOBE = {"beam pattern": {"cone_deg": 40.0, "rays": 11, "lobe_deg": 10.0}, "dropouts": {"dropout": 0.1}}


def _boxes(n: int, boxes: list[dict[str, Any]]) -> dict[str, Any]:
    """Landmark ``n``'s boxes replaced (its room and start region kept)."""
    return {f"landmark{n}": {"boxes": boxes}}


_BAR = [{"center": [3.0, 2.5], "size": [1.2, 0.3], "angle_deg": 0.0}]
_CRATES = [{"center": [x, 2.5], "size": [0.4, 0.4], "angle_deg": 0.0} for x in (2.3, 3.0, 3.7)]

SECOND: dict[str, World] = {w.name: w for w in [
    World("weaving",
          "another wall-following law: weakly damped (angle gain 0.3, 2.2 in training), so that the robot "
          "weaves along each wall, and corners started 0.9 m early (0.35), so that it cuts them wide",
          {"sim": _sim(follower=_all(_WEAVING))},
          {name: {"sim": _sim(follower=part)} for name, part in _WEAVING.items()}),
    World("lobe",
          "another beam pattern and failures: a 40 deg cone of 11 rays whose reach falls off away from the "
          "axis (a 10 deg Gaussian lobe: wide for near surfaces, narrow for far ones), and 10% of readings "
          "lost at random",
          {"sim": _sim(sonar=_all(_LOBE))},
          {name: {"sim": _sim(sonar=part)} for name, part in _LOBE.items()}),
    World("boxes",
          "other landmarks of the same extents: landmark 1 a thin 1.2 m x 0.3 m bar (1.2 x 0.6), landmark 2 "
          "three 0.4 m crates 0.3 m apart (two 0.6 m crates 0.6 m apart), spanning 1.8 m as in training",
          {**_boxes(1, _BAR), **_boxes(2, _CRATES)},
          {"landmark 1": _boxes(1, _BAR), "landmark 2": _boxes(2, _CRATES)}),
]}
"""The second set of held-out worlds by name: chosen against ``landmark-wide``'s training, before
any of its runs was judged, each differing in kind from what that training varies."""

SETS: dict[str, dict[str, World]] = {"first": WORLDS, "second": SECOND}
"""Every set of held-out worlds by name. A world's name is unique across sets."""


def world_set(name: str) -> str | None:
    """The set the held-out world ``name`` belongs to (``None`` for any other name).

    >>> world_set("room"), world_set("boxes"), world_set("training")
    ('first', 'second', None)
    """
    return next((s for s, worlds in SETS.items() if name in worlds), None)


def get(world: World | str) -> World:
    """``world`` itself, or the held-out world of that name (of any set).

    >>> get("boxes").name
    'boxes'
    >>> get("folower")
    Traceback (most recent call last):
    ...
    dnnevo.errors.InvalidArgumentError: no held-out world is called 'folower'; they are follower, sonar, room, weaving, lobe, boxes
    """
    if isinstance(world, World):
        return world
    found = world_set(world) if isinstance(world, str) else None
    if found is None:
        names = ", ".join(name for worlds in SETS.values() for name in worlds)
        raise InvalidArgumentError(f"no held-out world is called {world!r}; they are {names}")
    return SETS[found][world]


def single_factors(world: World | str) -> list[World]:
    """``world`` (or the held-out world of that name) taken apart: one world per factor it changes,
    named ``"WORLD: FACTOR"``, with only that factor changed; ``[world]`` for a world that changes
    one thing. Judging a champion in each says which factor it fails on.

    >>> [w.name for w in single_factors(WORLDS["follower"])]
    ['follower: speed', 'follower: wall distance', 'follower: turn rate']
    >>> [w.name for w in single_factors(WORLDS["room"])]
    ['room']
    """
    world = get(world)
    if not world.parts:
        return [world]
    return [World(f"{world.name}: {name}", f"{world.name}'s {name} alone", params)
            for name, params in world.parts.items()]


def envelope_edges(base: EvolutionConfig) -> list[World]:
    """Worlds at the ends of ``base``'s own training envelope, one variation at a time: each of
    the wall follower's speed and distance and the network's sonar's cone and axis that its
    ``training`` varies, set to the low and then the high end of its range as a training trial
    sets it (``crates/tasks/src/landmark/trials.rs``), the rest as in its training world. Training
    draws each variation uniformly over its range, so a champion that has learnt its envelope
    holds at each end. These are no held-out worlds: the run trained on every one of them, rarely.
    The landmark's, the room's, the trial's and the input's variations are not among them.

    >>> from dnnevo import presets
    >>> [w.name for w in envelope_edges(presets.get("landmark-robust"))]  # doctest: +NORMALIZE_WHITESPACE
    ['follower speed x0.92', 'wall distance -0.05 m', 'sonar cone -8 deg',
     'follower speed x1.08', 'wall distance +0.05 m', 'sonar cone +8 deg']
    >>> envelope_edges(presets.get("landmark"))
    []
    """
    params = landmark.params(base)
    training, follower, sonar = params["training"], params["sim"]["follower"], params["sim"]["sonars"][0]
    speed, distance = training["follower_speed"], training["follower_distance"]
    cone, axis = training["cone_deg"], training["sonar_axis_deg"]
    edges = []
    for sign in (-1, 1):
        if speed:
            factor = 1.0 + sign * speed
            edges.append(World(f"follower speed x{factor:g}", "the follower's speed at an end of training's range",
                               {"sim": {"follower": {"speed": follower["speed"] * factor}}}))
        if distance:
            edges.append(World(f"wall distance {sign * distance:+g} m",
                               "the follower's wall distance at an end of training's range",
                               {"sim": {"follower": {"wall_distance": follower["wall_distance"] + sign * distance}}}))
        if cone:
            edges.append(World(f"sonar cone {sign * cone:+g} deg", "the sonar's cone at an end of training's range",
                               {"sim": {"sonars": [{"cone_deg": sonar["cone_deg"] + sign * cone}]}}))
        if axis:
            edges.append(World(f"sonar axis {sign * axis:+g} deg", "the sonar's axis at an end of training's range",
                               {"sim": {"sonars": [{"mount_angle_deg": sonar["mount_angle_deg"] + sign * axis}]}}))
    return edges


NOT_CARRIED = ("training", "trials_per_landmark", "validation_trials", "train_robot_like")
"""A run's task settings that a held-out world leaves out: how the run trained and chose its
champion, which never changes a fresh trial."""


def _overlay(own: dict[str, Any], world: dict[str, Any]) -> dict[str, Any]:
    """``own`` task settings with ``world``'s on top: a landmark's world merges key by key (a
    world that changes the boxes keeps the run's room; the shipped world stands in for one the run
    does not set), a ``sim`` section part by part (the follower's and the robot's keys, each
    sonar's keys by its place in the list); any other setting is replaced."""
    out = copy.deepcopy(own)
    for key, value in world.items():
        if key in ("landmark1", "landmark2") and isinstance(value, dict):
            mine = out.get(key)
            base = mine if isinstance(mine, dict) else landmark.default_world(int(key[-1]))
            out[key] = {**base, **copy.deepcopy(value)}
            continue
        sim = out.get("sim")
        if key != "sim" or not isinstance(sim, dict) or not isinstance(value, dict):
            out[key] = copy.deepcopy(value)
            continue
        for part, settings in value.items():
            mine = sim.get(part)
            if part == "sonars" and isinstance(mine, list) and isinstance(settings, list):
                sim[part] = [{**(mine[i] if i < len(mine) else {}), **s} for i, s in enumerate(settings)]
                sim[part] += copy.deepcopy(mine[len(settings):])
            elif isinstance(mine, dict) and isinstance(settings, dict):
                sim[part] = {**mine, **settings}
            else:
                sim[part] = copy.deepcopy(settings)
    return out


def config(base: EvolutionConfig, world: World | str) -> EvolutionConfig:
    """``base`` (a run's config: its network layout and integrator) with ``world``'s task settings
    on top of its own, less those that only say how it trained (:data:`NOT_CARRIED`): the run's
    classifier, trial length, input scale and worlds stay its own wherever the held-out world
    does not change them. The task is built here, so a world that does not validate fails now.

    >>> from dnnevo import presets
    >>> cfg = config(presets.get("landmark-robust"), WORLDS["room"])
    >>> landmark.params(cfg)["landmark1"]["room"], landmark.params(cfg)["training"]["cone_deg"]
    ([8.0, 6.5], 0.0)
    >>> own = dataclasses.replace(presets.get("landmark"), task_params={"classifier": 3})
    >>> landmark.params(config(own, "weaving"))["classifier"]
    3
    """
    world = get(world)
    if base.task != landmark.NAME:
        raise InvalidArgumentError(f"the run's task is {base.task!r}; held-out worlds are for the "
                                   f"{landmark.NAME!r} task")
    own = {k: v for k, v in base.task_params.items() if k not in NOT_CARRIED}
    out = dataclasses.replace(base, task_params=_overlay(own, world.params))
    landmark.params(out)  # builds the task: an invalid world fails here
    return out


def factors(world: World | str) -> dict[str, tuple[Any, Any]]:
    """The task settings ``world`` (or the held-out world of that name) changes, by dotted name,
    as (training value, world value).

    >>> factors(WORLDS["follower"])["sim.follower.speed"]
    (0.6, 0.45)
    """
    base = landmark.params(EvolutionConfig(task=landmark.NAME))
    mine = landmark.params(config(EvolutionConfig(task=landmark.NAME), world))
    out: dict[str, tuple[Any, Any]] = {}

    def walk(a: Any, b: Any, path: str) -> None:
        if isinstance(a, dict) and isinstance(b, dict):
            for k in sorted(set(a) | set(b)):
                walk(a.get(k), b.get(k), f"{path}.{k}" if path else k)
        elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b) and not all(
                isinstance(x, int | float) for x in a + b):
            for i, (x, y) in enumerate(zip(a, b, strict=True)):
                walk(x, y, f"{path}.{i}")
        elif a != b:
            out[path] = (a, b)

    walk(base, mine, "")
    return out
