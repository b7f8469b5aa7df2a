"""The ``dnnevo`` command line. Every failure is one line on stderr and exit status 2
(``--debug`` shows the traceback)."""

from __future__ import annotations

import sys

import dnnevo
from dnnevo import _startup

# Ctrl-C while the rest of the command's modules load is one line too (see dnnevo/_startup.py).
if sys.excepthook is sys.__excepthook__:
    sys.excepthook = _startup.interrupted_import

import argparse
import traceback
from pathlib import Path
from typing import Any

from dnnevo import figures
from dnnevo.cli import analyze as _cli_analyze
from dnnevo.cli import assess as _cli_assess
from dnnevo.cli import nav1d_system as _cli_nav1d_system
from dnnevo.cli import outputs as _outputs
from dnnevo.cli import reproduce as _cli_reproduce
from dnnevo.cli import show as _cli_show
from dnnevo.cli import sweep as _cli_sweep
from dnnevo import presets
from dnnevo.config import PYTHON_TASK
from dnnevo.evolution import seeding
from dnnevo.experiments import sweep
from dnnevo.tasks import DEFAULT_TRIALS, user
from dnnevo.errors import DnnevoError
from dnnevo.runs import RunDir

EXAMPLES = """examples:
  dnnevo presets                                   list the experiments
  dnnevo run sequence-1bit --quick --out runs/demo a tiny demo run (under a second)
  dnnevo run sequence-1bit --seed 3                the paper's 1-bit experiment (1000 x 500)
  dnnevo run sequence-1bit --set population=200 --set mutation_rate=0.02
  dnnevo resume runs/demo                          continue a stopped run
  dnnevo show runs/demo                            summary and fitness.png
  dnnevo assess runs/demo                          judge the champion on fresh conditions
  dnnevo assess runs/demo --json                   ... as JSON; exit 0 pass, 1 fail, 3 undecided
  dnnevo plot runs/demo                            fitness curve and the paper's figures
  dnnevo analyze runs/demo                         attractors, bifurcations, lesions
  dnnevo sweep sequence-1bit --quick --seeds 0-4 --out runs/sweep
  dnnevo run nav1d-classifier --out runs/cls       the paper's navigation classifier (6 s)
  dnnevo nav1d-system --classifier runs/cls --far runs/far --near runs/near
  dnnevo run landmark --out runs/lm && dnnevo assess runs/lm --robot-like
  dnnevo reproduce --quick --seeds 0-1 --out runs/repro   the whole paper in miniature, with a report
"""


MAX_SEEDS = 10_000
"""The most seeds a sweep or reproduction takes."""

MAX_SEED = 999_999
"""The largest seed of a sweep or reproduction: its fresh conditions come from seeds 1000003 +
seed and up, which no run of it then uses."""


def _parse_seeds(text: str) -> list[int]:
    seeds: list[int] = []
    try:
        for part in text.split(","):
            lo, sep, hi = part.partition("-")
            first, last = (int(lo), int(hi)) if sep else (int(lo), int(lo))
            if not 0 <= first <= last <= MAX_SEED:
                raise argparse.ArgumentTypeError(
                    f"{part!r}: seeds go from 0 to {MAX_SEED}, a range low to high")
            seeds.extend(range(first, last + 1))
            if len(seeds) > MAX_SEEDS:
                raise argparse.ArgumentTypeError(f"more than {MAX_SEEDS} seeds")
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text[:40]!r} is not a seed list such as 0-9 or 1,4,7"
        ) from None
    if not seeds:
        raise argparse.ArgumentTypeError("the seed list is empty")
    if len(set(seeds)) != len(seeds):
        raise argparse.ArgumentTypeError("a seed is listed twice")
    return seeds


def _nonnegative(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} is negative")
    return value


def _positive(text: str) -> int:
    value = _nonnegative(text)
    if value == 0:
        raise argparse.ArgumentTypeError("must be >= 1")
    return value


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"dnnevo: error: {message} (see '{self.prog} --help')\n")
        raise SystemExit(2)


