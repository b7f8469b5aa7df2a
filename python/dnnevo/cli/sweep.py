"""The ``dnnevo sweep`` command: independent runs over seeds, each final champion judged on fresh
conditions, and the statistics of :mod:`dnnevo.experiments.sweep` printed and written to ``summary.csv`` and
``summary.json``."""

from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
from pathlib import Path
from typing import Any

from dnnevo import presets
from dnnevo.closedloop import named
from dnnevo.experiments import scheduler
from dnnevo.evolution import seeding
from dnnevo.evolution.evolve import refuse_idle_scale
from dnnevo.experiments import sweep
from dnnevo._checks import nonnegative
from dnnevo.closedloop.fitness import success_rule
from dnnevo.tasks import DEFAULT_TRIALS, registry
from dnnevo.config import EvolutionConfig, with_later_defaults
from dnnevo.errors import ConfigError, DnnevoError
from dnnevo.runs import LOCK_NAME, RunDir, RunFileError, check_settings, first_difference, write_atomic
from dnnevo.runs.files import checked, read_json, remove_temporaries
from dnnevo.experiments.runsview import RunsView

SETTINGS_FILE = "sweep.json"
"""The settings a sweep folder was begun with, so that running the command again continues it."""

EXAMPLE = """examples:
  dnnevo sweep sequence-1bit --quick --seeds 0-4 --out runs/sweep
  dnnevo sweep sequence-1bit --quick --seeds 0-4 --out runs/sweep --set generations=16   # extend it
  dnnevo sweep landmark --seeds 0-9 --out runs/sweep-lm --eval-trials 100
  dnnevo sweep sequence-1bit --seeds 0-7 --workers 2 --out runs/sweep-dask
  dnnevo sweep sequence-2bit --seeds 0-9 --out runs/inc --seed-from runs/sequence-1bit-seed0 \
      --seed-from runs/sequence-2bit-alternating-seed0 --seed-populations --spare-neurons 6

Reports the seeds whose run met the task's rule (k/n with a 95% Wilson interval), the median
first-success generation (95% bootstrap interval, fixed bootstrap seed; a seed that never
succeeded counts as +infinity, so "not reached" when more than half never did), and the final
champions (best.json) that pass on fresh conditions from seed BASE + seed (--eval-seed), judged as
'dnnevo assess' judges. Each final champion is also judged on the same conditions at a 10x
finer step and with RK4 ('dnnevo assess --dt-check'); one that fails there where it did not at
the run's step is counted as a step artefact (--no-dt-check skips the check). Writes
OUT/summary.csv (a row per seed, then a row 'all') and OUT/summary.json.

A sweep records its settings in OUT/sweep.json first. Running the same command again continues
it: finished seeds are judged again without evolving, stopped ones resume from their checkpoints,
and seeds not yet begun are run; more seeds may be added. With more generations (--set
generations=G) and otherwise the same settings it extends the sweep: every run continues to G
generations and is judged again. Other settings are refused, naming the first that differs.
--force starts the sweep afresh: the old summary goes, and so do the old sweep's seed-N run
folders (files dnnevo did not write are kept).

With --workers N the seeds run in parallel on a local Dask cluster of N processes, one run each
at a time with --threads threads (default 1); --scheduler tcp://HOST:8786 uses a running cluster
whose workers see OUT and the --seed-from runs at the same paths (pip install "dnnevo[cluster]").
The results are the same bits as in this process."""


def warn_unseeded(preset: str, how: seeding.Seeding | None, config: EvolutionConfig) -> None:
    """Says on stderr, in one line, when a preset meant to start from earlier runs has none.
    Its task is built first, so that a bad setting is the command's one line of error, not a
    warning and then an error."""
    warning = presets.unseeded_warning(preset, seeded=how is not None)
    if warning:
        config.native.builtin()
        print(f"dnnevo: warning: {warning}", file=sys.stderr)


