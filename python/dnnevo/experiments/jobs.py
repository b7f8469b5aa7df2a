"""Doing one job of ``dnnevo reproduce`` (:mod:`dnnevo.experiments.plan`), so that doing it again is safe.

A job's folder ``EXPERIMENT/seed-N`` is an ordinary run folder (for an evolution) and its result
is ``EXPERIMENT/seed-N.json``, written atomically when the job is done. :func:`run_job`:

- returns the stored result of a finished job, without work;
- resumes an evolution from its checkpoint when it was stopped (or its worker was killed), so the
  run's bits are those of an uninterrupted run;
- starts afresh a folder that holds no checkpoint yet.

Every result file is checked when read: a malformed one is a :class:`~dnnevo.runs.RunFileError`
naming it, and one written under other settings is refused.

The function is what a Dask worker runs, so it takes and returns plain data.
"""

from __future__ import annotations

import hashlib
import json
import time
from importlib import resources
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from dnnevo import tasks
from dnnevo.tasks import landmark_transfer, nav1d, registry
from dnnevo.experiments import plan
from dnnevo import presets
from dnnevo.evaluation import stats
from dnnevo.experiments import sweep
from dnnevo.evaluation.assessment import Assessment
from dnnevo.config import EvolutionConfig, with_later_defaults
from dnnevo.errors import ConfigError
from dnnevo.runs import RunDir, RunFileError, first_difference, short, write_atomic
from dnnevo.runs.files import read_json
from dnnevo.evolution.seeding import Seeding
from dnnevo.robots import navigation

__all__ = ["ROBOT_SEED_BASE", "SYSTEM_TRIALS", "HAND_STARTS", "HAND_QUICK_STARTS", "HAND_CONDITIONS", "WORLD_TRIALS",
           "WORLD_QUICK_TRIALS", "WORLDS_INPUT", "world_places", "Settings", "Stopped", "result_path", "read_result", "run_job",
           "hand_counts", "world_counts"]

ROBOT_SEED_BASE = 3_000_003
"""The robot-like test of seed s's landmark champion draws its trials from seed
``ROBOT_SEED_BASE + s``, which no run uses."""

SYSTEM_TRIALS = 5
"""Trials per environment of the integrated navigation system, as in the paper's Fig. 2."""

HAND_STARTS = 200
"""Fresh start poses per world and condition for the hand-designed reactive navigator, unless
``eval_trials`` says otherwise: as many as ``examples/reactive_navigation.py`` draws."""

HAND_QUICK_STARTS = 20
"""The same in a quick reproduction: it shows that the test runs, in about a second."""

HAND_STEPS = 1200
"""The hand-designed navigator's trials: 1200 steps of 0.1 s (120 s), ``Navigate``'s default."""

HAND_CONDITIONS = ("with", "without")
"""The hand-designed navigator's conditions: with the static and cyclic detectors, without."""

WORLD_TRIALS = 100
"""Trials per landmark of a held-out-worlds job in each world, unless ``eval_trials`` says
otherwise: as many as ``examples/landmark_transfer.py`` judges on, and as many again to fit the
bounds on."""

WORLD_QUICK_TRIALS = 10
"""The same in a quick reproduction: it shows that the test runs, in about a second."""

def world_places(world_set: str = "first") -> tuple[str, ...]:
    """The places a held-out-worlds job judges its champion in: the training world and the
    held-out worlds of ``world_set`` (the robot-like test is its own job).

    >>> world_places("second")
    ('training', 'weaving', 'lobe', 'boxes')
    """
    return ("training", *landmark_transfer.held_out(world_set))

_BOUNDS = ("threshold", "observer", "observer, other worlds")

WORLDS_INPUT = "held-out worlds: "
"""The start of a held-out-worlds test's input that holds its worlds' digest (results written
before it was added lack it)."""


class Stopped(Exception):
    """A job's run stopped on Ctrl-C or SIGTERM; its checkpoint lets the next call resume it."""


