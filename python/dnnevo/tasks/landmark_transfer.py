"""Judging landmark champions in the held-out worlds (issue 47), beside a trivial bound and an
upper bound fitted on each world: what ``examples/landmark_transfer.py`` and the reproduction's
``held-out-worlds`` jobs (:mod:`dnnevo.experiments.jobs`) both compute.

A champion is judged on fresh trials per landmark drawn from :data:`TEST_SEED` in each
:class:`Place`: the training world (the run's own world, unvaried: the paper's ideal world for a
run that keeps the defaults), the robot-like test, and
the held-out worlds of :mod:`dnnevo.tasks.landmark_worlds`, in sets of three. In each world, on
the same test trials, :func:`bounds` gives

- **constant**: always one answer: 50% by construction (as many trials of each landmark);
- **threshold**: the best single-threshold rule on the sonar input's mean or the fraction of
  steps it reads near (input above :data:`NEAR`, a range under 2 m), fitted on trials of that
  world drawn from :data:`FIT_SEED`;
- **observer**: logistic regression (:mod:`dnnevo.evaluation.observer`) on seven features of the
  input stream, fitted on the same :data:`FIT_SEED` trials; for a held-out world also fitted on
  the other two held-out worlds of its set only (leave one world out), which says whether the
  features themselves transfer.

The sonar does not depend on the network, so the bounds do not depend on the champion judged:
only on the trial counts (and the task settings a world keeps).

>>> [p.name for p in PLACES]
['training', 'robot-like', 'follower', 'sonar', 'room', 'weaving', 'lobe', 'boxes']
>>> held_out("second")
['weaving', 'lobe', 'boxes']
>>> meets(172, 200), meets(171, 200)
(True, False)
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo._checks import bounded_count
from dnnevo.errors import InvalidArgumentError
from dnnevo.evaluation import observer
from dnnevo.evaluation.stats import wilson
from dnnevo.tasks import landmark, landmark_worlds

__all__ = ["FIT_SEED", "TEST_SEED", "NEAR", "THRESHOLD_COLUMNS", "GOAL_RATE", "GOAL_LOWER", "Place", "PLACES",
           "held_out", "worlds_digest", "place", "sonar_features", "bounds", "pooled_bounds", "judge", "meets"]

FIT_SEED = 47_001
"""The seed of the trials the threshold rule and the observer are fitted on."""
TEST_SEED = 47_002
"""The seed of the trials everything is judged on. Runs draw their training and validation
trials from their own run seeds (0-9) under other stream purposes; ``dnnevo sweep`` and the docs
judge on 1000003 + seed, 3000003, 5000011 and 7: no run or earlier figure used 47001 or 47002."""

NEAR = 0.25
"""The input above which the sonar "reads near": a range under 0.5 / 0.25 = 2 m."""

THRESHOLD_COLUMNS = [observer.FEATURES.index("mean"), observer.FEATURES.index("fraction near")]
"""The features the single-threshold rule may use: the input's mean and the fraction near."""

GOAL_RATE, GOAL_LOWER = 0.85, 0.80
"""The issue's goal for a champion in a world: rate above 85%, interval's lower end above 80%."""


@dataclass(frozen=True)
class Place:
    """A world champions are judged in: its config overlay and whether trials are robot-like."""

    name: str
    world: landmark_worlds.World
    robot_like: bool = False


PLACES = [Place("training", landmark_worlds.TRAINING),
          Place("robot-like", landmark_worlds.TRAINING, robot_like=True),
          *(Place(name, w) for worlds in landmark_worlds.SETS.values() for name, w in worlds.items())]
"""Every place, in the tables' order."""


def held_out(world_set: str = "first") -> list[str]:
    """The names of the held-out worlds of ``world_set`` (see ``landmark_worlds.SETS``).

    >>> held_out("third")
    Traceback (most recent call last):
    ...
    dnnevo.errors.InvalidArgumentError: world_set is 'third'; the sets of held-out worlds are first, second
    """
    if not isinstance(world_set, str) or world_set not in landmark_worlds.SETS:
        raise InvalidArgumentError(f"world_set is {world_set!r}; the sets of held-out worlds are "
                                   + ", ".join(landmark_worlds.SETS))
    return list(landmark_worlds.SETS[world_set])



def worlds_digest(world_set: str) -> str:
    """SHA-256 of the task settings of ``world_set``'s held-out worlds and of the training world,
    on the defaults, every default filled in as the core reads them, less what a held-out job
    never uses (how a run trains, the robot-like test): it changes when any of those worlds does."""
    worlds = [landmark_worlds.TRAINING, *(landmark_worlds.get(name) for name in held_out(world_set))]
    unused = {*landmark_worlds.NOT_CARRIED, "robot_like"}
    settings = {}
    for w in worlds:
        params = landmark.params(landmark_worlds.config(EvolutionConfig(task=landmark.NAME), w))
        settings[w.name] = {k: v for k, v in params.items() if k not in unused}
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def place(name: str) -> Place:
    """The place called ``name``.

    >>> place("lobe").world.name
    'lobe'
    >>> place("folower")
    Traceback (most recent call last):
    ...
    dnnevo.errors.InvalidArgumentError: no place is called 'folower'; the places are training, robot-like, follower, sonar, room, weaving, lobe, boxes
    """
    found = next((p for p in PLACES if p.name == name), None)
    if found is None:
        raise InvalidArgumentError(f"no place is called {name!r}; the places are "
                                   + ", ".join(p.name for p in PLACES))
    return found


def _places(places: Sequence[Place | str] | None) -> list[Place]:
    """``places`` as places (names looked up), :data:`PLACES` when None."""
    return list(PLACES) if places is None else [place(p) if isinstance(p, str) else p for p in places]


