"""The generation loop: evolve with a built-in task or a Python fitness function, with a run
folder, checkpoints, Ctrl-C/SIGTERM handling and resume.

The loop itself is Python, one call into Rust per generation; all the work of a generation
(decoding, evaluating on all cores, breeding) happens in Rust with the GIL released.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import inspect
import numbers
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core, presets
from dnnevo._checks import nonnegative
from dnnevo.closedloop import named
from dnnevo.closedloop.fitness import ClosedLoop, close_copy
from dnnevo.closedloop.source import fingerprint, plain_source, task_source
from dnnevo.config import PYTHON_TASK, EvolutionConfig
from dnnevo.errors import ConfigError, DnnevoError, FitnessError, InvalidArgumentError, did_you_mean
from dnnevo.evolution.ga import GeneticAlgorithm, Validate, founders_argument
from dnnevo.evolution.progress import Progress
from dnnevo.runs import RunDir, RunFileError, first_difference, short

__all__ = ["EvolutionResult", "evaluate", "evolve", "resume"]

# Called as fitness(networks), or fitness(networks, *, generation, seed) when it takes those keywords.
FitnessFn = Callable[..., npt.ArrayLike]
Callback = Callable[[dict[str, float], GeneticAlgorithm], Any]

#: Seconds between two checkpoints (one is also written at the end and on interruption).
CHECKPOINT_SECONDS = 10.0
#: Seconds between two rewrites of log.csv (it is also rewritten with every checkpoint).
LOG_SECONDS = 1.0
#: Mixed into the run's seed for the fresh conditions of the champion's success checks.
SUCCESS_SEED_SALT = 0x5EED_C0DE


@dataclass(frozen=True)
class EvolutionResult:
    """What a run produced."""

    best: _core.Network
    """The champion: the best network of the run by validation (see
    ``EvolutionConfig.validation_candidates``), or by training fitness when the task has no
    validation set (in its initial state), with the ``meta`` and ``integrator`` that
    ``best.json`` holds: ``best.run(inputs, **best.integrator,
    precision=best.meta["precision"])`` runs it as the run did."""
    best_fitness: float
    """The champion's training fitness."""
    best_generation: int
    history: dict[str, npt.NDArray[np.float64]]
    """Per-generation arrays: generation, best, mean, std, min, champion_success,
    validation_rate, validation_score, evals_per_s, elapsed_s."""
    config: EvolutionConfig
    seed: int
    run_dir: Path | None
    interrupted: bool = False
    """True when Ctrl-C or SIGTERM stopped the run before its last generation: ``evolve``
    returns the champion so far rather than raising, and ``dnnevo.resume(run_dir)`` continues
    the run. A script that needs the whole run checks this."""
    best_validation: tuple[float, float] | None = None
    """The champion's validation ``(rate, score)``, or None when it was chosen by training
    fitness."""

    @property
    def first_success(self) -> int | None:
        """The first generation whose champion met the task's success criterion, if any."""
        hits = np.flatnonzero(self.history.get("champion_success", np.array([])) == 1.0)
        return int(self.history["generation"][hits[0]]) if len(hits) else None


def evaluate(
    task: str,
    genomes: npt.ArrayLike | Sequence[_core.Network],
    *,
    generation: int,
    seed: int,
    config: EvolutionConfig | None = None,
    threads: int | None = None,
) -> npt.NDArray[np.float64]:
    """Scores genomes (P, G) or networks with a built-in task or a preset: a pure function of
    (task config, genomes, generation, seed), bit-identical to the scores inside :func:`evolve`.
    A preset of a task written in Python (``legged-walker``, ``double-pole``, ...) is scored by
    its :class:`~dnnevo.closedloop.ClosedLoop` fitness; ``threads`` does not apply to it."""
    config = _task_config(task, config)
    if named.is_python_task(config.task):
        if isinstance(genomes, Sequence) and all(isinstance(g, _core.Network) for g in genomes):
            networks = list(genomes)
        else:
            try:
                rows = np.asarray(genomes, dtype=np.float64)
            except (TypeError, ValueError) as e:
                raise InvalidArgumentError(f"genomes must be an array (P, G) or a list of networks: {e}") from None
            if rows.ndim != 2:
                raise InvalidArgumentError(f"genomes must be an array (P, G) or a list of networks; got shape {rows.shape}")
            networks = [_core.Network.from_genome(row, size=config.size, n_inputs=config.n_inputs) for row in rows]
        return named.closed_loop(config)(networks, generation=generation, seed=seed)
    return _core.evaluate(
        config.native,
        genomes,
        generation=generation,
        seed=seed,
        threads=threads,
    )