def sweep_command(args: argparse.Namespace) -> int:
    """``dnnevo sweep``."""
    config = presets.get(args.preset, quick=args.quick, overrides=args.set)
    if named.is_python_task(config.task):
        # A task class must have its success rule before any seed runs.
        success_rule(named.closed_loop(config).env, config.task)
    elif config.task not in DEFAULT_TRIALS:
        raise ConfigError(f"task {config.task!r} has no success rule, so a sweep cannot judge it")
    refuse_idle_scale(config)  # before the manifest: the seeds' runs would refuse it
    for seed in args.seeds:  # before any run, so a bad --eval-seed costs nothing
        nonnegative("--eval-seed + seed", sweep.eval_seed(seed, args.eval_seed))
    trials = args.eval_trials if args.eval_trials is not None else registry.get(config.task).DEFAULT_TRIALS
    if args.workers is not None or args.scheduler is not None:
        scheduler.check_options(workers=args.workers, scheduler=args.scheduler)
    how = seeding.Seeding.from_args(args)
    warn_unseeded(args.preset, how, config)
    settings = {"preset": args.preset, "eval_seed": args.eval_seed, "eval_trials": trials,
                "dt_check": args.dt_check, "seeding": how.info() if how else None,
                "config": config.to_dict()}
    manifest = args.out / SETTINGS_FILE
    if not (manifest.exists() or manifest.is_symlink()):
        RunDir(args.out).refuse_unless_new(force=args.force)  # before the lock file is made
    with RunDir(args.out).writing(create=True) as folder:
        resuming = not args.force and (manifest.exists() or manifest.is_symlink())
        if resuming:
            # A sweep killed inside a write of its own files left their temporary files.
            remove_temporaries(args.out, (*sweep.SUMMARY_FILES, SETTINGS_FILE))
            _extend(manifest, settings)
            check_settings(manifest, settings, what="sweep")
        else:
            folder.create(force=args.force, extra=(*sweep.SUMMARY_FILES, SETTINGS_FILE))
            if args.force:
                _clear_other_seeds(args.out, args.seeds)
            write_atomic(manifest, json.dumps(settings, indent=1) + "\n")
        return _sweep(args, config, how, trials, resuming)


def _extend(manifest: Path, settings: dict[str, Any]) -> None:
    """A sweep continued with more generations (``--set generations=G``) and otherwise the same
    settings is extended: ``manifest`` is rewritten to say so, and each seed's run continues to
    ``G`` generations when its turn comes. Anything else is left to :func:`check_settings`."""
    try:
        with checked(manifest):  # a damaged manifest is check_settings' to report, not this
            found = read_json(manifest)
            found = {**found, "config": with_later_defaults(found["config"])}
            before = found["config"]["generations"]
        if not isinstance(before, int) or isinstance(before, bool):
            return
    except RunFileError:
        return
    after = settings["config"]["generations"]
    if before < after and first_difference(
            {**found, "config": {**found["config"], "generations": after}}, json.loads(json.dumps(settings))) is None:
        write_atomic(manifest, json.dumps(settings, indent=1) + "\n")
        print(f"extending the sweep from {before} to {after} generations")


def _clear_other_seeds(out: Path, seeds: list[int]) -> None:
    """``--force``: the old sweep's run folders ``seed-N`` of seeds the new sweep does not run
    lose their run files and figures (each under its lock), and go if nothing else is left, so
    the folder holds only the new sweep's runs."""
    keep = {f"seed-{s}" for s in seeds}
    for p in sorted(out.iterdir()):
        if p.name in keep or not re.fullmatch(r"seed-\d+", p.name) or not p.is_dir() or p.is_symlink():
            continue
        run = RunDir(p)
        with run.writing(create=False):
            run.clear()
        if [q.name for q in p.iterdir()] in ([], [LOCK_NAME]):
            shutil.rmtree(p)