@dataclass(frozen=True)
class Settings:
    """What every job of one reproduction shares; recorded in its folder so that running the
    command again continues the same reproduction."""

    quick: bool = False
    """Each preset's quick variant (small population, few generations)."""
    eval_trials: int | None = None
    """Fresh trials judging each final champion, in the task's unit (default: the task's
    :data:`~dnnevo.tasks.DEFAULT_TRIALS`); also the robot-like test's trials per landmark."""
    eval_seed: int = sweep.EVAL_SEED_BASE
    """Seed s's final champion is judged on fresh conditions from ``eval_seed + s``."""
    dt_check: bool = True
    """Judge each final champion again at a 10x finer step and with RK4."""
    environments: int = 100
    """Fresh environments for the integrated navigation system."""
    overrides: tuple[str, ...] = ()
    """``key=value`` settings applied to every evolution after its own (e.g. ``population=200``
    for a cheaper reproduction)."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "overrides", tuple(self.overrides))
        for name in ("eval_trials", "eval_seed", "environments"):
            value = getattr(self, name)
            if value is not None and (not isinstance(value, int) or isinstance(value, bool) or value < 0
                                      or (value == 0 and name != "eval_seed")):
                raise ConfigError(f"{name} is {value!r}; it must be an integer >= {0 if name == 'eval_seed' else 1}")

    def config(self, experiment: plan.Experiment) -> EvolutionConfig:
        """The config of an evolution experiment under these settings."""
        if experiment.preset is None:
            raise ConfigError(f"{experiment.name} is not an evolution")
        overrides = list(experiment.overrides)
        if experiment.generations is not None and not self.quick:
            overrides.append(f"generations={experiment.generations}")
        return presets.get(experiment.preset, quick=self.quick, overrides=[*overrides, *self.overrides])

    def trials(self, task: str) -> int:
        """The fresh trials judging a champion of ``task``."""
        return self.eval_trials if self.eval_trials is not None else registry.get(task).DEFAULT_TRIALS

    def starts(self) -> int:
        """The hand-designed reactive navigator's fresh starts per world and condition:
        ``eval_trials`` when given, as the robot-like test's trials per landmark are, else
        :data:`HAND_QUICK_STARTS` in a quick reproduction and :data:`HAND_STARTS` in a full one."""
        if self.eval_trials is not None:
            return self.eval_trials
        return HAND_QUICK_STARTS if self.quick else HAND_STARTS

    def world_trials(self) -> int:
        """A held-out-worlds job's trials per landmark in each world (and the bounds' fitting
        trials): ``eval_trials`` when given, else :data:`WORLD_QUICK_TRIALS` in a quick
        reproduction and :data:`WORLD_TRIALS` in a full one."""
        if self.eval_trials is not None:
            return self.eval_trials
        return WORLD_QUICK_TRIALS if self.quick else WORLD_TRIALS

    def to_dict(self) -> dict[str, Any]:
        """The settings and every evolution's config, as plain JSON types."""
        configs = {e.name: self.config(e).to_dict() for e in plan.EXPERIMENTS if e.kind == plan.EVOLVE}
        return {"settings": asdict(self), "configs": configs}


def result_path(root: Path, job: plan.Job) -> Path:
    """Where ``job``'s result is stored: ``EXPERIMENT/seed-N.json`` under ``root``."""
    return root / job.experiment / f"seed-{job.seed}.json"