def _numbers(scores: Any) -> npt.NDArray[np.float64]:
    """A fitness function's return as float64, or a :class:`~dnnevo.FitnessError` when it holds
    anything but numbers (strings, even of numbers, None, objects)."""
    try:
        given = np.asarray(scores)
    except (TypeError, ValueError) as e:
        raise FitnessError(f"the fitness function returned values that are not numbers ({e})") from None
    numeric = given.dtype.kind in "biuf" or (
        given.dtype.kind == "O" and all(isinstance(v, numbers.Real) for v in given.ravel()))
    if not numeric:  # strings (even of numbers), None, other objects
        raise FitnessError(f"the fitness function returned values that are not numbers (of type "
                           f"{given.dtype}); return one number per network")
    return given.astype(np.float64)


def _check_task(task: object) -> None:
    """A :class:`~dnnevo.ConfigError` unless ``task`` is a name or a callable; it names an
    environment passed without its :class:`~dnnevo.closedloop.ClosedLoop`."""
    environment = all(callable(getattr(task, m, None)) for m in ("reset", "step"))
    if inspect.isclass(task) and environment:
        raise ConfigError(f"task is the class {task.__name__}; an environment is given as an object "
                          f"wrapped in a ClosedLoop: ClosedLoop({task.__name__}(...), max_steps=...)")
    if isinstance(task, str) or callable(task):
        return
    kind = type(task).__name__
    raise ConfigError(
        f"task has type {kind}; expected a task or preset name, a fitness function "
        "fitness(networks) -> array, or a ClosedLoop"
        + (f" ({kind} looks like an environment: wrap it, ClosedLoop({kind}(...), max_steps=...))"
           if environment else ""))


def _task_config(task: str, config: EvolutionConfig | None) -> EvolutionConfig:
    """The config for a built-in task name or preset name."""
    if task not in presets.names() and task not in _core.task_names():
        known = [*_core.task_names(), *presets.names()]
        raise ConfigError(
            f"unknown task {task!r}{did_you_mean(task, known)}; built-in tasks: "
            f"{', '.join(_core.task_names())}; presets: {', '.join(presets.names())}"
        )
    if config is not None:
        named = presets.get(task).task if task in presets.names() else task
        if named != config.task:
            raise ConfigError(f"task {task!r} does not match config.task {config.task!r}")
        return config
    if task in presets.names():
        return presets.get(task)
    return EvolutionConfig(task=task)


def evolve(
    task: str | FitnessFn,
    config: EvolutionConfig | None = None,
    *,
    seed: int = 0,
    out: str | Path | None = None,
    progress: bool = True,
    callback: Callback | None = None,
    threads: int | None = None,
    founders: Sequence[_core.Network] | None = None,
    force: bool = False,
    run_info: Mapping[str, Any] | None = None,
    seeds: Sequence[_core.Network] | None = None,
) -> EvolutionResult:
    """Evolves networks for ``task`` and returns the champion and the history.

    ``task`` is a built-in task or preset name, a task class's name (``"python:module.Class"``,
    whose config without ``config`` is the class's own ``preset`` over the defaults), or a
    Python callable ``fitness(networks) -> array`` (slower, but works with everything else,
    checkpoints included). A callable that
    takes ``generation`` and ``seed`` keywords gets them, to draw each generation's conditions
    from (see :class:`dnnevo.closedloop.ClosedLoop` for a task in closed loop); one with a
    method ``validate(networks, *, seed) -> (rates, scores)`` has its champion chosen on that
    validation set, as a built-in task has (``config.validation_candidates``). With ``out`` the run
    writes a run folder (see :mod:`dnnevo.runs.rundir`); an existing non-empty folder is refused unless
    ``force``. ``callback(stats, ga)`` runs after every generation; returning True stops the run.
    ``founders`` are networks placed first in the initial population (e.g. from :func:`compose`;
    ``seeds``, its old name, is deprecated). ``run_info`` adds entries to the ``[run]`` table of
    ``config.toml``, e.g. where the founders came from.

    ``threads`` (default: every core) sizes a built-in task's own thread pool. A task written in
    Python steps its networks on the process's shared pool, which takes a size only before its
    first use: the first call sizes it for the whole process (later calls, ``run_population`` and
    ``Batch`` included), and a later ``threads`` that differs is said on stderr and does not apply.
    """
    _check_task(task)
    named_task = isinstance(task, str)  # a task built from its name is built so again
    if isinstance(task, str) and task in presets.names() and named.is_python_task(presets.get(task).task):
        config = _task_config(task, config)  # a preset of a task written in Python
        task = config.task
    if isinstance(task, str) and named.is_python_task(task):
        # Without a config, the class's own preset, as the command line starts from.
        config = dataclasses.replace(config, task=task) if config is not None else presets.get(task)
        task = named.closed_loop(config)  # imports the task's module, checks it, builds it
    elif isinstance(task, ClosedLoop):
        config = task.configured(config or EvolutionConfig())
    elif callable(task):
        config = dataclasses.replace(config or EvolutionConfig(), task=_python_task_name(task))
        if config.precision != "f64":
            raise ConfigError(
                f"precision is {config.precision!r}, but a fitness function integrates its networks "
                "itself: leave precision at 'f64' and compute in f32 inside it (Network.run or "
                "Batch with precision='f32'), or wrap an environment in ClosedLoop(..., "
                "precision='f32')")
    else:
        config = _task_config(task, config)
        _check_layout(config)
        task = config.task  # a preset name stands for its config's task
    _share_threads(task, threads)
    refuse_idle_scale(config)
    ga = GeneticAlgorithm(config, seed=seed, founders=founders_argument(founders, seeds))
    if out is None:
        return _loop(ga, task, [], None, progress=progress, callback=callback, threads=threads)
    run = RunDir(out)
    run.refuse_unless_new(force=force)  # a refused folder is left as it was, lock file included
    table = {**_run_table(seed), **(run_info or {})}
    if callable(task) and (digest := _fitness_digest(task)) is not None:
        table["fitness_sha256"] = digest
    if isinstance(task, ClosedLoop):
        table["fitness_parts"] = task.part_digests()
        if not named_task and (why := _not_rebuilt(task, config)) is not None:
            print(f"dnnevo: note: the command line will not judge, draw or resume {out} ({why}); "
                  "do so from Python with this environment (docs/closed-loop.md)", file=sys.stderr)
    with run.writing(create=True):
        run.create(force=force)
        # The checkpoint first: from here on the folder can be resumed.
        run.write_checkpoint(ga.state_dict(), [], table, ga.seed)
        run.write_config(config, table)
        run.write_log([])
        return _loop(ga, task, [], run, progress=progress, callback=callback, threads=threads,
                     table=table, resume_hint=lambda: _resume_hint(task, config, run, named=named_task))


