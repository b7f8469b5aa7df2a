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

import copy
import warnings
from collections.abc import Callable, Mapping
from os import PathLike
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

from dnnevo import _core, plot
from dnnevo.analysis import events
from dnnevo.closedloop import named
from dnnevo.closedloop.loop import Rollout
from dnnevo.config import EvolutionConfig
from dnnevo.errors import InvalidArgumentError
from dnnevo.evaluation.stats import wilson
from dnnevo.robots.world import D0, RobotWorld
from dnnevo.tasks import user
from dnnevo.tasks.protocol import Analysis, ViewResult

__all__ = ["APPEARS", "ARENA", "PURSUERS", "SECTORS", "TRANSFER", "TRANSFER_FACTORS", "Pursuit", "appears", "drive",
           "escape", "pursuer_appears", "transfer_part"]

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

TRANSFER_FACTORS: dict[str, tuple[str, ...]] = {"room": ("world",), "pursuers": ("pursuers",),
                                                "noise": ("sonar", "sector_noise_sd")}
"""The three changes :data:`TRANSFER` makes at once, each named by the keys of :data:`TRANSFER`
it sets: the room (its size, boxes and starting area), the pursuers (faster, sharper-turning)
and the sensors' noise (on the sonar ranges and on the pursuer sensor's gaps). Each key belongs
to one factor; :func:`transfer_part` makes a world of some of them."""


def transfer_part(*factors: str) -> dict[str, Any]:
    """The arguments of :class:`Pursuit` for the training world changed by ``factors`` (names of
    :data:`TRANSFER_FACTORS`) alone, as :data:`TRANSFER` changes them: no factor is the training
    world, all of them :data:`TRANSFER` itself. A copy: changing it leaves :data:`TRANSFER` alone.

    >>> sorted(transfer_part("noise"))
    ['sector_noise_sd', 'sonar']
    >>> transfer_part("pursuers")
    {'pursuers': {'speed': 0.45, 'max_turn_rate': 2.5}}
    >>> transfer_part() == {} and transfer_part(*TRANSFER_FACTORS) == TRANSFER
    True
    """
    unknown = [f for f in factors if f not in TRANSFER_FACTORS]
    if unknown:
        raise InvalidArgumentError(f"no transfer factor {unknown[0]!r}; expected one of {', '.join(TRANSFER_FACTORS)}")
    keys = {key for f in factors for key in TRANSFER_FACTORS[f]}
    return copy.deepcopy({key: value for key, value in TRANSFER.items() if key in keys})


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


APPEARS: dict[str, float] = {"hidden_s": 3.0, "before_s": 2.0, "after_s": 5.0, "episodes": 100}
"""The settings of :func:`pursuer_appears`: the pursuer sensor hidden for the first ``hidden_s``
seconds of ``episodes`` fresh episodes, and windows from ``before_s`` before an appearance to
``after_s`` after it."""


def appears(sectors: npt.ArrayLike, *, quiet: int) -> list[int]:
    """The steps at which a pursuer becomes visible to the pursuer sensor: ``sectors`` (T, Q)
    are its inputs (0: no pursuer within its reach), and a pursuer appears at a step where some
    sector reads one after none did for at least ``quiet`` steps (:func:`dnnevo.analysis.events.onsets`)."""
    s = np.asarray(sectors, dtype=float)
    return events.onsets((s > 0.0).any(axis=1), quiet=quiet)


