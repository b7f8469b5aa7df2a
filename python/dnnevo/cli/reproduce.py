"""The ``dnnevo reproduce`` command: every experiment of the paper over seeds (:mod:`dnnevo.experiments.plan`),
run in this process or on Dask (:mod:`dnnevo.experiments.scheduler`), resumable, with a report
(:mod:`dnnevo.experiments.report`)."""

from __future__ import annotations

import argparse
import importlib.util
import json
import shlex
import sys
import time
from pathlib import Path
from typing import Any

from dnnevo.experiments import jobs
from dnnevo.experiments import plan
from dnnevo.experiments import report
from dnnevo.experiments import scheduler
from dnnevo.errors import ConfigError, DnnevoError
from dnnevo.runs import LOCK_NAME, RunDir, RunFileError, check_settings, manifest_with_later_defaults, write_atomic
from dnnevo.runs.files import read_json, remove_temporaries
from dnnevo.experiments.runsview import RunsView

SETTINGS_FILE = "reproduce.json"
"""The settings a reproduction's folder was begun with, so that running the command again
continues it."""

DESCRIPTION = """\
Run every experiment of the paper over seeds and write a report: landmark recognition (ideal
training, then the robot-like test of the champions and the held-out worlds), predator avoidance and reactive navigation
(family robots: the paper's hand-designed network with and without its detectors on fresh
starts, nothing evolved, then dnnevo's evolved comparison), one-dimensional navigation (the
three subnetworks, the goal seekers evolved on chains, both integrated systems, the single
network) and sequence learning (1-bit, alternating, the incremental 2-bit route from those two
runs, direct 2-bit, and beyond the paper direct 2-bit with 16 neurons, 3-bit). --only ablation
runs the working incremental 2-bit route with one of its departures from the paper removed at a
time, and with the two that matter least removed together (ablation-2bit-smallest), with the
1-bit and alternating runs it composes (those the folder holds are used).
--only precision runs the landmark, navigation (with the integrated system), 1-bit and 3-bit
experiments again with precision = "f32", to compare their success counts with f64's.
--only classic runs the field's benchmarks written as Python tasks instead (walker, categorical
perception, double pole). Each evolution has its own run folder OUT/EXPERIMENT/seed-N and its result in
OUT/EXPERIMENT/seed-N.json (the robot-like test, the held-out worlds, the integrated systems
and the hand-designed navigator are tests and have only the result; the navigator's starts per
world are --eval-trials, else 200, or 20 with --quick, and the held-out worlds' trials per
landmark --eval-trials, else 100, or 10 with --quick). The report, OUT/report.md and OUT/report.html,
covers the seeds and families of the command that wrote it."""

EXAMPLE = """examples:
  dnnevo reproduce --quick --seeds 0-1 --out runs/repro-quick     2-3 minutes on 2 cores
  dnnevo reproduce --only sequence --seeds 0-4 --out runs/repro-seq
  dnnevo reproduce --only classic --quick --seeds 0 --out runs/repro-classic
  dnnevo reproduce --out reproduce --workers 4 --threads-per-worker 2
  dnnevo reproduce --only ablation --out reproduce      uses the sequence runs it holds
  dnnevo reproduce --only sequence-2bit --seeds 3 --out reproduce   one experiment and the runs it needs
  dnnevo reproduce --only precision --quick --seeds 0 --out runs/repro-f32   seconds
  dnnevo reproduce --out /shared/reproduce --scheduler tcp://HOST:8786

By default the runs go to a Dask LocalCluster of one worker process per core, one run at a time
each (pip install "dnnevo[cluster]"); without Dask, or with --in-process, they run one after
another here, each on every core. Running the same command again skips finished runs, resumes
stopped ones from their checkpoints (a killed worker's run too) and refuses other settings,
naming the first that differs; more seeds or families may be added. A result whose run files
changed since (e.g. a run extended with 'dnnevo resume') is made again. After Ctrl-C with
--scheduler, the cluster's workers finish the runs they hold. Exit status: 0 when every
run finished, 2 when some did not (each is named), 130 on Ctrl-C."""