def resume(
    run_dir: str | Path,
    task: FitnessFn | None = None,
    *,
    progress: bool = True,
    callback: Callback | None = None,
    threads: int | None = None,
    generations: int | None = None,
    new_fitness: bool = False,
) -> EvolutionResult:
    """Continues a stopped run from its checkpoint; the result is identical to a run that was
    never stopped. A run with a Python fitness function needs it passed again as ``task``.

    Every file of the folder is checked first: config.toml, the checkpoint's config (against
    the digest it carries) and the GA state must agree, or a :class:`DnnevoError` names the
    first field that differs. ``generations`` extends (or shortens, down to the generations
    already done) the run; config.toml and the checkpoint are rewritten to say so. A ``task``
    other than the run's own fitness function is refused unless ``new_fitness``, which records
    the change in the ``[run]`` table of config.toml and of the checkpoint. A folder whose run
    stopped before its first checkpoint is started from its config.toml. Temporary files left
    by a killed write are removed, and a successful resume leaves best.json, log.csv, config.toml
    and the checkpoint in agreement.
    """
    if task is not None:
        _check_task(task)
    run = RunDir(run_dir)
    with run.writing(create=False):
        run.remove_stale()
        if not run.checkpoint.exists() and not run.checkpoint.is_symlink():
            ga, history, table = _restart(run)
        else:
            ga, history, table = _restored(run)
        if generations is not None:
            nonnegative("generations", generations)
            if generations < max(ga.generation, 1):
                raise ConfigError(f"generations is {generations}; the run has done {ga.generation}")
            ga.config = dataclasses.replace(ga.config, generations=generations)
        elif ga.generation > ga.config.generations:
            raise RunFileError(f"{run.checkpoint}: generation {ga.generation} is beyond the run's "
                               f"{ga.config.generations} generations")
        # What is damaged, judged by the run's own settings, before a new task may change them.
        repairs = _repairs(run, ga)
        fitness: str | FitnessFn = ga.config.task
        if isinstance(task, str) and named.is_python_task(task):
            if task != ga.config.task:
                raise ConfigError(f"{run.path} was evolved with {ga.config.task}, not {task}")
            fitness = _named_fitness(run, ga.config, table)
        elif task is not None:
            if isinstance(task, ClosedLoop) and task.settings["precision"] != ga.config.precision:
                raise ConfigError(f"{run.path} computes in {ga.config.precision}, not "
                                  f"{task.settings['precision']}; give ClosedLoop(..., "
                                  f"precision={ga.config.precision!r})")
            fitness = task
            name = task if isinstance(task, str) else _python_task_name(task)
            digests = () if isinstance(task, str) else _fitness_digests(task)
            digest = digests[0] if digests else None
            # Same name, other source: a different function all the same.
            edited = digest is not None and table.get("fitness_sha256", digest) not in digests
            if not edited and _moved(task, name, ga.config.task, digests, table):
                name = ga.config.task  # the same source, imported from another module
            if name != ga.config.task or edited:
                if not new_fitness:
                    raise ConfigError(f"{run.path} was evolved with {ga.config.task}, not "
                                      f"{_other_task(task, name, table) if edited and name == ga.config.task else name}"
                                      "; pass new_fitness=True to continue it with another fitness function")
                change: dict[str, Any] = {"generation": ga.generation, "task": name}
                evolved_with = ga.config.task
                table = {k: v for k, v in table.items() if k != "fitness_parts"}
                if isinstance(task, ClosedLoop):
                    # config.toml says what the task is from here on, so that a command can build
                    # it again (its digest is the new one)
                    ga.config = task.configured(ga.config)
                    change["task_params"] = dict(ga.config.task_params)
                    table["fitness_parts"] = task.part_digests()
                table["fitness_changes"] = [*table.get("fitness_changes", []), change]
                if digest is not None:
                    table["fitness_sha256"] = digest
                print(f"{run.path}: continuing at generation {ga.generation} with {name} "
                      f"(the run was evolved with {evolved_with}); recorded in config.toml",
                      file=sys.stderr)
        elif named.is_closed_loop(ga.config):
            fitness = _named_fitness(run, ga.config, table)
        elif named.is_python_task(ga.config.task):
            raise DnnevoError(
                f"{run.path} was evolved with a Python fitness function ({ga.config.task}); resume it "
                "from Python: dnnevo.resume(dir, task=fitness)")
        # Every file rewritten from the state about to continue, so they agree from here on;
        # one that was damaged or gone is said, as it is repaired.
        _share_threads(fitness, threads)
        try:
            ahead = run.logged_generations() - len(history)
        except DnnevoError:  # an unreadable log is repaired below
            ahead = 0
        if ahead > 0:  # a kill between two checkpoints: said, since the bar starts further back
            print(f"{run.path}: continuing from its checkpoint at generation {len(history)}; the "
                  f"{ahead} generation{'s' * (ahead != 1)} log.csv has after it run again",
                  file=sys.stderr)
        for note in repairs:
            print(f"{run.path}: {note}; written again from checkpoint.json", file=sys.stderr)
        run.write_checkpoint(ga.state_dict(), history, table, ga.seed)
        run.write_config(ga.config, table)
        run.write_log(history)
        _write_best(run, ga)
        return _loop(ga, fitness, history, run, progress=progress, callback=callback,
                     threads=threads, table=table,
                     resume_hint=lambda: _resume_hint(fitness, ga.config, run,
                                                      named=task is None or isinstance(task, str)))


