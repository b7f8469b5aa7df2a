"""The ``dnnevo assess`` command (``assess``, its old name, still works): a run's champion judged on fresh conditions by
:func:`dnnevo.tasks.assess`, printed as text (default) or JSON (``--json``). The exit status is
the verdict: 0 pass, 1 fail, 3 undecided (2 is an error)."""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from dnnevo import tasks
from dnnevo.cli.outputs import reader_gone
from dnnevo.closedloop import named
from dnnevo.closedloop.fitness import ROLLOUT_KEYS
from dnnevo.config import EvolutionConfig, apply_overrides
from dnnevo.evaluation.assessment import Assessment, Rate
from dnnevo.evaluation.stats import Verdict
from dnnevo.errors import ConfigError
from dnnevo.runs import RunDir
from dnnevo.evaluation.stepcheck import StepCheck, step_check, with_dt

EXAMPLE = """examples:
  dnnevo assess runs/demo                      the champion on fresh trials, default counts
  dnnevo assess runs/demo --trials 2000 --seed 1
  dnnevo assess runs/lm --robot-like --json    the whole assessment as JSON on stdout
  dnnevo assess runs/demo --dt 0.01            the same champion integrated 10x finer
  dnnevo assess runs/demo --dt-check           also at a 10x finer step and with RK4
  dnnevo assess runs/demo --precision f64      an f32 run's champion judged in f64
  dnnevo assess runs/lm --set task_params.sim.follower.speed=0.4   a transfer test: a slower robot

Each rate gets a 95% Wilson score interval. Verdict: pass when the interval lies at or above the
task's threshold (sequence: 90% of trials per target; landmark and nav1d: 95%), fail when it lies
below, undecided when it straddles it; then the output says how many trials would decide.
A sequence run passes when every target passes and fails when any fails. nav1d trials within one
chain share the network's state: with several scored trials per chain the interval counts chains.
--dt integrates the champion with a finer (or coarser) step of the run's method (Euler or RK4),
each time step of the task kept as long:
a behaviour that vanishes at a finer step is an artefact of the integrator, not a result.
--dt-check judges the champion again on the same trials at a 10x finer step and with RK4 (with
Euler runs), and calls it a step artefact when a rate that does not fail at the run's step fails
at either; an artefact's exit status is 1, whatever the run's step says.
Exit status: 0 pass, 1 fail, 3 undecided, 2 error."""

EXIT_STATUS: dict[Verdict, int] = {"pass": 0, "fail": 1, "undecided": 3}
"""``dnnevo assess``'s exit status per verdict (2 is a usage or input error, 130 Ctrl-C)."""


def assess(args: argparse.Namespace) -> int:
    """``dnnevo assess``."""
    run = RunDir(args.dir)
    config, table = run.read_run_config()
    champion = run.read_best(config, table)
    seed = args.seed if args.seed is not None else int.from_bytes(os.urandom(4), "little")
    task = tasks.get(config.task)
    named.refuse_fitness_function(config, args.dir, "which has no success rule; a task class can "
                                  "have one (docs/closed-loop.md)")
    named.check_own_task(config, table)  # before --dt changes the settings
    if args.robot_like and not task.ROBOT_LIKE:
        raise ConfigError(f"--robot-like applies to landmark runs; {args.dir} is a {config.task} run")
    if args.set:
        config = variant(config, args.set)
    if args.dt is not None:
        config = with_dt(config, args.dt, "--dt")
    evolved_in = config.precision
    if args.precision is not None:
        config = dataclasses.replace(config, precision=args.precision)
    a = tasks.assess(config, champion, args.trials, seed=seed, robot_like=args.robot_like)
    extra = task.assess_extra(config, champion, seed)
    if args.set:
        extra = {"variant": list(args.set), **extra}
    if args.dt is not None:
        extra = {"integrator": dataclasses.asdict(config.integrator), **extra}
    if config.precision != "f64" or evolved_in != "f64":
        extra = {"precision": config.precision, "evolved_in": evolved_in, **extra}
    check = None
    if args.dt_check:
        check = step_check(lambda c: tasks.assess(c, champion, a.trials, seed=seed, robot_like=args.robot_like),
                           config, base=a)
        extra = {**extra, "step_check": check.to_dict()}
    status = EXIT_STATUS["fail" if check is not None and check.artefact else a.verdict]
    try:  # the verdict stands when the reader stops early (`| head`)
        if args.json:
            print(json.dumps({"run": str(args.dir), **a.to_dict(), **extra}, indent=1), flush=True)
        else:
            print("\n".join(text(args.dir, a, extra) + (step_lines(check) if check else [])), flush=True)
    except BrokenPipeError:
        reader_gone()
    return status


COUNTS = tuple(k for k in ROLLOUT_KEYS if k != "max_steps")
"""The rollout's settings that count episodes or rows: a variant may not set them, since they
do not change what a fresh episode is (``--trials`` counts the judged ones)."""