def _wrap(a: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    return np.asarray((a + np.pi) % (2.0 * np.pi) - np.pi)


SERIES = {"away_speed": "velocity away from the pursuer the wheels command (m/s)",
          "speed": "forward speed the wheels command (m/s)",
          "turn_away": "turning of the direction of travel away from the pursuer the wheels command (rad/s)",
          "bearing_deg": "pursuer's bearing off the direction of travel (deg)",
          "distance": "distance to the pursuer (m)"}
"""The series :func:`pursuer_appears` follows through each window, as ``analysis.json`` names them.
The first three are the wheel commands of the step (a robot pressed against a wall moves less)."""


def _event(e: user.Episode, at: int, before: int, after: int, settings: dict[str, Any],
           left: int, right: int) -> dict[str, Any]:
    """One appearance's window: the pursuer nearest at ``at`` followed from ``before`` steps
    before to ``after`` after."""
    pose, chasers = e.probes["pose"], e.probes["pursuers"]
    k = int(np.argmin(np.hypot(*(chasers[at, :, :2] - pose[at, :2]).T)))
    dx, dy = (chasers[:, k, :2] - pose[:, :2]).T
    speed, base = settings["robot"]["max_speed"], settings["robot"]["wheel_base"]
    wheels = speed * (2.0 * e.outputs[:, [left, right]] - 1.0)
    forward, omega = wheels.mean(axis=1), (wheels[:, 1] - wheels[:, 0]) / base
    # The direction of travel is the heading, or its opposite while the robot backs; it turns
    # with the heading, so turning it away from the pursuer is -omega * sign(its bearing).
    travel = pose[:, 2] + np.where(forward < 0.0, np.pi, 0.0)
    bearing = _wrap(np.arctan2(dy, dx) - travel)
    series = {"away_speed": -np.abs(forward) * np.cos(bearing), "speed": forward,
              "turn_away": -omega * np.sign(bearing), "bearing_deg": np.degrees(np.abs(bearing)),
              "distance": np.hypot(dx, dy)}
    out: dict[str, Any] = {name: events.aligned(v, at, before=before, after=after) for name, v in series.items()}
    out["rates"] = events.aligned(e.outputs, at, before=before, after=after)
    out["length"], out["at"] = len(e.outputs), at
    return out


def _rate(k: int, n: int) -> str:
    if n == 0:
        return "0/0"
    lo, hi = wilson(k, n)
    return f"{k}/{n} (95% {lo:.0%}-{hi:.0%})"


def pursuer_appears(config: EvolutionConfig, net: _core.Network, seed: int, title: str) -> ViewResult:
    """What the champion does when a pursuer appears: ``analysis.json``'s ``pursuer_appears``,
    its summary lines and ``analysis-pursuer.png``.

    The pursuer sensor reaches 6.5 m through walls, and the pursuers start at least 3 m away in
    an 8 m x 6 m room: in the trained world a pursuer is in reach from the first step of almost
    every episode, and is seldom lost again. So the view counts that on :data:`APPEARS`'s
    ``episodes`` fresh episodes drawn from ``seed`` (the first of those ``dnnevo assess``
    judges with it, ``purpose="evaluate"``, which no run draws from), and then makes the event
    itself: the same episodes again with the pursuer sensor reading nothing for the first
    ``hidden_s`` seconds, while the pursuers chase the robot. The step at which the sensor
    reads a pursuer after ``before_s`` of nothing (:func:`appears`) is t = 0; the pursuer
    nearest then is followed, and each :data:`SERIES` and every neuron's firing rate is drawn
    as the mean over the appearances with ±1 standard deviation. Appearances in the unchanged
    episodes, if there are at least 2, are drawn too."""
    a = APPEARS
    params = {k: v for k, v in config.task_params.items() if k not in named.ROLLOUT_KEYS}
    loop_dt = float(Pursuit(**params).settings["dt"])
    hidden, before, after = (round(a[k] / loop_dt) for k in ("hidden_s", "before_s", "after_s"))
    episodes = int(a["episodes"])
    left, right = 0, 1  # Pursuit's wheels (RobotWorld's defaults)
    found: dict[str, Any] = {}

    def probe(env: Any) -> dict[str, npt.ArrayLike]:
        found.setdefault("settings", env.settings)
        found.setdefault("sonars", len(env.settings["sonar"]["angles_deg"]))
        return {"pose": env.fleet.poses, "pursuers": env.fleet.pursuers}

    def hide(t: int, obs: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        if t >= hidden:
            return obs
        out = obs.copy()
        out[:, found["sonars"]:] = 0.0
        return out

    limit = int(named.closed_loop(config).settings["max_steps"])  # type: ignore[call-overload]
    natural = user.record(config, net, episodes, seed=seed, probe=probe)
    m = found["sonars"]
    at_start = sum(bool((e.inputs[0, m:] > 0).any()) for e in natural)
    probed = user.record(config, net, episodes, seed=seed, probe=probe, shown=hide)
    hidden_name = f"sensor hidden for the first {a['hidden_s']:g} s"
    groups = {name: [_event(e, t, before, after, found["settings"], left, right)
                     for e in recorded for t in appears(e.inputs[:, m:], quiet=before)]
              for name, recorded in (("trained world", natural), (hidden_name, probed))}
    for evs in groups.values():
        for ev in evs:  # an episode that ended inside the window before the step limit: caught
            ev["caught"] = ev["at"] + after >= ev["length"] and ev["length"] < limit
    t_axis = np.asarray(np.arange(-before, after + 1) * loop_dt, dtype=np.float64)
    doc: dict[str, Any] = {**a, "seed": seed, "purpose": "evaluate", "visible_at_start": at_start,
                           "t": t_axis.tolist(), "series": SERIES,
                           "groups": {name: _group(evs, before, round(1.0 / loop_dt)) for name, evs in groups.items()}}
    lines = [f"pursuer appears: in the trained world the pursuer sensor reads a pursuer from the first step in "
             f"{at_start}/{episodes} fresh episodes (seed {seed}); one appears after {a['before_s']:g} s unseen "
             f"{len(groups['trained world'])} times"]
    for name, evs in groups.items():
        g = doc["groups"][name]
        if not evs or (name == "trained world" and len(evs) < 2):
            continue
        lines.append(f"    {name}: {len(evs)} appearances, the pursuer {g['distance_at_onset']:.2f} m away on "
                     f"average; over the next {a['after_s']:g} s the robot's forward speed averages "
                     f"{g['mean_speed']:+.2f} m/s ({g['mean_speed_before']:+.2f} in the {a['before_s']:g} s before) "
                     f"and its velocity away from the pursuer {g['mean_away_speed']:+.2f} m/s "
                     f"({g['mean_away_speed_before']:+.2f} before)")
        lines.append(f"    moving away from it on average over those {a['after_s']:g} s in "
                     f"{_rate(g['moves_away'], g['lasted'])}, farther from it at their end in "
                     f"{_rate(g['farther'], g['lasted'])}; turns its direction of travel away from it over the "
                     f"first second in "
                     f"{_rate(g['turns_away_1s'], len(evs))}; caught within {a['after_s']:g} s in "
                     f"{_rate(g['caught'], len(evs))}")
    fig = _figure(groups, t_axis, title)
    return ViewResult("pursuer_appears", doc, lines, {"analysis-pursuer.png": fig})


def _group(evs: list[dict[str, Any]], zero: int, per_second: int) -> dict[str, Any]:
    """One group's numbers: counts for the summary, and each series' mean and standard deviation
    over the events at each step (None where no event has a value); ``per_second`` steps make a
    second."""
    lasted = [e for e in evs if np.isfinite(e["distance"][-1])]
    second = zero + per_second
    after = np.array([e["away_speed"][zero:] for e in evs]) if evs else np.zeros((0, 1))
    with warnings.catch_warnings():  # a step that every appearance's episode has ended by is NaN
        warnings.simplefilter("ignore", RuntimeWarning)
        out: dict[str, Any] = {
            "events": len(evs), "lasted": len(lasted),
            "distance_at_onset": float(np.mean([e["distance"][zero] for e in evs])) if evs else None,
            "mean_speed": float(np.nanmean([e["speed"][zero:] for e in evs])) if evs else None,
            "mean_away_speed": float(np.nanmean(after)) if evs else None,
            "mean_away_speed_before": float(np.nanmean([e["away_speed"][:zero] for e in evs])) if evs else None,
            "mean_speed_before": float(np.nanmean([e["speed"][:zero] for e in evs])) if evs else None,
            "moves_away": sum(bool(np.mean(e["away_speed"][zero:]) > 0) for e in lasted),
            "farther": sum(bool(e["distance"][-1] > e["distance"][zero]) for e in lasted),
            "turns_away_1s": sum(bool(np.nanmean(e["turn_away"][zero:second + 1]) > 0) for e in evs),
            "caught": sum(bool(e["caught"]) for e in evs),
        }
        for name in (*SERIES, "rates"):
            if evs:
                w = np.array([e[name] for e in evs])
                mean, sd = np.nanmean(w, axis=0), np.nanstd(w, axis=0)
                out[name] = {"mean": _json(mean), "sd": _json(sd)}
    return out


def _json(a: npt.NDArray[np.float64]) -> Any:
    """``a`` as nested lists, None where it is not finite (a step every event had ended by)."""
    out = a.astype(object)
    out[~np.isfinite(a)] = None
    return out.tolist()


def _figure(groups: dict[str, list[dict[str, Any]]], t: npt.NDArray[np.float64], title: str) -> Any:
    """One panel per series and one of the firing rates, over the time from the appearance."""
    fig, axes = plot.subplots(5, 1, figsize=(7.0, 9.0), sharex=True, layout="constrained")
    shown = {name: evs for name, evs in groups.items() if len(evs) >= 2}
    for g, (name, evs) in enumerate(shown.items()):
        color = "tab:gray" if name == "trained world" else "tab:blue"
        label = f"{name} ({len(evs)} appearances)"
        events.plot_aligned(t, [e["away_speed"] for e in evs], axes[0], label=f"away from it, {label}", color=color)
        events.plot_aligned(t, [e["speed"] for e in evs], axes[0], label=f"forward, {label}",
                            color="tab:orange" if color == "tab:blue" else "tab:brown")
        events.plot_aligned(t, [e["turn_away"] for e in evs], axes[1], label=label, color=color)
        events.plot_aligned(t, [e["bearing_deg"] for e in evs], axes[2], label=label, color=color)
        events.plot_aligned(t, [e["distance"] for e in evs], axes[3], label=label, color=color)
        if g == len(shown) - 1:
            rates = np.array([e["rates"] for e in evs])
            wheel = {0: " (left wheel)", 1: " (right wheel)"}
            for i in range(rates.shape[2]):
                events.plot_aligned(t, rates[:, :, i], axes[4], label=f"neuron {i}{wheel.get(i, '')}", color=f"C{i}")
            axes[4].set_title(f"firing rates, {name}", fontsize=9)
    for ax in axes[:2]:
        ax.axhline(0.0, color="0.6", lw=0.8)
    for ax, text in zip(axes, ("speed (m/s)", "turning away\n(rad/s)", "bearing off\ntravel (deg)",
                               "distance (m)", "firing rate")):
        ax.set_ylabel(text)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="best", ncol=3 if ax is axes[4] else 1)
    axes[2].set_ylim(0, 180)
    axes[4].set_ylim(0, 1)
    axes[4].set_xlabel("time from the pursuer's appearance (s); mean ± 1 s.d. over appearances")
    axes[0].set_title(f"{title}: when a pursuer appears")
    return fig


# Declared outside the class body so that the class's source, which a run folder's
# fitness_sha256 records, stays that of the runs evolved before analyze knew this task.
Pursuit.analysis = Analysis(  # type: ignore[attr-defined]
    input_names=[f"sonar {a:g} deg" for a in (0, 45, 90, 135, 180, -135, -90, -45)]
    + [f"pursuer {s}" for s in ("front", "left", "back", "right")],
    conditions={"nothing sensed": [0.0] * 12,
                **{f"pursuer {s} at 1.5 m": [0.0] * 8 + [1.0 - 1.5 / 6.5 if q == k else 0.0 for q in range(4)]
                   for k, s in enumerate(("front", "left", "back", "right"))}},
    main_input=8, output_neuron=0, episodes=4, views=[pursuer_appears],
)