def add_parser(sub: Any, parse_seeds: Any, positive: Any) -> None:
    """Adds the ``reproduce`` command."""
    p = sub.add_parser("reproduce", help="the whole paper: every experiment over seeds, with a report",
                       description=DESCRIPTION, epilog=EXAMPLE, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=parse_seeds, default=parse_seeds("0-9"), help="e.g. 0-9 or 1,4,7 (default 0-9)")
    p.add_argument("--quick", action="store_true", help="each preset's quick variant: small populations, few generations")
    p.add_argument("--only", type=_picked, default=plan.PAPER_FAMILIES, metavar="NAMES",
                   help=f"comma-separated families, from {','.join(plan.FAMILIES)} (default the paper's: "
                        f"{','.join(plan.PAPER_FAMILIES)}), or experiments, e.g. sequence-2bit (a "
                        "name that is both, as landmark, is the family)")
    p.add_argument("--out", type=Path, default=Path("reproduce"), help="the reproduction's folder (default reproduce)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a setting for every evolution, after its preset's, e.g. population=200")
    p.add_argument("--eval-trials", type=positive, metavar="N",
                   help="fresh trials judging each final champion (default: the task's, as 'dnnevo assess')")
    p.add_argument("--no-dt-check", dest="dt_check", action="store_false",
                   help="skip judging each final champion again at a 10x finer step and with RK4")
    p.add_argument("--workers", type=positive, metavar="N", help="worker processes of the local Dask cluster "
                                                                  "(default: one per core)")
    p.add_argument("--threads-per-worker", type=positive, default=None, metavar="T",
                   help="threads of each run (default: 1 on Dask, all cores in process)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler, e.g. tcp://HOST:8786")
    p.add_argument("--in-process", action="store_true", help="run here, one run after another, without Dask")
    p.add_argument("--no-figures", dest="figures", action="store_false",
                   help="a report of tables only: drawing the figures takes about a second per experiment")


def _picked(text: str) -> tuple[str, ...]:
    try:
        return plan.picked(text.split(","))
    except ConfigError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def reproduce(args: argparse.Namespace) -> int:
    """``dnnevo reproduce``."""
    settings = jobs.Settings(quick=args.quick, eval_trials=args.eval_trials, dt_check=args.dt_check,
                             overrides=tuple(args.set))
    for e in plan.EXPERIMENTS:  # a bad --set is one line now, not a failure of every run
        if e.kind == plan.EVOLVE:
            settings.config(e)
    order = plan.jobs(args.seeds, args.only)
    dask = not args.in_process and (args.scheduler is not None or args.workers is not None
                                    or importlib.util.find_spec("distributed") is not None)
    if args.in_process and (args.scheduler or args.workers):
        raise ConfigError("--in-process runs here; it takes no --workers or --scheduler")
    if dask:
        scheduler.check_options(workers=args.workers, scheduler=args.scheduler)
    root = args.out.resolve()
    t0 = time.perf_counter()
    with RunDir(root).writing(create=True):
        _tidy(root, order)
        _begin(root, settings, {j.experiment for j in order})
        # Finished runs are not run again; the others need only the unfinished among their needs.
        stored = {j.id: jobs.read_result(root, j, settings) for j in order}
        done = {j.id: scheduler.Outcome(scheduler.Task(j.id, j.needs, jobs.run_job), "done", stored[j.id])
                for j in order if stored[j.id] is not None}
        before = len(done)
        print(f"{len(order)} runs in {args.out} ({before} already done)"
              + ("" if dask else "; in this process" + (" (Dask is not installed: "
                                                         f"{scheduler.CLUSTER_EXTRA})" if not args.in_process else "")))
        view = RunsView(len(order), before, bar=dask)
        threads = (args.threads_per_worker or 1) if dask else args.threads_per_worker
        progress = not dask and sys.stderr.isatty()
        tasks = [scheduler.Task(j.id, tuple(n for n in j.needs if n not in done), jobs.run_job,
                                (j, str(root), settings, threads), {"progress": progress})
                 for j in order if j.id not in done]
        try:
            if not tasks:
                workers, ran = "none (every run was done before)", {}
            elif dask:
                with scheduler.dask_client(workers=args.workers, scheduler=args.scheduler) as client:
                    workers = scheduler.describe(client, args.scheduler)
                    print(f"on {workers}")
                    ran = scheduler.run_on_dask(tasks, view, client)
            else:
                workers = "none (in process)"
                ran = scheduler.run_in_process(tasks, view)
        except jobs.Stopped as e:
            view.close()
            sys.stderr.write(f"dnnevo: stopped: {e}; run the same command again to continue\n")
            return 130
        except KeyboardInterrupt:
            view.close()
            sys.stderr.write("dnnevo: interrupted; run the same command again to continue from the checkpoints\n")
            return 130
        view.close()
        outcomes = {j.id: done[j.id] if j.id in done else ran[j.id] for j in order}
        env = report.environment(workers=workers, threads=threads, wall_s=time.perf_counter() - t0)
        command = _command(args)
        blocks = report.build(root, order, outcomes, settings=settings, environment=env, command=command,
                              draw=args.figures)
        paths = report.write(root, blocks)
    print(report.markdown([b for b in blocks if b.kind == "table"][:1]), end="")
    print(f"wrote {', '.join(str(args.out / p.name) for p in paths)}")
    missing = [o for o in outcomes.values() if o.status != "done"]
    for o in missing:
        sys.stderr.write(f"dnnevo: {o.task.id} {o.status}: {o.message}\n")
    return 2 if missing else 0