def read_result(root: Path, job: plan.Job, settings: Settings) -> dict[str, Any] | None:
    """``job``'s stored result, checked, or None when the job has not finished, or when the run
    files it was computed from have changed or gone since (then it is done again)."""
    path = result_path(root, job)
    if not path.exists() and not path.is_symlink():
        return None
    try:
        found = read_json(path)
        if not isinstance(found, dict):
            raise ValueError("not a JSON object")
        expected = _header(job, settings)
        stored = {k: found.get(k) for k in expected}
        stored["config"] = with_later_defaults(stored["config"])
        diff = first_difference(stored, expected)
        if diff is not None:
            raise RunFileError(f"{path}: its {diff[0]} is {short(diff[1])}, this reproduction's is {short(diff[2])}")
        _check_body(job, found, settings)
        if found["inputs"] != _inputs(root, job):
            return None
    except RunFileError:
        raise
    except (OSError, UnicodeDecodeError, ValueError, KeyError, TypeError, AttributeError, IndexError,
            OverflowError, RecursionError) as e:
        raise RunFileError(f"{path}: not a valid job result ({type(e).__name__}: {e}); delete it to "
                           "redo the job") from None
    return found


def _inputs(root: Path, job: plan.Job) -> dict[str, Any]:
    """What ``job``'s result was computed from, by path under ``root``: the SHA-256 of the
    champion (``best.json``) of its own run (an evolution) or of each run it tests, and an
    evolution's generation count (the rows of ``log.csv``; the file itself holds wall times).
    None stands for a missing file. A result whose inputs changed (a run folder deleted, a run
    extended with ``dnnevo resume``) is done again. The hand-designed navigator's inputs are the
    SHA-256 of the shipped network and worlds, and a held-out-worlds test's also the SHA-256 of
    its worlds' task settings as the core reads them, so that a result made with other ones is
    done again."""
    if job.spec.kind == plan.HAND_DESIGNED:
        files = ["navigator.json", *(f"{w}.toml" for w in navigation.WORLDS)]
        data = resources.files("dnnevo.robots").joinpath("data")
        return {f"dnnevo/robots/data/{f}": hashlib.sha256(data.joinpath(f).read_bytes()).hexdigest()
                for f in files}
    own = job.spec.kind == plan.EVOLVE
    out: dict[str, Any] = {}
    for run in [job.id] if own else list(job.needs):
        try:
            out[f"{run}/best.json"] = hashlib.sha256((root / run / "best.json").read_bytes()).hexdigest()
        except FileNotFoundError:
            out[f"{run}/best.json"] = None
    if job.spec.kind == plan.HELD_OUT:
        out[f"{WORLDS_INPUT}{job.spec.worlds}"] = landmark_transfer.worlds_digest(job.spec.worlds)
    if own:
        try:
            out[f"{job.id}/log.csv rows"] = len((root / job.id / "log.csv").read_text(encoding="utf-8").splitlines()) - 1
        except FileNotFoundError:
            out[f"{job.id}/log.csv rows"] = None
    return out


def _header(job: plan.Job, settings: Settings) -> dict[str, Any]:
    e = job.spec
    header = {"job": job.id, "kind": e.kind, "settings": asdict(settings),
              "config": settings.config(e).to_dict() if e.kind == plan.EVOLVE else None}
    return dict(json.loads(json.dumps(header)))


def _fraction(value: Any, what: str) -> float:
    x = float(value)
    if not 0.0 <= x <= 1.0:
        raise ValueError(f"{what} is {value!r}, not a fraction")
    return x


def _count(value: Any, what: str, low: int = 0, high: int | None = None) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or value < low or (high is not None and value > high):
        raise ValueError(f"{what} is {short(value)}; expected an integer from {low}"
                         + (f" to {high}" if high is not None else ""))
    return value