def refuse_idle_scale(config: EvolutionConfig) -> None:
    """Refuses a new run whose ``mutation_scale`` would do nothing: uniform mutation redraws a
    gene and has no step to scale. (A run folder that recorded one, from before this check, is
    still read and resumed: the scale never acted on it.)"""
    if config.mutation == "uniform" and config.mutation_scale != EvolutionConfig.mutation_scale:
        raise ConfigError(f"mutation_scale is {config.mutation_scale}, but mutation is \"uniform\", which "
                          "redraws a gene and has no step to scale; set mutation = \"creep\" to use it")


def _share_threads(task: str | FitnessFn, threads: int | None) -> None:
    """``threads`` for a task written in Python, which steps its networks (``Batch``, robot
    fleets) on the process's shared thread pool: the pool is sized to it, which takes only before
    its first use; said on stderr when it is running with another size already. (A built-in task
    runs on a pool of its own of that size.)"""
    if threads is None or not callable(task):
        return
    running = _core.process_threads(threads)
    if running != threads:
        print(f"dnnevo: note: threads={threads} does not reach this Python task: the process's "
              f"thread pool started earlier, with {running} (set RAYON_NUM_THREADS={threads} "
              "before the process starts)", file=sys.stderr)


def _other_task(task: FitnessFn, name: str, table: Mapping[str, Any]) -> str:
    """What differs in ``task``, called ``name`` as the run's own task is but with another digest:
    an edited function, or for an environment the parts that differ (source, attributes or
    settings), when the run recorded its parts."""
    parts = table.get("fitness_parts")
    if not isinstance(task, ClosedLoop):
        return f"an edited {name}"
    if isinstance(parts, Mapping) and parts.get("source") == task.part_digests()["source"]:
        return f"{name} as made here ({named.what_differs(task, parts)})"
    return f"an edited {name} ({named.what_differs(task, parts)})"