def variant(config: EvolutionConfig, assignments: Sequence[str]) -> EvolutionConfig:
    """``config`` with ``task_params.KEY=VALUE`` ``assignments``: the run's task in conditions its
    evolution never saw. Other settings belong to the evolution, not the task, and are refused."""
    for item in assignments:
        key = item.partition("=")[0].strip()
        if not key.startswith("task_params."):
            raise ConfigError(f"--set {item!r}: assess changes the task's conditions only "
                              f"(task_params.KEY=VALUE); {key or '(no key)'} is not one")
        if key.removeprefix("task_params.") in COUNTS:
            raise ConfigError(f"--set {item!r}: the run's {key} does not change what a fresh episode "
                              "is; --trials says how many are judged")
    return apply_overrides(config, list(assignments))


def text(where: Path, a: Assessment, extra: dict[str, Any]) -> list[str]:
    """The human report of ``a`` on the run in ``where``."""
    task = tasks.get(a.task)
    lines = [*task.preface(where, a), *rate_table(a.rates, task.rate_column(a)), task.overall(a)]
    lines += [hint(r, a.unit) for r in a.judged if r.verdict == "undecided"]
    lines.append(f"intervals: {a.method}")
    if "variant" in extra:
        lines.append(f"judged on a variant of the run's task: {' '.join(extra['variant'])} (--set); "
                     "evolution never saw it")
    if "integrator" in extra:
        i = extra["integrator"]
        lines.append(f"integrated with dt = {i['dt']:g}, {i['substeps']} steps per time step "
                     "(--dt); the run was evolved with its config's step")
    if "precision" in extra:
        lines.append(f"computed in {extra['precision']}; the run was evolved in {extra['evolved_in']}")
    lines += task.extra_lines(extra)
    return lines


def step_lines(check: StepCheck) -> list[str]:
    """The time-step check's report: each judged rate at the run's step and at each check."""
    names = list(check.checks)
    judged = [r for r in check.base.rates if r.verdict is not None]
    width = max(4, *(len(r.name) for r in judged))
    run = check.integrators["run"]
    lines = [f"time-step check, same trials (run: {run['method']}, dt {run['dt']:g}; "
             f"dt/10: dt {check.integrators[names[0]]['dt']:g})",
             f"{'':>{width}} {'run step':>10}" + "".join(f" {n:>10}" for n in names)]
    def cell(rate: float, verdict: str | None) -> str:
        return percent(rate, 1) + ("!" if verdict == "fail" else "")

    marked = False
    for r in judged:
        cells = [cell(r.rate, r.verdict)] + [cell(c.rate, c.verdict) for c in
                                             (next(c for c in check.checks[n].rates if c.name == r.name)
                                              for n in names)]
        marked = marked or any(c.endswith("!") for c in cells)
        lines.append(f"{r.name:>{width}}" + "".join(f" {c:>10}" for c in cells))
    change = f"largest change {100 * check.max_change:.1f} points"
    legend = " (! marks a failing rate)" if marked else ""
    if check.artefact:
        lines.append(f"step artefact ({change}): fails only at a finer step: {'; '.join(check.artefacts)}{legend}")
    else:
        lines.append(f"step check: no artefact ({change}){legend}")
    return lines


def percent(x: float, digits: int = 2) -> str:
    """``x`` as a percentage; 2 decimals so a bound never rounds onto a threshold."""
    return f"{x:.{digits}%}"


def interval(r: Rate) -> str:
    """``[lo, hi]`` in percent."""
    return f"[{percent(r.interval[0])}, {percent(r.interval[1])}]"


def rate_table(rates: Sequence[Rate], column: tuple[str, dict[str, str]] | None = None) -> list[str]:
    """One line per rate: right / trials, the rate, its 95% interval, the threshold and verdict
    (``-`` for a rate that is shown, not judged); ``column`` adds a (header, cells by name)."""
    width = max(4, *(len(r.name) for r in rates))
    right = max(5, *(len(f"{r.k}/{r.n}") for r in rates))
    head = f"{'':>{width}} {'right':>{right}} {'rate':>8}  {'95% interval':<20} {'needs':>7}  verdict"
    lines = [head + (f"  {column[0]:>8}" if column else "")]
    for r in rates:
        needs = "-" if r.threshold is None else f">= {r.threshold:.0%}"
        line = (f"{r.name:>{width}} {f'{r.k}/{r.n}':>{right}} {percent(r.rate):>8}  {interval(r):<20} "
                f"{needs:>7}  {r.verdict or '-':<9}")
        lines.append(line + (f"  {column[1].get(r.name, ''):>8}" if column else "").rstrip())
    return [line.rstrip() for line in lines]


def hint(r: Rate, unit: str) -> str:
    """What would decide the undecided rate ``r``."""
    if r.trials_to_decide is not None:
        return (f"{r.name} is undecided: if its rate of {percent(r.rate, 1)} holds, --trials "
                f"{r.trials_to_decide} ({unit}) would decide it")
    if r.rate == r.threshold:
        return (f"{r.name} is undecided: its rate equals the threshold ({percent(r.rate, 1)}), so no "
                "number of trials decides it")
    return f"{r.name} is undecided: its rate is too close to the threshold for any practical number of trials"