def hand_counts(found: dict[str, Any]) -> dict[str, dict[str, tuple[int, int]]]:
    """The hand-designed navigator's counts in a result, ``(arrived, starts)`` by world
    (:data:`~dnnevo.robots.navigation.WORLDS`) and condition (:data:`HAND_CONDITIONS`), checked:
    every world and condition there and nothing else, each count an integer, ``arrived`` from 0
    to ``starts``, ``starts`` the result's, its ``seed`` an integer and its ``steps``
:data:`HAND_STEPS` (a result of trials of another length is not pooled with these). Raises
    ValueError, KeyError or TypeError otherwise."""
    _count(found["seed"], "seed")
    if _count(found["steps"], "steps", 1) != HAND_STEPS:  # trials of another length
        raise ValueError(f"steps is {found['steps']}; this dnnevo's trials take {HAND_STEPS}")
    starts = _count(found["starts"], "starts", 1)
    worlds = found["worlds"]
    if not isinstance(worlds, dict) or sorted(worlds) != sorted(navigation.WORLDS):
        raise ValueError(f"worlds is {short(worlds)}; expected the worlds {', '.join(navigation.WORLDS)}")
    out: dict[str, dict[str, tuple[int, int]]] = {}
    for world in navigation.WORLDS:
        conditions = worlds[world]
        if not isinstance(conditions, dict) or sorted(conditions) != sorted(HAND_CONDITIONS):
            raise ValueError(f"worlds.{world} is {short(conditions)}; expected {' and '.join(HAND_CONDITIONS)}")
        out[world] = {}
        for c in HAND_CONDITIONS:
            counts = conditions[c]
            if not isinstance(counts, dict) or sorted(counts) != ["arrived", "starts"]:
                raise ValueError(f"worlds.{world}.{c} is {short(counts)}; expected arrived and starts")
            n = _count(counts["starts"], f"worlds.{world}.{c}.starts", starts, starts)
            out[world][c] = (_count(counts["arrived"], f"worlds.{world}.{c}.arrived", 0, n), n)
    return out


def world_counts(found: dict[str, Any], world_set: str = "first") -> dict[str, dict[str, int]]:
    """A held-out-worlds result's counts, checked, by place (:func:`world_places` of
    ``world_set``): ``right``
    and ``one answer`` of the champion and the bounds' ``threshold``, ``observer`` and (in a
    held-out world) ``observer, other worlds``, each of ``n``, twice the result's ``trials``. Its
    ``test_seed`` and ``fit_seed`` must be :mod:`~dnnevo.tasks.landmark_transfer`'s (trials of
    other seeds are not pooled with these) and ``fit_trials`` its ``trials``. Raises ValueError,
    KeyError or TypeError otherwise."""
    for key, want in (("test_seed", landmark_transfer.TEST_SEED), ("fit_seed", landmark_transfer.FIT_SEED)):
        if _count(found[key], key) != want:
            raise ValueError(f"{key} is {found[key]}; this dnnevo draws them from {want}")
    trials = _count(found["trials"], "trials", 1)
    _count(found["fit_trials"], "fit_trials", trials, trials)
    worlds = found["worlds"]
    places = world_places(world_set)
    if not isinstance(worlds, dict) or sorted(worlds) != sorted(places):
        raise ValueError(f"worlds is {short(worlds)}; expected the places {', '.join(places)}")
    out: dict[str, dict[str, int]] = {}
    for name in places:
        w = worlds[name]
        keys = ["right", "one answer", "n", "rule", *_BOUNDS[:2 if name == "training" else 3]]
        if not isinstance(w, dict) or sorted(w) != sorted(keys):
            raise ValueError(f"worlds.{name} is {short(w)}; expected {', '.join(keys)}")
        n = _count(w["n"], f"worlds.{name}.n", 2 * trials, 2 * trials)
        out[name] = {k: _count(w[k], f"worlds.{name}.{k}", 0, n) for k in keys if k not in ("n", "rule")}
        out[name]["n"] = n
        if not isinstance(w["rule"], str):
            raise ValueError(f"worlds.{name}.rule is {short(w['rule'])}; expected text")
    return out