def _resume_hint(task: str | FitnessFn, config: EvolutionConfig, run: RunDir, *, named: bool) -> str:
    """How to resume ``run`` after an interrupt: with ``dnnevo resume`` when the command builds
    its task again from config.toml (a task ``named`` by its name, or an environment one made from
    config.toml would equal), else from Python with the same task."""
    script = config.task.startswith(f"{PYTHON_TASK}__main__.")  # no other process imports it
    if not script and (named or isinstance(task, str)
                       or (isinstance(task, ClosedLoop) and _not_rebuilt(task, config) is None)):
        return f"dnnevo resume {run.path}"
    same = "environment (in ClosedLoop)" if isinstance(task, ClosedLoop) else "fitness function"
    return f"dnnevo.resume({str(run.path)!r}, task=...) from Python, with the same {same}"


def _not_rebuilt(task: ClosedLoop, config: EvolutionConfig) -> str | None:
    """Why a command that builds ``task`` from ``config`` (as ``dnnevo assess`` does) would not get
    this very task, or None when it would (or when the class is a script's, which says so itself)."""
    if task.__module__ == "__main__":
        return None
    try:
        again = named.closed_loop(config)
    except DnnevoError as e:
        return str(e)
    mine, theirs = getattr(task.env, "__dict__", {}), getattr(again.env, "__dict__", {})
    differ = sorted(k for k in set(mine) | set(theirs)
                    if k not in mine or k not in theirs or fingerprint(mine[k]) != fingerprint(theirs[k]))
    close_copy(again.env)
    if again.digest() == task.digest():
        return None
    kind = type(task.env).__name__
    record = ("keep each argument of __init__ as an attribute of the same name, holding a Python "
              "number, string or boolean, or a list or dict of them")
    if not differ:
        return f"config.toml cannot record the arguments this {kind} was made with: {record}"
    return (f"this {kind}'s attributes {', '.join(differ)} differ from those of one made from "
            f"config.toml: either an argument that config.toml cannot record ({record}), or "
            "attributes set after __init__, as an earlier reset or rollout sets them (give "
            "ClosedLoop a freshly made environment)")


def _named_fitness(run: RunDir, config: EvolutionConfig, table: Mapping[str, Any]) -> FitnessFn:
    """The task class a run's config names, built from the config (importing its module), when
    its digest is the run's own."""
    try:
        return named.closed_loop(config, digest=table.get("fitness_sha256"), parts=table.get("fitness_parts"))
    except ConfigError as e:
        raise ConfigError(f"{run.path}: {e}; resume it from Python with the environment it began "
                          "with, or with new_fitness=True") from None


def _moved(task: FitnessFn, name: str, recorded: str, digests: tuple[str, ...],
           table: Mapping[str, Any]) -> bool:
    """Whether a fitness function named ``name`` is the run's own (``recorded``) under another
    name: the same source digest, and either the same environment class (a task class reached
    through another module) or one of the two names a script's (``__main__``) with the same
    qualified name after the module. A run started by ``python light.py`` then resumes from a
    script that does ``from light import ...``."""
    if table.get("fitness_sha256") not in digests:
        return False
    if not (name.startswith(PYTHON_TASK) and recorded.startswith(PYTHON_TASK)):
        return False
    if isinstance(task, ClosedLoop):
        try:
            return named.environment_class(recorded) is type(task.env)
        except ConfigError:
            pass
    main = f"{PYTHON_TASK}__main__."
    mine, theirs = name.removeprefix(main), recorded.removeprefix(main)
    one_is_main = (mine != name) != (theirs != recorded)
    return one_is_main and (mine.endswith("." + theirs) or theirs.endswith("." + mine))


def _python_task_name(task: FitnessFn) -> str:
    name = getattr(task, "__qualname__", type(task).__qualname__)
    module = getattr(task, "__module__", None) or "?"
    return f"{PYTHON_TASK}{module}.{name}"


def _restart(run: RunDir) -> tuple[GeneticAlgorithm, list[dict[str, float]], dict[str, Any]]:
    """A folder with a config.toml and no checkpoint: its run stopped before its first
    checkpoint, so it starts again from generation 0 (identical to a run never stopped)."""
    if not run.config.exists():
        if (hint := run.sweep_hint()) is not None:
            raise RunFileError(f"{run.path} has no checkpoint.json and no config.toml; {hint}")
        raise RunFileError(f"{run.path} has no checkpoint.json and no config.toml; nothing to resume "
                           "(start the run again)")
    done = run.logged_generations()
    if done or run.best.exists():
        raise RunFileError(f"{run.path} has no checkpoint.json, but {run.log.name} records {done} generation"
                           f"{'s' if done != 1 else ''}{' and best.json a champion' if run.best.exists() else ''}: "
                           "resuming would start again from generation 0 and lose them; restore "
                           "checkpoint.json, or start the run again (dnnevo run --force)")
    config, table = run.read_config()
    if "seed" not in table:
        raise RunFileError(f"{run.config}: has no [run] table with the run's seed")
    if "seeded_from" in table:
        raise RunFileError(f"{run.path} stopped before its first checkpoint and was seeded from other "
                           "runs; start it again with --force")
    if not named.is_python_task(config.task):
        _check_layout(config)
    return GeneticAlgorithm(config, seed=table["seed"]), [], table