def sonar_features(config: EvolutionConfig, net: _core.Network, per_landmark: int, seed: int,
                   robot_like: bool, describe: Callable[[Any, float], np.ndarray] = observer.features,
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Features and labels (0: landmark 1, 1: landmark 2) of the trials ``assess`` draws from
    ``seed``: trial t of ``2 per_landmark``, landmark 1 first (the sonar does not depend on the
    network, which the recorder only needs to run). ``describe(stream, NEAR)`` makes a trial's
    features: :func:`observer.features`, or :func:`observer.profile` for more."""
    rows, labels = [], []
    for t in range(2 * per_landmark):
        which = 1 if t < per_landmark else 2
        rec = landmark.record(config, net, which, seed=seed, trial=t, robot_like=robot_like)
        rows.append(describe(rec.input, NEAR))
        labels.append(which - 1)
    return np.array(rows), np.array(labels)


def pooled_bounds(base: EvolutionConfig, net: _core.Network, fit: int, test: int,
                  places: Sequence[Place | str]) -> dict[str, dict[str, int]]:
    """Whether one rule tells the landmarks apart in all ``places`` at once, as a champion
    trained on all of them must. In each place, trials right of ``test`` per landmark (from
    TEST_SEED) of: ``"own"``, the observer fitted on that place alone (``fit`` per landmark, from
    FIT_SEED); ``"one linear"``, one observer (logistic regression on the same features) fitted
    on every place's trials together; ``"one linear, profile"``, the same on the trials'
    :func:`observer.profile` (the features, the stream's distribution and its time course);
    ``"one nearest"``, the nearest of every place's fitted trials in their profile, which draws
    any boundary. ``n`` is the trials per place."""
    bounded_count("fit", fit)
    bounded_count("test", test)
    summary = len(observer.FEATURES)  # a profile starts with the features
    data = {}
    for p in _places(places):
        cfg = landmark_worlds.config(base, p.world)
        data[p.name] = (sonar_features(cfg, net, fit, FIT_SEED, p.robot_like, observer.profile),
                        sonar_features(cfg, net, test, TEST_SEED, p.robot_like, observer.profile))
    x = np.vstack([xf for (xf, _), _ in data.values()])
    y = np.concatenate([yf for (_, yf), _ in data.values()])
    linear = observer.fit_logistic(x[:, :summary], y)
    profiled = observer.fit_logistic(x, y)
    nearest = observer.fit_nearest(x, y)
    out = {}
    for name, ((xf, yf), (xt, yt)) in data.items():
        own = observer.fit_logistic(xf[:, :summary], yf)
        out[name] = {"own": int(np.sum(own.predict(xt[:, :summary]) == yt)),
                     "one linear": int(np.sum(linear.predict(xt[:, :summary]) == yt)),
                     "one linear, profile": int(np.sum(profiled.predict(xt) == yt)),
                     "one nearest": int(np.sum(nearest.predict(xt) == yt)), "n": len(yt)}
    return out


def bounds(base: EvolutionConfig, net: _core.Network, fit: int, test: int,
           places: Sequence[Place | str] | None = None) -> dict[str, dict[str, Any]]:
    """Each place's threshold rule and observer (of ``places``, places or their names, default
    :data:`PLACES`), fitted on ``fit`` trials per landmark from FIT_SEED and judged on ``test``
    from TEST_SEED; a held-out world also gets the observer fitted on the other held-out worlds of
    its set when all of them are among ``places``."""
    bounded_count("fit", fit)
    bounded_count("test", test)
    data = {}
    for p in _places(places):
        cfg = landmark_worlds.config(base, p.world)
        data[p.name] = (sonar_features(cfg, net, fit, FIT_SEED, p.robot_like),
                        sonar_features(cfg, net, test, TEST_SEED, p.robot_like))
    out = {}
    for name, ((xf, yf), (xt, yt)) in data.items():
        rule = observer.fit_threshold(xf, yf, THRESHOLD_COLUMNS)
        model = observer.fit_logistic(xf, yf)
        result = {"threshold": int(np.sum(rule.predict(xt) == yt)), "observer": int(np.sum(model.predict(xt) == yt)),
                  "n": len(yt), "rule": f"{observer.FEATURES[rule.feature]} {'>' if rule.sign > 0 else '<'} "
                                        f"{rule.threshold:.3g} says landmark 2"}
        world_set = landmark_worlds.world_set(name)
        group = held_out(world_set) if world_set else []
        if group and set(group) <= set(data):
            others = [data[o][0] for o in group if o != name]
            lowo = observer.fit_logistic(np.vstack([x for x, _ in others]), np.concatenate([y for _, y in others]))
            result["observer, other worlds"] = int(np.sum(lowo.predict(xt) == yt))
        out[name] = result
    return out


def judge(config: EvolutionConfig, net: _core.Network, trials: int,
          places: Sequence[Place | str] | None = None) -> dict[str, int]:
    """Trials right of ``net`` (a champion of ``config``) in each place (of ``places``, places or
    their names, default :data:`PLACES`; of ``2 trials``, drawn from TEST_SEED), and under
    ``"<place> one answer"`` the trials given its commoner answer."""
    out = {}
    for p in _places(places):
        report = landmark.assess(landmark_worlds.config(config, p.world), net, trials, TEST_SEED,
                                 robot_like=p.robot_like)
        (a, b), (c, d) = report["confusion"]
        out[p.name] = a + d
        out[f"{p.name} one answer"] = max(a + c, b + d)
    return out


def meets(k: int, n: int) -> bool:
    """Whether ``k`` right of ``n`` meets the issue's goal: more than 85%, the 95% Wilson
    interval's lower end above 80%."""
    return k / n > GOAL_RATE and wilson(k, n)[0] > GOAL_LOWER