def _check_body(job: plan.Job, found: dict[str, Any], settings: Settings) -> None:
    """Every field a report reads is there and of its type."""
    if not float(found["wall_s"]) >= 0.0:
        raise ValueError("wall_s is negative")
    kind = job.spec.kind
    if kind == plan.EVOLVE:
        run = sweep.SeedResult.from_dict(found["run"])
        if run.seed != job.seed:
            raise ValueError(f"it holds seed {run.seed}")
    elif kind == plan.ROBOT_LIKE:
        a = Assessment.from_dict(found["assessment"])
        matrix = a.details["confusion"]
        if len(matrix) != 2 or any(len(row) != 2 for row in matrix) or not all(
                isinstance(x, int) and not isinstance(x, bool) and x >= 0 for row in matrix for x in row):
            raise ValueError("confusion is not a 2 x 2 matrix of counts")
    elif kind == plan.HELD_OUT:
        world_counts(found, job.spec.worlds)
        if found["trials"] != settings.world_trials():
            raise ValueError(f"trials is {found['trials']}; these settings draw {settings.world_trials()}")
    elif kind == plan.HAND_DESIGNED:
        hand_counts(found)
        if found["starts"] != settings.starts():
            raise ValueError(f"starts is {found['starts']}; these settings draw {settings.starts()}")
        if found["seed"] != sweep.eval_seed(job.seed, settings.eval_seed):
            raise ValueError(f"seed is {short(found['seed'])}; job {job.id} draws its starts from "
                             f"{sweep.eval_seed(job.seed, settings.eval_seed)}")
    else:
        for key in ("goal_rate", "classification_rate"):
            _fraction(found[key], key)
        for key in ("goal_interval", "classification_interval"):
            if len([_fraction(x, key) for x in found[key]]) != 2:
                raise ValueError(f"{key} is not an interval")
        by_trial = found["goal_rate_by_trial"]
        if not by_trial["all"] or not all(_fraction(x, "a goal rate") >= 0 for v in by_trial.values() for x in v):
            raise ValueError("goal_rate_by_trial has no rates")
        for key in ("environments", "trials", "seed"):
            if not (isinstance(found[key], int) and found[key] >= 0):
                raise ValueError(f"{key} is not a count")


def run_job(job: plan.Job, root: str | Path, settings: Settings, threads: int | None = None,
            *needed: Any, progress: bool = False) -> dict[str, Any]:
    """Does ``job`` under ``root`` (or returns its stored result) and returns its result.
    ``needed`` are the results of the jobs it needs (unused: passing them makes a scheduler wait
    for them). ``threads`` is the run's worker threads (default: all cores); ``progress`` shows
    an evolution's progress bar. Raises :class:`Stopped` when Ctrl-C or SIGTERM stopped the run."""
    root = Path(root)
    done = read_result(root, job, settings)
    if done is not None:
        return done
    t0 = time.perf_counter()
    body = {plan.EVOLVE: _evolve, plan.ROBOT_LIKE: _robot_like, plan.HELD_OUT: _held_out, plan.SYSTEM: _system,
            plan.HAND_DESIGNED: _hand_designed}[job.spec.kind](
        job, root, settings, threads, progress)
    result = {**_header(job, settings), **body, "wall_s": round(time.perf_counter() - t0, 2),
              "inputs": _inputs(root, job)}
    path = result_path(root, job)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(path, json.dumps(result, indent=1) + "\n")
    return result


def _folder(root: Path, name: str, seed: int) -> Path:
    return root / plan.job_id(name, seed)


def _evolve(job: plan.Job, root: Path, settings: Settings, threads: int | None, progress: bool) -> dict[str, Any]:
    e = job.spec
    config = settings.config(e)
    out = _folder(root, e.name, job.seed)
    seeding = (Seeding(tuple(_folder(root, n, job.seed) for n in e.needs), populations=e.seed_populations,
                       spare=e.spare_neurons) if e.needs else None)
    resume = (out / "checkpoint.json").exists()
    run = sweep.run_seed(config, job.seed, out, threads=threads, force=not resume and out.exists(),
                         eval_seed_base=settings.eval_seed, eval_trials=settings.trials(config.task),
                         dt_check=settings.dt_check, seeding=seeding, resume=resume, progress=progress)
    if run.interrupted:
        raise Stopped(f"{job.id} stopped; its checkpoint is in {out}")
    return {"run": run.to_dict()}