def _restored(run: RunDir) -> tuple[GeneticAlgorithm, list[dict[str, float]], dict[str, Any]]:
    """The checkpoint's GA and history, checked against each other and against config.toml."""
    cp = run.read_checkpoint()
    try:
        ga = GeneticAlgorithm.from_state_dict(cp.state)
    except DnnevoError as e:
        raise RunFileError(f"{run.checkpoint}: state.evolution: {e}") from None
    where = run.checkpoint
    if len(cp.history) != ga.generation:
        raise RunFileError(f"{where}: the history has {len(cp.history)} generations; the GA state "
                           f"is at generation {ga.generation}")
    table = dict(cp.run) if cp.run is not None else _run_table(ga.seed)
    if table["seed"] != ga.seed:
        raise RunFileError(f"{where}: run.seed is {table['seed']}; the GA state's seed is {ga.seed}")
    if run.config.exists() or run.config.is_symlink():
        config, toml_table = run.read_config()
        diff = first_difference(config.to_dict(), ga.config.to_dict())
        if diff is None and toml_table.get("seed") != ga.seed:
            diff = ("run.seed", toml_table.get("seed", "(missing)"), ga.seed)
        if diff is not None:
            raise RunFileError(
                f"{run.config} disagrees with checkpoint.json at {diff[0]}: {short(diff[1])} in "
                f"config.toml, {short(diff[2])} in the checkpoint (to run longer, use "
                f"'dnnevo resume {run.path} --generations N')")
        if cp.run is None:
            table = toml_table
    return ga, cp.history, table


def _repairs(run: RunDir, ga: GeneticAlgorithm) -> list[str]:
    """What is wrong with a resumed folder's files besides its checkpoint, which resume then
    writes again from it: a file gone, or one its reader refuses. (A log.csv ahead of the
    checkpoint, as a kill leaves it, is not damage.)"""
    notes = []
    if not run.config.exists():
        notes.append("config.toml was gone")
    # log.csv's rows may outnumber the checkpoint's generations; that is no damage
    for path, read, expected in ((run.log, run.read_log, ga.generation > 0),
                                 (run.best, lambda: run.read_best(ga.config), ga.best is not None)):
        if not path.exists():
            if expected:
                notes.append(f"{path.name} was gone")
            continue
        if path == run.log and not expected:  # nothing logged yet
            continue
        try:
            read()
        except DnnevoError as e:
            notes.append(f"{path.name} was damaged ({str(e).removeprefix(str(path) + ': ')})")
    return notes


def _takes_conditions(task: FitnessFn) -> bool:
    """Whether a fitness function takes the generation and the run's seed as keywords, to draw
    its conditions from (``fitness(networks, *, generation, seed)``)."""
    try:
        params = inspect.signature(task).parameters
    except (TypeError, ValueError):
        return False
    keyword = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    named = all(k in params and params[k].kind in keyword for k in ("generation", "seed"))
    return named or any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())


def _validation(task: str | FitnessFn, ga: GeneticAlgorithm) -> Validate | None:
    """A fitness function's own validation, when it has one (a method ``validate(networks, *,
    seed) -> (rates, scores)``, as :class:`~dnnevo.closedloop.ClosedLoop` has) and the config
    asks for candidates; the GA then chooses the champion by it (see
    :meth:`GeneticAlgorithm.tell`)."""
    method = getattr(task, "validate", None)
    if not callable(task) or not callable(method) or ga.config.validation_candidates == 0:
        return None
    seed = ga.seed
    return lambda networks: method(networks, seed=seed)


def _fitness_digest(task: FitnessFn) -> str | None:
    """SHA-256 of a Python fitness function's source and of what it reads from its module
    (:mod:`dnnevo.closedloop.source`), so that resume can tell an edited function from the run's
    own; None when Python cannot find the source (e.g. typed at a prompt). A callable object can
    say what identifies it in a ``fitness_source`` text (as :class:`dnnevo.closedloop.ClosedLoop`
    does: its environment's source and settings)."""
    digests = _fitness_digests(task)
    return digests[0] if digests else None


def _fitness_digests(task: FitnessFn) -> tuple[str, ...]:
    """Every digest a run of ``task`` may record: :func:`_fitness_digest`'s, then the ones of
    runs made before digests left out comments and layout, and before they took in what the
    function reads from its module; none when Python cannot find the source."""
    if callable(own := getattr(task, "digests", None)):
        return tuple(own())
    if isinstance(given := getattr(task, "fitness_source", None), str):
        return (hashlib.sha256(given.encode()).hexdigest(),)
    target = task if inspect.isfunction(task) or inspect.ismethod(task) else type(task)
    target = getattr(target, "__func__", target)
    texts = (task_source(target), task_source(target, raw=True), plain_source(target))
    return tuple(hashlib.sha256(t.encode()).hexdigest() for t in texts if t is not None)