def _sweep(args: argparse.Namespace, config: EvolutionConfig, how: seeding.Seeding | None,
           trials: int, resuming: bool) -> int:
    tasks = []
    for seed in args.seeds:
        out = args.out / f"seed-{seed}"
        resume = resuming and (out / "checkpoint.json").exists()
        if resume:
            done = len(RunDir(out).read_checkpoint().history)
            print(f"seed {seed}: " + ("finished; judging its champion again" if done >= config.generations
                                      else f"resuming at generation {done}"))
        # A seed folder without a checkpoint holds no run yet: it starts afresh.
        options = {"threads": args.threads, "force": args.force or (resuming and not resume),
                   "eval_seed_base": args.eval_seed, "eval_trials": trials, "dt_check": args.dt_check,
                   "seeding": how, "resume": resume}
        tasks.append(scheduler.Task(f"seed-{seed}", (), sweep.run_seed, (config, seed, out), options))
    failed = 0
    if args.workers is not None or args.scheduler is not None:
        runs, failed = _on_dask(args, tasks)
    else:
        runs = []
        for task in tasks:
            runs.append(task.fn(*task.args, **task.kwargs))
            if runs[-1].interrupted:
                break
            print(_seed_line(runs[-1]), flush=True)
    # A seed stopped part-way is not a result: its champion is an early one, not the run's.
    stopped = [r.seed for r in runs if r.interrupted]
    finished = [r for r in runs if not r.interrupted]
    if finished:
        summary = sweep.summarize(finished)
        info = {"preset": args.preset, "quick": args.quick, "overrides": list(args.set), "task": config.task,
                "eval_seed": f"{args.eval_seed} + seed", "eval_trials": trials,
                "eval_unit": registry.get(config.task).UNIT, **(how.info() if how else {})}
        paths = summary.write(args.out, info)
        print("\n".join(lines(summary, args.eval_seed, trials, registry.get(config.task).UNIT)))
        print(f"wrote {', '.join(map(str, paths))}")
    if stopped:
        print(f"interrupted during seed {stopped[0]}, which the statistics leave out; they cover the "
              f"{len(finished)} finished seed(s); run the same command again to continue the sweep (it resumes seed {stopped[0]} "
              "from its checkpoint, as the dnnevo resume above would, then runs the seeds after it)")
        return 130
    if failed:
        print(f"{failed} seed(s) failed (named above); the statistics cover the {len(runs)} that did not")
        return 2
    return 0


def _on_dask(args: argparse.Namespace, tasks: list[scheduler.Task]) -> tuple[list[sweep.SeedResult], int]:
    """The seeds' runs on a Dask cluster, one run per worker at a time, each with ``--threads``
    threads (default 1), and how many failed: each is named on stderr and left out of the
    statistics."""
    for task in tasks:
        task.kwargs.update(progress=False, threads=args.threads or 1)
    view = RunsView(len(tasks))
    with scheduler.dask_client(workers=args.workers, scheduler=args.scheduler) as client:
        print(f"on {scheduler.describe(client, args.scheduler)}")
        outcomes = scheduler.run_on_dask(tasks, view, client)
    view.close()
    failed = [o for o in outcomes.values() if o.status != "done"]
    if len(failed) == len(tasks):
        raise DnnevoError(f"every seed failed; the first: {failed[0].message}")
    for o in failed:
        sys.stderr.write(f"dnnevo: {o.task.id} failed: {o.message}\n")
    return [o.result for o in outcomes.values() if o.status == "done"], len(failed)


def _seed_line(r: sweep.SeedResult) -> str:
    """One finished seed in a line, printed as soon as it is judged."""
    met = "never met the rule" if r.first_success is None else f"met the rule at generation {r.first_success}"
    return (f"seed {r.seed}: {met}; final champion {r.final.verdict} ({_weakest_rate(r)})"
            + ("; a step artefact" if r.artefact else "")
            + ("; note: every fresh episode gave the same return and length, as a task that draws "
               "nothing from rng gives, or one whose episodes all end alike (docs/closed-loop.md)"
               if r.final.details.get("all_alike") else ""))