def _robot_like(job: plan.Job, root: Path, settings: Settings, threads: int | None,
                progress: bool) -> dict[str, Any]:
    run = RunDir(_folder(root, job.spec.needs[0], job.seed))
    config, table = run.read_config()
    a = tasks.assess(config, run.read_best(config, table), settings.trials(config.task),
               seed=ROBOT_SEED_BASE + job.seed, robot_like=True)
    return {"assessment": a.to_dict()}


def _held_out(job: plan.Job, root: Path, settings: Settings, threads: int | None,
              progress: bool) -> dict[str, Any]:
    """The champion in the training world and each held-out world, and each world's bounds, on
    the trials ``examples/landmark_transfer.py`` uses: every seed's champion is judged on the
    same trials (:data:`~dnnevo.tasks.landmark_transfer.TEST_SEED`), so its figures are the
    example's and seeds differ by their champions alone. The bounds do not depend on the
    champion; they cost as much again as judging it."""
    run = RunDir(_folder(root, job.spec.needs[0], job.seed))
    config, table = run.read_config()
    net = run.read_best(config, table)
    trials = settings.world_trials()
    names = world_places(job.spec.worlds)
    places = [landmark_transfer.place(p) for p in names]
    right = landmark_transfer.judge(config, net, trials, places)
    bounds = landmark_transfer.bounds(config, net, trials, trials, places)
    worlds = {p: {"right": right[p], "one answer": right[f"{p} one answer"], **bounds[p]} for p in names}
    return {"test_seed": landmark_transfer.TEST_SEED, "fit_seed": landmark_transfer.FIT_SEED, "trials": trials,
            "fit_trials": trials, "worlds": worlds}


def _system(job: plan.Job, root: Path, settings: Settings, threads: int | None, progress: bool) -> dict[str, Any]:
    classifier, far, near = (nav1d.load_part(_folder(root, n, job.seed)) for n in job.spec.needs)
    envs = settings.environments
    report = nav1d.system_assess(classifier, far, near, environments=envs, trials=SYSTEM_TRIALS,
                                 seed=sweep.eval_seed(job.seed, settings.eval_seed), persist_state=True)
    rates = nav1d.goal_rates(report["episodes"])
    # The trials of one environment share the system's state: intervals count environments.
    return {
        "environments": envs, "trials": SYSTEM_TRIALS, "seed": sweep.eval_seed(job.seed, settings.eval_seed),
        "goal_rate": report["goal_rate"],
        "goal_interval": list(stats.wilson(report["goal_rate"] * envs, envs)),
        "classification_rate": report["classification_rate"],
        "classification_interval": list(stats.wilson(report["classification_rate"] * envs, envs)),
        "goal_rate_by_trial": {env: [float(r) for r in v] for env, v in rates.items()},
    }


def _hand_designed(job: plan.Job, root: Path, settings: Settings, threads: int | None,
                   progress: bool) -> dict[str, Any]:
    """The paper's reactive navigation: the shipped hand-designed network in every world, from
    the same fresh starts with and without the detectors (:func:`dnnevo.robots.navigation.hand_designed`)."""
    seed, starts = sweep.eval_seed(job.seed, settings.eval_seed), settings.starts()
    worlds: dict[str, dict[str, dict[str, int]]] = {}
    for world in navigation.WORLDS:
        worlds[world] = {}
        for condition in HAND_CONDITIONS:
            r = navigation.hand_designed(world, starts, seed=seed, detectors=condition == "with",
                                         steps=HAND_STEPS)
            worlds[world][condition] = {"arrived": r["arrived"], "starts": r["starts"]}
    return {"seed": seed, "starts": starts, "steps": HAND_STEPS, "worlds": worlds}