def _run_table(seed: int) -> dict[str, Any]:
    return {"seed": seed, "dnnevo_version": _core.__version__}


def _check_layout(config: EvolutionConfig) -> None:
    names = _core.task_names()
    if config.task not in names:
        raise ConfigError(f"unknown task {config.task!r}{did_you_mean(config.task, names)}; "
                          f"built-in tasks: {', '.join(names)}")
    size, n_inputs = config.native.builtin().layout
    if (size, n_inputs) != (config.size, config.n_inputs):
        raise ConfigError(
            f"the {config.task} task drives networks with {n_inputs} inputs; "
            f"the config has size = {config.size}, n_inputs = {config.n_inputs}"
        )


class _StopRequest:
    """Ctrl-C and SIGTERM ask the loop to stop after the generation in progress; a second
    signal stops at once."""

    def __init__(self) -> None:
        self.requested = False

    def __call__(self, signum: int, frame: Any) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    @contextlib.contextmanager
    def installed(self) -> Iterator[_StopRequest]:
        """Installs the handler for SIGINT and SIGTERM (main thread only)."""
        if threading.current_thread() is not threading.main_thread():
            yield self
            return
        old = {sig: signal.signal(sig, self) for sig in (signal.SIGINT, signal.SIGTERM)}
        try:
            yield self
        finally:
            for sig, handler in old.items():
                signal.signal(sig, handler)


def _loop(
    ga: GeneticAlgorithm,
    task: str | FitnessFn,
    history: list[dict[str, float]],
    run: RunDir | None,
    *,
    progress: bool,
    callback: Callback | None,
    threads: int | None,
    table: Mapping[str, Any] | None = None,
    resume_hint: Callable[[], str] = lambda: "",
) -> EvolutionResult:
    config = ga.config
    bar = Progress(config.generations, start=ga.generation) if progress else None
    t_start = time.perf_counter() - (history[-1]["elapsed_s"] if history else 0.0)
    last_checkpoint = last_log = time.perf_counter()
    seen = _champion_key(ga)
    success = history[-1]["champion_success"] if history else float("nan")
    interrupted = False
    saved = ""
    conditions = callable(task) and _takes_conditions(task)
    validate = _validation(task, ga)

    checkpointed = len(history)  # the generations the folder's checkpoint holds

    def save_state() -> None:
        nonlocal checkpointed
        if run is not None:
            run.write_log(history)
            run.write_checkpoint(ga.state_dict(), history, table or _run_table(ga.seed), ga.seed)
            _write_best(run, ga)
            checkpointed = len(history)

    try:
        with _StopRequest().installed() as stop:
            while ga.generation < config.generations and not stop.requested:
                t0 = time.perf_counter()
                if callable(task):
                    networks = ga.ask().networks
                    if conditions:
                        scores = task(networks, generation=ga.generation, seed=ga.seed)
                    else:
                        scores = task(networks)
                    fitness = _numbers(scores)
                    if fitness.shape != (config.population,):
                        raise FitnessError(
                            f"the fitness function returned shape {fitness.shape}; "
                            f"expected ({config.population},)"
                        )
                    stats = ga.tell(fitness, validate=validate)
                else:
                    stats = ga.step(threads=threads).stats
                seconds = time.perf_counter() - t0
                validation = ga.best_validation or (float("nan"), float("nan"))
                if _champion_key(ga) != seen:
                    seen = _champion_key(ga)
                    success = _champion_success(ga, task)
                    if run is not None:
                        _write_best(run, ga)
                history.append({
                    "generation": float(stats["generation"]),
                    "best": stats["best"],
                    "mean": stats["mean"],
                    "std": stats["std"],
                    "min": stats["min"],
                    "champion_success": success,
                    "validation_rate": validation[0],
                    "validation_score": validation[1],
                    "evals_per_s": config.population / seconds if seconds > 0 else 0.0,
                    "elapsed_s": time.perf_counter() - t_start,
                })
                now = time.perf_counter()
                if run is not None and now - last_checkpoint >= CHECKPOINT_SECONDS:
                    save_state()
                    last_checkpoint = last_log = now
                elif run is not None and now - last_log >= LOG_SECONDS:
                    run.write_log(history)
                    last_log = now
                if bar is not None:
                    row = history[-1]
                    # A task class without a success rule gives every network the rate 0 and
                    # chooses by the score (ClosedLoop.has_success_rule; other fitness objects
                    # that validate are taken to have a rate).
                    validated = ga.best_validation is not None
                    ruled = validated and getattr(task, "has_success_rule", True)
                    bar.update(int(row["generation"]), row["best"], row["mean"], row["evals_per_s"],
                               champion=ga.best_fitness,
                               validation_rate=validation[0] if ruled else None,
                               validation_score=validation[1] if validated and not ruled else None)
                if callback is not None and callback(stats, ga) is True:
                    break
            interrupted = stop.requested
            save_state()
            saved = f"at generation {ga.generation}; checkpoint saved"
    except KeyboardInterrupt:
        # A second signal, or an interrupt outside the loop's own handler: keep the checkpoint
        # only if the history still matches the population.
        interrupted = True
        if len(history) == ga.generation:
            save_state()
            saved = f"at generation {ga.generation}; checkpoint saved"
        else:
            lost = ga.generation - checkpointed  # its tell may have come before the history's row
            saved = (f"mid-generation; the checkpoint of generation {checkpointed} is kept, and the "
                     f"{lost} generation{'s' if lost != 1 else ''} since will be run again")
            if run is not None:  # the log says what the checkpoint holds, as resume will
                run.write_log(history[:checkpointed])
        if run is None:
            raise
    except Exception as e:
        # The task (or a callback) failed: the folder keeps every generation finished before,
        # when the history still matches the population, so that show and resume start there.
        # (Not after a failed write, which would fail again.)
        if run is not None and len(history) == ga.generation and not isinstance(e, OSError):
            save_state()
        raise
    finally:
        if bar is not None:
            bar.close()
    # Made only now: it may build the task's environment again, to tell whether the command can.
    hint = f"interrupted {saved}. Resume with: {resume_hint()}" if run is not None and interrupted else ""
    if interrupted and ga.best is None:
        # Stopped before any generation was scored: there is no result to return.
        raise KeyboardInterrupt(hint)
    if interrupted and run is not None:
        print(hint, file=sys.stderr)
    return _result(ga, history, run, interrupted)