def _command(args: argparse.Namespace) -> str:
    """The command that makes this reproduction, for its report."""
    words = ["dnnevo", "reproduce", "--seeds", ",".join(map(str, args.seeds)), "--out", str(args.out)]
    words += ["--quick"] if args.quick else []
    words += ["--only", ",".join(args.only)] if tuple(args.only) != plan.PAPER_FAMILIES else []
    words += ["--eval-trials", str(args.eval_trials)] if args.eval_trials is not None else []
    words += [] if args.dt_check else ["--no-dt-check"]
    words += [] if args.figures else ["--no-figures"]
    words += [w for kv in args.set for w in ("--set", kv)]
    return " ".join(shlex.quote(w) for w in words)


def _tidy(root: Path, order: list[plan.Job]) -> None:
    """Removes the temporary files that a reproduction killed inside a write left behind (of the
    report, its figures, the settings and the runs' results). The lock's holder alone writes
    them; each run folder's own are its run's to remove."""
    remove_temporaries(root, (*report.REPORT_FILES, SETTINGS_FILE))
    remove_temporaries(root / report.FIGURES)
    for experiment in sorted({j.experiment for j in order}):
        remove_temporaries(root / experiment, {jobs.result_path(root, j).name for j in order})


def _begin(root: Path, settings: jobs.Settings, experiments: set[str]) -> None:
    """Records the settings and the configs of ``experiments`` (those the command runs) in a new
    reproduction's folder, or checks them in an old one. Other experiments' configs are neither
    recorded nor checked: a change to a family this command does not run cannot refuse it."""
    manifest = root / SETTINGS_FILE
    wanted = settings.to_dict()
    wanted["configs"] = {k: v for k, v in wanted["configs"].items() if k in experiments}
    if manifest.exists() or manifest.is_symlink():
        # Experiments added to dnnevo since the folder was begun join it; the others must match.
        try:
            found = manifest_with_later_defaults(read_json(manifest))
            recorded = found["configs"]
        except (RunFileError, TypeError, KeyError):
            recorded = None  # check_settings names what is wrong
        if not isinstance(recorded, dict):
            check_settings(manifest, wanted, what="reproduction", force=False)
            return
        # The recorded configs of experiments this command runs must be the wanted ones.
        ours = {k: v for k, v in wanted["configs"].items() if k in recorded}
        check_settings(manifest, {**wanted, "configs": {**recorded, **ours}}, what="reproduction", force=False)
        added = {k: v for k, v in wanted["configs"].items() if k not in recorded}
        for name in added:  # an experiment the folder has runs of was recorded, or it is not ours
            if (root / name).exists():
                raise RunFileError(f"{manifest}: has no config for {name}, yet {root / name} holds "
                                   "its runs; choose another --out")
        if added:
            write_atomic(manifest, json.dumps({**found, "configs": {**recorded, **added}}, indent=1) + "\n")
        return
    if any(p.name != LOCK_NAME for p in root.iterdir()):
        raise DnnevoError(f"{root} holds files but no {SETTINGS_FILE}; choose another --out")
    write_atomic(manifest, json.dumps(wanted, indent=1) + "\n")