class _CommandParser(_Parser):
    """A subcommand's parser: it takes ``--debug`` too, so that the option works after the
    command as well as before it. Its default is left out (``SUPPRESS``), so that a command
    without it keeps the value the top-level parser set."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                          help="show tracebacks on errors")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``dnnevo`` command."""
    parser = _Parser(
        prog="dnnevo",
        description="Evolve continuous-time recurrent neural networks (after Yamauchi & Beer).",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"dnnevo {dnnevo.__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_CommandParser)

    def run_options(p: argparse.ArgumentParser) -> None:
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help="override a setting, e.g. population=200, integrator.dt=0.05 or "
                            "task_params.sim.sonars.0.lobe_deg=10 (in task_params, a number picks "
                            "a list's entry and the rest of the task's table keeps its defaults; a "
                            "top-level pair is set whole: ranges.tau=[1, 10]); values are TOML: "
                            "booleans are true and false")
        p.add_argument("--quick", action="store_true",
                       help="small population, few generations: a demo, not a result")
        p.add_argument("--threads", type=_positive, help="worker threads (default: all cores)")

    p = sub.add_parser("run", help="run a preset, or a task written in Python",
                       epilog="examples:\n  dnnevo run sequence-1bit --quick --out runs/demo\n"
                              "  dnnevo run landmark --quick --set task_params.sim.sonars.0.lobe_deg=10 "
                              "--set task_params.sim.follower.angle_gain=0.3\n"
                              "  dnnevo run python:light.Light --set size=3 --set selection=rank "
                              "--set task_params.max_steps=300 --set task_params.episodes=4\n"
                              "    (the class Light of light.py in this folder: docs/closed-loop.md)",
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("preset", help="preset name (see 'dnnevo presets'), or python:module.Class for a "
                                  "closed-loop task class")
    p.add_argument("--seed", type=_nonnegative, default=0, help="random seed (default 0)")
    p.add_argument("--out", type=Path, help="run folder (default runs/PRESET-seedN; with --quick, runs/PRESET-quick-seedN)")
    p.add_argument("--force", action="store_true",
                   help="overwrite a non-empty run folder (its run files and figures are removed)")
    seeding.add_arguments(p)
    run_options(p)

    p = sub.add_parser("resume", help="continue a stopped run",
                       description="Continue a stopped run from its checkpoint, bit for bit. Every "
                                   "file of the folder is checked first: an edited config.toml is "
                                   "refused, naming the first setting that differs, and a damaged "
                                   "or deleted log.csv or best.json is written again from the "
                                   "checkpoint, and said.",
                       epilog="examples:\n  dnnevo resume runs/demo\n"
                              "  dnnevo resume runs/demo --generations 500   extend a finished run",
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir", type=Path, help="the run folder")
    p.add_argument("--threads", type=_positive, help="worker threads (default: all cores)")
    p.add_argument("--generations", type=_positive, metavar="N",
                   help="run until generation N: more than the run's count extends it, fewer "
                        "(not below the generations done) ends it sooner; config.toml and the "
                        "checkpoint are updated to say so")

    p = sub.add_parser("show", help="summarise a run and write fitness.png",
                       description="Summarise a run folder (its champion, generations, success rule "
                                   "and the next command) and write fitness.png into it; for a "
                                   "sweep's folder, print the sweep's statistics over its finished seeds.",
                       epilog="examples: dnnevo show runs/demo; dnnevo show runs/sweep (a sweep's folder)")
    p.add_argument("dir", type=Path)

    sub.add_parser("presets", help="list the presets",
                   description="List the named experiments that 'dnnevo run PRESET' and "
                               "'dnnevo sweep PRESET' take, with what each is.",
                   epilog="example: dnnevo presets")

    trials_help = (f"trials per target (sequence, default {DEFAULT_TRIALS['sequence']}), per landmark "
                   f"(landmark, default {DEFAULT_TRIALS['landmark']}), chains of trials (nav1d, "
                   f"default {DEFAULT_TRIALS['nav1d']}; each default takes 2 s at most on one core) "
                   f"or episodes (a Python task class, default {user.DEFAULT_TRIALS})")
    p = sub.add_parser("sweep", help="independent runs over seeds, with success statistics",
                       description="Independent runs of a preset over seeds; each final champion is "
                                   "judged on fresh conditions as 'dnnevo assess' judges it.",
                       epilog=_cli_sweep.EXAMPLE, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("preset")
    p.add_argument("--seeds", type=_parse_seeds, default=_parse_seeds("0-9"), help="e.g. 0-9 or 1,4,7")
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--force", action="store_true")
    p.add_argument("--eval-seed", type=_nonnegative, default=sweep.EVAL_SEED_BASE, metavar="BASE",
                   help="seed s's final champion is judged on fresh conditions from seed BASE + s "
                        f"(default {sweep.EVAL_SEED_BASE}, which no run uses)")
    p.add_argument("--eval-trials", type=_positive, metavar="N", help="fresh " + trials_help)
    p.add_argument("--no-dt-check", dest="dt_check", action="store_false",
                   help="skip judging each final champion again at a 10x finer step and with RK4")
    p.add_argument("--workers", type=_positive, metavar="N",
                   help="run the seeds on a local Dask cluster of N worker processes")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run the seeds on the Dask cluster at ADDRESS")
    seeding.add_arguments(p)
    run_options(p)

    p = sub.add_parser("assess", aliases=["evaluate"],
                       help="judge a champion on fresh random conditions (evaluate: its old name, deprecated)",
                       description="Judge a run's champion on fresh random conditions: every rate "
                                   "with a 95% Wilson interval and a verdict (pass, fail or undecided).",
                       epilog=_cli_assess.EXAMPLE, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir", type=Path)
    p.add_argument("--trials", type=_positive, default=None, help="fresh " + trials_help)
    p.add_argument("--seed", type=_nonnegative, default=None,
                   help="seed of the fresh conditions (default: a random one, printed)")
    p.add_argument("--robot-like", action="store_true",
                   help="landmark runs: sonar noise, specular misses and a jittered room")
    p.add_argument("--json", action="store_true",
                   help="print the whole assessment as JSON on stdout instead of text")
    p.add_argument("--dt", type=float, default=None,
                   help="integrate with this step (of the run's method, Euler or RK4) instead of the run's, each time step kept "
                        "as long (e.g. 0.01 for 10x finer): tells a behaviour from a step artefact")
    p.add_argument("--dt-check", action="store_true",
                   help="also judge the champion on the same trials at a 10x finer step and with "
                        "RK4; a success that fails there is flagged as a step artefact (exit 1)")
    p.add_argument("--precision", choices=["f64", "f32"], default=None,
                   help="compute the champion in this precision instead of the run's (e.g. an f32 "
                        "run's champion in f64)")
    p.add_argument("--set", action="append", default=[], metavar="task_params.KEY=VALUE",
                   help="judge the champion on a variant of its task, conditions evolution never "
                        "saw (repeatable), e.g. task_params.speed=0.3: a transfer test (not the "
                        "rollout's episodes, validation_episodes or rows: --trials counts episodes)")

    p = sub.add_parser("plot", help="write the run's figures as PNGs into its folder",
                       description="Write the run's figures (its fitness and the paper's figures "
                                   "for its task, drawn from fresh trials) as PNGs into its folder.",
                       epilog="example: dnnevo plot runs/demo")
    p.add_argument("dir", type=Path)
    p.add_argument("--seed", type=_nonnegative, default=0, help="seed of the trials shown")
    p.add_argument("--animate", action="store_true",
                   help="landmark runs: also write a GIF of a trial (slower)")

    _cli_analyze.add_parser(sub)
    _cli_nav1d_system.add_parser(sub)
    _cli_reproduce.add_parser(sub, _parse_seeds, _positive)
    return parser


def _cmd_run(args: argparse.Namespace) -> int:
    config = presets.get(args.preset, quick=args.quick, overrides=args.set)
    stem = args.preset.removeprefix(PYTHON_TASK)
    out = args.out or Path("runs") / f"{stem}{'-quick' if args.quick else ''}-seed{args.seed}"
    how = seeding.Seeding.from_args(args)
    _cli_sweep.warn_unseeded(args.preset, how, config)
    seeds = how.networks(config.size, args.seed) if how else None
    info = how.info() if how else None
    result = dnnevo.evolve(config.task, config, seed=args.seed, out=out, threads=args.threads,
                           founders=seeds, force=args.force, run_info=info)
    return _report(result)


def _report(result: dnnevo.EvolutionResult) -> int:
    """Ends ``run`` and ``resume``: the time taken, the champion, the success rule and the next
    command, in the words of ``dnnevo show`` (see :mod:`dnnevo.cli.show`)."""
    h = result.history
    wall = h["elapsed_s"][-1] if len(h.get("elapsed_s", [])) else 0.0
    print(f"{len(h['generation'])} generations in {wall:.1f} s; run folder {result.run_dir}")
    champion: dict[str, float] = {"fitness": result.best_fitness, "generation": result.best_generation}
    if result.best_validation is not None:
        champion["validation_rate"], champion["validation_score"] = result.best_validation
    assert result.run_dir is not None, "the command line always writes a run folder"
    for line in _cli_show.outcome(result.run_dir, result.config, champion,
                                  list(h.get("champion_success", [])), interrupted=result.interrupted,
                                  best=list(h.get("best", [])), worst=list(h.get("min", []))):
        print(line)
    return 130 if result.interrupted else 0


def _cmd_resume(args: argparse.Namespace) -> int:
    done = _finished(args.dir) if args.generations is None else None
    # Resumed first: a finished run whose checkpoint is damaged gets the error alone.
    result = dnnevo.resume(args.dir, threads=args.threads, generations=args.generations)
    if done is not None:
        print(f"nothing to resume: {args.dir} has run all its {done} generations; to run it "
              f"longer: dnnevo resume {args.dir} --generations N (N > {done})")
    return _report(result)


def _finished(path: Path) -> int | None:
    """The generations of the run at ``path`` when its log says it has run them all, else None
    (also when a file is unreadable: ``resume`` then says what is wrong, or repairs it)."""
    try:
        run = RunDir(path)
        config, _ = run.read_config()
        done = len(run.read_log(config))
    except (DnnevoError, OSError):
        return None
    return done if done >= config.generations else None


def _cmd_presets(args: argparse.Namespace) -> int:
    width = max(map(len, presets.names()))
    for name in presets.names():
        preset = presets.PRESETS[name]
        if name in presets.ALIASES:
            print(f"{name:<{width}}  another name for {presets.ALIASES[name]}")
            continue
        seeded_by = f"; {preset.seeded_by}" if preset.seeded_by else ""
        print(f"{name:<{width}}  {preset.summary}{seeded_by}")
    return 0


def _cmd_plot(args: argparse.Namespace) -> int:
    written = figures.draw_run(args.dir, seed=args.seed, animate=args.animate)
    print(f"wrote {', '.join(str(args.dir / w) for w in written)}")
    if args.animate and not any(w.endswith(".gif") for w in written):
        print("note: --animate: only landmark runs have an animation; no GIF written", file=sys.stderr)
    return 0


COMMANDS = {
    "run": _cmd_run,
    "resume": _cmd_resume,
    "show": _cli_show.show,
    "presets": _cmd_presets,
    "sweep": _cli_sweep.sweep_command,
    "assess": _cli_assess.assess,
    "plot": _cmd_plot,
    "analyze": _cli_analyze.analyze,
    "nav1d-system": _cli_nav1d_system.system,
    "reproduce": _cli_reproduce.reproduce,
}


DEPRECATED = {"evaluate": "assess"}
"""Old command names that still work, each with a line on stderr naming the new one."""


def one_line(message: str) -> str:
    r"""``message`` with every character that is not printable (a line break or a control
    character quoted from a damaged file) escaped, so that an error stays on one line.

    >>> one_line("has columns \x0b; expected generation")
    'has columns \\x0b; expected generation'
    """
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in message)


def main(argv: list[str] | None = None) -> int:
    """Runs the command line; returns the exit status."""
    if sys.excepthook is _startup.interrupted_import:
        sys.excepthook = sys.__excepthook__
    try:
        _startup.allow_interrupts()  # one pressed during start-up is raised here
        parser = build_parser()
        args, extra = parser.parse_known_args(argv)
        if extra:  # named by the command's own parser, whose --help lists its options
            commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
            where = commands.choices.get(args.command, parser) if args.command else parser
            where.error(f"unrecognized arguments: {' '.join(extra)}")
    except KeyboardInterrupt:
        sys.stderr.write("dnnevo: interrupted\n")
        return 130
    if args.command is None:
        parser.print_help()
        return 0
    if args.command in DEPRECATED:
        sys.stderr.write(f"dnnevo: '{args.command}' is deprecated; use 'dnnevo {DEPRECATED[args.command]}'\n")
        args.command = DEPRECATED[args.command]
    try:
        return COMMANDS[args.command](args)
    except BrokenPipeError:
        _outputs.reader_gone()
        return 0
    except (DnnevoError, OSError) as e:
        if args.debug:  # the traceback too, and the same exit status: 1 is assess's "fail"
            traceback.print_exc()
        sys.stderr.write(f"dnnevo: error: {one_line(str(e))}\n")
        return 2
    except KeyboardInterrupt as e:
        # evolve's message says where a stopped run's checkpoint is, when it has one.
        sys.stderr.write(f"dnnevo: {e}\n" if str(e) else "dnnevo: interrupted\n")
        return 130
    except Exception:
        # A bug: show it, but exit 2 as for any error, never 1 (assess's "fail").
        sys.stderr.write("dnnevo: internal error, please report it:\n" + traceback.format_exc())
        return 2