def _champion_key(ga: GeneticAlgorithm) -> tuple[Any, ...] | None:
    """What identifies the champion: a new one has another generation, fitness or validation."""
    return (ga.best_fitness, ga.best_generation, ga.best_validation)


def _champion_success(ga: GeneticAlgorithm, task: str | FitnessFn) -> float:
    """1.0 or 0.0 when the task has a success rule (a built-in task, or a task class with one),
    else NaN."""
    seed = (ga.seed ^ SUCCESS_SEED_SALT) & 0xFFFF_FFFF_FFFF_FFFF
    if isinstance(task, ClosedLoop):
        assert ga.best is not None, "a champion has just been found"
        return task.succeeds(ga.best, seed)
    if callable(task):
        return float("nan")
    verdict = ga.best_succeeds(seed)
    return float("nan") if verdict is None else float(verdict)


def _write_best(run: RunDir, ga: GeneticAlgorithm) -> None:
    """Writes the champion as best.json; before the first generation there is none."""
    net = ga.best
    if net is None:
        run.best.unlink(missing_ok=True)
        return
    net.save(run.best, **_champion_notes(ga))


def _champion_notes(ga: GeneticAlgorithm) -> dict[str, dict[str, Any]]:
    """The champion's ``meta`` (task, seed, generation, fitness, validation, precision) and its
    ``integrator``, as ``best.json`` holds them and :attr:`EvolutionResult.best` carries them."""
    meta: dict[str, Any] = {
        "task": ga.config.task,
        "seed": ga.seed,
        "generation": ga.best_generation,
        "fitness": ga.best_fitness,
        "dnnevo_version": _core.__version__,
    }
    if ga.best_validation is not None:
        meta["validation_rate"], meta["validation_score"] = ga.best_validation
    # How the run integrated it, so that the file alone says how to run the champion.
    meta["precision"] = ga.config.precision
    return {"meta": meta, "integrator": dataclasses.asdict(ga.config.integrator)}


def _result(
    ga: GeneticAlgorithm, history: list[dict[str, float]], run: RunDir | None, interrupted: bool
) -> EvolutionResult:
    net, fitness, generation = ga.best, ga.best_fitness, ga.best_generation
    if net is None or fitness is None or generation is None:
        raise FitnessError("no generation was scored, so there is no champion")
    columns = history[0].keys() if history else ()
    arrays = {k: np.array([row[k] for row in history]) for k in columns}
    return EvolutionResult(
        best=_core.Network.from_dict({**net.to_dict(), **_champion_notes(ga)}),
        best_fitness=fitness,
        best_generation=generation,
        history=arrays,
        config=ga.config,
        seed=ga.seed,
        run_dir=run.path if run else None,
        interrupted=interrupted,
        best_validation=ga.best_validation,
    )