def _weakest_rate(r: sweep.SeedResult) -> str:
    """The final champion's weakest judged rate as k/n, named when there are several."""
    w = r.final.weakest
    return f"{w.name} {w.k}/{w.n}" if len(r.final.judged) > 1 else f"{w.k}/{w.n}"


def _generation(x: float) -> str:
    return "not reached" if x == float("inf") else f"{x:.0f}"


def stored_summary(out: Path) -> list[str] | None:
    """What the sweep in ``out`` printed about its finished seeds, made again from its
    ``summary.json`` (checked as it is read); None when ``out`` holds no sweep's summary."""
    path = out / sweep.SUMMARY_FILES[1]
    if not (out / SETTINGS_FILE).is_file() or not path.is_file():
        return None
    with checked(path):
        d = read_json(path)
        runs = [sweep.SeedResult.from_dict(r) for r in d["runs"]]
        base = int(str(d["eval_seed"]).split()[0])  # written as "BASE + seed"
        trials, unit = int(d["eval_trials"]), str(d["eval_unit"])
        if not runs:
            raise ValueError("no seed's result")
    return [f"{out}: a sweep of {d['preset']}, {len(runs)} finished seed{'s' * (len(runs) != 1)} "
            f"(summary.json; each seed's run: dnnevo show {out / f'seed-{runs[0].seed}'})",
            *lines(sweep.summarize(runs), base, trials, unit)]


def lines(s: sweep.Summary, eval_seed: int, trials: int, unit: str) -> list[str]:
    """The sweep's table and statistics in words."""
    out = [
        "first success: the first generation whose champion met the task's success rule during the run",
        f"final: the run's final champion on fresh conditions (seed {eval_seed} + seed, {trials} {unit}),"
        " judged as 'dnnevo assess' judges; the weakest judged rate is shown",
        f"{'seed':>5} {'best':>8} {'at gen':>7} {'first success':>14} {'wall s':>8}  "
        f"{'final rate':>16}  {'95% interval':<16}  verdict",
    ]
    for r in s.runs:
        w = r.final.weakest
        rate = _weakest_rate(r)
        bounds = f"[{w.interval[0]:.1%}, {w.interval[1]:.1%}]"
        out.append(
            f"{r.seed:>5} {r.best_fitness:>8.4f} {r.best_generation:>7} "
            f"{'-' if r.first_success is None else r.first_success:>14} {r.wall_s:>8.1f}  "
            f"{rate:>16}  {bounds:<16}  {r.final.verdict}"
            + ("  (step artefact)" if r.artefact else ""))
    n = s.seeds
    lo, hi = s.success_interval
    out.append(f"seeds whose run met the rule: {s.succeeded}/{n} = {s.succeeded / n:.0%} "
               f"(95% Wilson interval [{lo:.1%}, {hi:.1%}])")
    m = s.first_success
    censored = (f"{m.censored} of {n} seed(s) never met the rule and count as censored at their last "
                "generation")
    bounds = f"95% bootstrap interval [{_generation(m.lo)}, {_generation(m.hi)}]"
    if m.reached:
        out.append(f"median first-success generation: {_generation(m.median)} ({bounds}; {censored})")
    else:
        out.append(f"median first-success generation: not reached, as more than half the seeds never "
                   f"met the rule ({censored}; {bounds})")
    lo, hi = s.pass_interval
    v = s.verdicts
    out.append(f"final champions passing on fresh trials: {s.passed}/{n} = {s.passed / n:.0%} "
               f"(95% Wilson interval [{lo:.1%}, {hi:.1%}]); {v['fail']} fail, {v['undecided']} undecided")
    if s.checked:
        out.append(f"step artefacts: {s.artefacts} of {s.checked} final champions fail at a 10x finer "
                   "step or with RK4 on the same trials where the run's step did not")
    return out
