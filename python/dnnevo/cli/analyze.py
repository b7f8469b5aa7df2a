"""The ``dnnevo analyze`` command: a run's champion explained by its attractors (see
:mod:`dnnevo.analysis`). It writes ``analysis.json`` and three figures into the run folder, each
atomically, and prints a summary."""

from __future__ import annotations

import argparse
import contextlib
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from dnnevo import _core, analysis, plot
from dnnevo.analysis import Attractors, Bifurcation, LesionTable
from dnnevo.closedloop import named
from dnnevo.config import EvolutionConfig
from dnnevo.errors import InvalidArgumentError, counted
from dnnevo.cli.outputs import try_write
from dnnevo.runs import RunDir, save_figure, write_atomic
from dnnevo.tasks.protocol import Task, views

EXAMPLE = """examples:
  dnnevo run sequence-1bit --quick --out runs/demo && dnnevo analyze runs/demo
  dnnevo analyze runs/demo --input 0,0 --input 0,1 --neurons 0,2
  dnnevo analyze runs/demo --sweep 0:1 --sweep-input 1 --sweep-cycles --no-lesions
  dnnevo run predator-avoidance --quick --out runs/pa && dnnevo analyze runs/pa

A Python task ("python:module.Class") is analysed when its class declares an
analysis = dnnevo.tasks.protocol.Analysis(...): its input names, default --input vectors, main
input, output neuron, how many fresh episodes to record, and views of its own (predator
avoidance: what the champion does when a pursuer appears, analysis-pursuer.png); its recorded
trials are fresh episodes of those 'dnnevo assess' judges with --seed, and its lesions are
judged by the class's success rule.

With the sensors held at each --input vector (default: the task's own conditions; for the
built-in tasks all off, then each input on alone), the champion is an autonomous dynamical system: its equilibria (stable node or focus,
saddle, unstable) and attracting limit cycles are found and printed (an equilibrium's time scale is
1 / min |Re lambda| over its eigenvalues, in the units of tau: how slowly its slowest direction
moves). --sweep varies one input
(default: the task's main one), the others held at the first --input vector's values, and marks folds (F: two equilibria meet and vanish) and Hopf
points (H: a complex pair of eigenvalues crosses the imaginary axis, where a cycle appears or
vanishes); --sweep-cycles also follows the attracting cycles along it,
each branch from where it appears to where it vanishes. Lesions clamp each
neuron at its mean firing rate over real trials, and cut the N strongest connections, then judge
the champion on the same fresh trials as 'dnnevo assess'. See docs/analysis.md. Written into the run folder: analysis.json, analysis-phase.png (firing rates of
two neurons, those that vary most unless --neurons, with a real trial, equilibria by stability, cycles,
and nullclines for 2 neurons), analysis-bifurcation.png (the firing rate of the neuron whose
equilibria move most), analysis-basins.png (the recorded trials over time, on a background that
says which attractor of the first --input the state would settle in if that input were held
from then on) and analysis-lesions.png; one of these that an earlier analysis drew and this one
does not (--no-lesions) is removed."""

FIGURES = ("analysis-phase.png", "analysis-bifurcation.png", "analysis-lesions.png", "analysis-basins.png")
"""The figures ``analyze`` itself draws (a task's views add their own)."""

DEFAULT_LESION_TRIALS = 200


def add_parser(sub: Any) -> None:
    """Adds ``analyze`` to the subcommands."""
    p = sub.add_parser("analyze", help="explain a champion by its attractors; write analysis.json and figures",
                       description="Explain a run's champion by its dynamics: equilibria, limit cycles, a "
                                   "bifurcation sweep of one input, and lesions.",
                       epilog=EXAMPLE, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("dir", type=Path)
    p.add_argument("--input", action="append", default=[], metavar="V,V",
                   help="a constant input vector to analyse under (repeatable), e.g. 0,1")
    p.add_argument("--neurons", metavar="I,J", help="the two neurons of the phase portrait")
    p.add_argument("--sweep", metavar="START:STOP", default="0:1", help="the swept input's range (default 0:1); a negative start is written --sweep=-1:1")
    p.add_argument("--sweep-input", type=int, metavar="K", help="which input to sweep (default: the task's main one); "
                                                                     "the others keep the first --input's values")
    p.add_argument("--steps", type=int, default=101, help="input values in the sweep (default 101)")
    p.add_argument("--sweep-cycles", action="store_true",
                   help="also search each swept value for limit cycles (4 starts; about 100x slower)")
    p.add_argument("--trials", type=int, default=DEFAULT_LESION_TRIALS,
                   help=f"fresh trials per lesion, in 'dnnevo assess --trials' units (default {DEFAULT_LESION_TRIALS})")
    p.add_argument("--cuts", type=int, default=None, help="strongest connections to cut (default N)")
    p.add_argument("--seed", type=int, default=0, help="seed of the trials shown and judged (default 0)")
    p.add_argument("--no-lesions", dest="lesions", action="store_false", help="skip the lesions")


def _vector(text: str, what: str) -> list[float]:
    if not text.strip():
        return []  # the input of a network without sensors
    try:
        return [float(x) for x in text.split(",")]
    except ValueError:
        raise InvalidArgumentError(f"{what} {text!r} is not a comma-separated list of numbers") from None


def _pair(text: str, n: int) -> tuple[int, int]:
    try:
        i, j = (int(x) for x in text.split(","))
    except ValueError:
        raise InvalidArgumentError(f"--neurons {text!r} is not two neuron indices such as 0,2") from None
    if not (0 <= i < n and 0 <= j < n and i != j):
        raise InvalidArgumentError(f"--neurons {text!r}: need two different neurons in 0..{n - 1}")
    return i, j


def _range(text: str) -> tuple[float, float]:
    try:
        a, b = (float(x) for x in text.split(":"))
    except ValueError:
        raise InvalidArgumentError(f"--sweep {text!r} is not a range such as 0:1") from None
    return a, b


def analyze(args: argparse.Namespace) -> int:
    """``dnnevo analyze``."""
    started = time.perf_counter()
    run = RunDir(args.dir)
    config, raw = run.read_run_config()
    named.refuse_fitness_function(
        config, args.dir, "whose trials the command line cannot record; analyse the champion from "
        "Python: dnnevo.analysis.attractors(dnnevo.Network.load(path), inputs) (docs/analysis.md)")
    named.check_own_task(config, raw)
    net = run.read_best(config, raw)
    m = net.n_inputs
    task = analysis.analysed_task(config)
    if args.steps < 2:
        raise InvalidArgumentError(f"--steps is {args.steps}; a sweep needs at least 2 input values")
    if args.trials < 1:
        raise InvalidArgumentError(f"--trials is {args.trials}; it must be >= 1")
    if args.seed < 0:
        raise InvalidArgumentError(f"--seed is {args.seed}; it must be >= 0")
    if args.input:
        conditions = {text: _vector(text, "--input") for text in args.input}
    else:
        conditions = {name: v[:m] for name, v in task.ANALYSIS_CONDITIONS.items()}
    for name, v in conditions.items():
        if len(v) != m:
            raise InvalidArgumentError(f"--input {name} has {counted(len(v), 'value')}; this network has "
                                       f"{counted(m, 'sensor')}")
    found = [analysis.attractors(net, v, name) for name, v in conditions.items()]

    trials = analysis.recorded_trials(config, net, seed=args.seed)
    outputs = np.vstack([o for o, _ in trials])
    basins = _basins(config, net, trials, found[0])
    output = output_neuron(config, task)
    if args.neurons:
        neurons = _pair(args.neurons, net.size)
    else:
        order = np.argsort(-outputs.var(axis=0), kind="stable")
        neurons = (int(order[0]), int(order[1])) if net.size > 1 else (0, 0)

    start, stop = _range(args.sweep)
    bif, name = None, "no input"  # a network without sensors has no input to sweep
    if m > 0:
        index, name = task.MAIN_INPUT, task.INPUT_NAMES[task.MAIN_INPUT]
    if args.sweep_input is not None:
        if not 0 <= args.sweep_input < m:
            where = f"the network's inputs are 0..{m - 1}" if m else "the network has no inputs"
            raise InvalidArgumentError(f"--sweep-input is {args.sweep_input}; {where}")
        index, name = args.sweep_input, f"input {args.sweep_input}"
    if m > 0:
        # The other inputs are held at the first condition's values, as in the basins figure.
        bif = analysis.bifurcation(net, index, start, stop, input=found[0].input, steps=args.steps,
                                   cycle_starts=4 if args.sweep_cycles else 0)

    table = analysis.lesions(config, net, args.trials, seed=args.seed, cuts=args.cuts) if args.lesions else None
    seen = [view(config, net, args.seed, run.path.name) for view in views(task)]
    elapsed = time.perf_counter() - started

    stable = [e for e in found[0].equilibria if e.stable]
    doc = {
        "format": "dnnevo-analysis", "version": 1, "run": str(args.dir), "task": config.task,
        "size": net.size, "seed": args.seed, "neurons": list(neurons),
        "conditions": [a.to_dict() for a in found],
        "bifurcation": None if bif is None else {"input_name": name, "shown_neuron": _moving_neuron(bif),
                                                 **bif.to_dict()},
        "lesions": table.to_dict() if table else None,
        "trial_basins": {"input": found[0].input.tolist(), "attractors": [e.outputs.tolist() for e in stable],
                         "every": basins[0], "basins": basins[1].tolist()},
        **{v.key: v.doc for v in seen},
        "elapsed_s": elapsed,
    }
    text = json.dumps(doc, indent=1) + "\n"
    written = ["analysis.json"] if try_write(lambda: write_atomic(run.path / "analysis.json", text)) else []
    written += _figures(run, net, found, bif, table, outputs, neurons, name)
    written += _basin_figure(run, task, trials, basins, found[0], bif, name, output)
    for view_result in seen:
        for file, fig in view_result.figures.items():
            if try_write(lambda: save_figure(fig, run.path / file)):
                written.append(file)
            plot.close(fig)
    # A figure of an earlier analysis that this one did not draw (--no-lesions) would sit beside
    # an analysis.json that does not describe it. Only analyze's own names are removed.
    stale = [f for f in FIGURES if f not in written and (run.path / f).is_file()]
    for file in stale:
        with contextlib.suppress(OSError):
            (run.path / file).unlink()
    print("\n".join(summary(found, bif, table, name, basins, output=output)
                    + [line for v in seen for line in v.lines]))
    wrote = ", ".join(str(run.path / w) for w in written) if written else "nothing"
    print(f"analysed in {elapsed:.1f} s; wrote {wrote}"
          + (f"; removed the earlier analysis's {', '.join(stale)}" if stale else ""))
    return 0


def _figures(run: RunDir, net: _core.Network, found: list[Attractors], bif: Bifurcation | None,
             table: LesionTable | None, outputs: np.ndarray, neurons: tuple[int, int], label: str) -> list[str]:
    written = []
    n_lesions = len(table.lesions) if table is not None else 0
    for name, size in (("analysis-phase.png", (7.0, 5.5)), ("analysis-bifurcation.png", (7.0, 4.0)),
                       ("analysis-lesions.png", (7.0, 1.5 + 0.22 * n_lesions))):
        if name == "analysis-lesions.png" and table is None or name == "analysis-bifurcation.png" and bif is None:
            continue
        fig, ax = plot.subplots(figsize=size, layout="constrained")
        if name == "analysis-phase.png":
            analysis.plot_phase_portrait(found, ax, net=net, neurons=neurons, trajectory=outputs,
                                title=f"{run.path.name}: attractors under each input, and a real trial")
        elif name == "analysis-bifurcation.png" and bif is not None:
            analysis.plot_bifurcation(bif, ax, neuron=_moving_neuron(bif), xlabel=label,
                             title=f"{run.path.name}: equilibria as {label} varies")
        elif table is not None:
            analysis.plot_lesions(table, ax, title=f"{run.path.name}: lesions")
        if try_write(lambda: save_figure(fig, run.path / name)):
            written.append(name)
        plot.close(fig)
    return written


def output_neuron(config: EvolutionConfig, task: Task) -> int:
    """The neuron whose firing rate is ``config``'s task's answer (``task``, as
    :func:`dnnevo.analysis.analysed_task` reads it)."""
    return int(config.task_params.get("classifier", task.OUTPUT_NEURON))


BASIN_STATES = 1500
"""The most trial steps whose basin is computed; longer recordings are subsampled evenly."""


def _basins(config: EvolutionConfig, net: _core.Network, trials: list[tuple[np.ndarray, np.ndarray]],
            off: Attractors) -> tuple[int, np.ndarray]:
    """Every ``every``-th step of the recorded trials: which stable equilibrium of the first
    condition the state would settle in (-1: none)."""
    states = np.vstack([analysis.replay(config, net, i) for _, i in trials])
    every = max(1, -(-len(states) // BASIN_STATES))
    stable = [e for e in off.equilibria if e.stable]
    return every, analysis.settles_to(net, states[::every], stable, off.input)


def _basin_figure(run: RunDir, task: Task, trials: list[tuple[np.ndarray, np.ndarray]],
                  basins: tuple[int, np.ndarray], off: Attractors, bif: Bifurcation | None, name: str,
                  neuron: int) -> list[str]:
    every, which = basins
    outputs = np.vstack([o for o, _ in trials])[::every]
    inputs = np.vstack([i for _, i in trials])[::every]
    names = task.INPUT_NAMES
    starts = np.cumsum([0] + [len(o) for o, _ in trials])[1:-1] // every
    stable = [e for e in off.equilibria if e.stable]
    labels = [f"{chr(65 + k)} (neuron {neuron} at {e.outputs[neuron]:.2f})" for k, e in enumerate(stable)]
    fig, ax = plot.subplots(figsize=(9.0, 3.6), layout="constrained")
    analysis.plot_basins(outputs, {names[k]: inputs[:, k] for k in range(inputs.shape[1])}, which, ax, labels=labels,
                neuron=neuron, boundaries=list(starts), levels=[e.value for e in bif.events if e.kind == "fold"] if bif else [],
                level_label=f"folds of the {name} sweep",
                title=f"{run.path.name}: recorded trials; background: where the state would settle "
                      f"with input {off.label}")
    saved = try_write(lambda: save_figure(fig, run.path / "analysis-basins.png"))
    plot.close(fig)
    return ["analysis-basins.png"] if saved else []


def _moving_neuron(bif: Bifurcation) -> int:
    """The neuron whose equilibrium firing rate spans the widest range over the sweep (the lowest
    index among equals, 0 when nothing moves)."""
    rates = np.array([e.outputs for row in bif.equilibria for e in row])
    if rates.size == 0:
        return 0
    return int(np.argmax(np.ptp(rates, axis=0)))


def event_texts(events: list[analysis.Event]) -> list[str]:
    """Each event as "fold at 0.4374"; events that would read the same get more digits and the
    firing rate of the neuron that tells them apart (two folds at one value are two pairs)."""
    texts = [f"{e.kind} at {e.value:.4g}" for e in events]
    for text in set(texts):
        group = [k for k, t in enumerate(texts) if t == text]
        if len(group) < 2:
            continue
        digits = next((d for d in range(5, 13) if len({f"{events[k].value:.{d}g}" for k in group}) == len(group)), 12)
        rates = np.array([events[k].outputs for k in group])
        neuron = int(np.argmax(np.ptp(rates, axis=0))) if rates.size else None
        for k in group:
            e = events[k]
            where = f" (neuron {neuron} at {e.outputs[neuron]:.2f})" if neuron is not None else ""
            texts[k] = f"{e.kind} at {e.value:.{digits}g}{where}"
    return texts


def _end_text(end: analysis.CycleEnd | None, edge: str, events: list[analysis.Event],
              period: float | None = None) -> str:
    """A cycle branch's end, with the period there (and ``period``, the one at the nearest swept
    value); a lost one names the folds between its two swept values (a cycle lost at a fold of
    equilibria, its period growing, may end on a saddle-node on the cycle)."""
    if end is None:
        return edge
    if end.kind == "hopf":
        return f"a Hopf point at {end.value:.4g} (period {end.period:.3g})"
    lo, hi = sorted((end.with_cycle, end.without_cycle))
    folds = [e.value for e in events if e.kind == "fold" and lo <= e.value <= hi]
    there = f"; fold{'s' * (len(folds) > 1)} at {', '.join(f'{v:.4g}' for v in folds)} there" if folds else ""
    was = f", {period:.3g} at {end.with_cycle:g}" if period is not None else ""
    return (f"{end.value:.4g} (found at {end.with_cycle:g}, gone at {end.without_cycle:g}{there}; "
            f"period {end.period:.3g} there{was})")


def _eq_line(e: analysis.Equilibrium, letter: str = "") -> str:
    rates = " ".join(f"{o:.2f}" for o in e.outputs)
    scale = f", time scale {e.time_scale:.3g}" if e.time_scale is not None else ""
    return f"  {letter:<2}{e.stability.replace('_', ' '):<15} outputs [{rates}]{scale}"


def letters(a: Attractors) -> dict[int, str]:
    """The names A, B, C, ... of ``a``'s stable equilibria, in their order (the index of each in
    ``a.equilibria``), as the basins' summary line and figure call them."""
    stable = [k for k, e in enumerate(a.equilibria) if e.stable]
    return {k: chr(65 + i) for i, k in enumerate(stable)}


def _sweep_lines(bif: Bifurcation, name: str) -> list[str]:
    """The bifurcation sweep of ``name`` in words."""
    events = ", ".join(event_texts(bif.events)) or "none"
    others = [f"{x:g}" for k, x in enumerate(bif.input) if k != bif.index]
    held = f" (the other inputs held at {','.join(others)})" if others else ""
    lines = [f"sweep of {name} from {bif.values[0]:g} to {bif.values[-1]:g}{held}: {events}"]
    if bif.retried:
        lines.append(f"    searched again with {analysis.RETRY_STARTS} starts at {len(bif.retried)} value"
                     f"{'s' * (len(bif.retried) != 1)} where the count of equilibria was even")
    if bif.even:
        shown = ", ".join(f"{v:g}" for v in bif.even[:8]) + (", ..." if len(bif.even) > 8 else "")
        lines.append(f"    (the count stays even at {len(bif.even)} value{'s' * (len(bif.even) != 1)} ({shown}): "
                     "equilibria were missed there, see docs/analysis.md)")
    for b in bif.branches:
        first, last = (bif.cycles[s][bif.cycle_branch[s].index(b.id)].period for s in (b.first, b.last))
        lines.append(f"    cycle branch {b.id}: from {_end_text(b.start, 'the sweep start', bif.events, first)} "
                     f"to {_end_text(b.end, 'the sweep end', bif.events, last)}")
    return lines


def summary(found: list[Attractors], bif: Bifurcation | None, table: LesionTable | None, name: str,
            basins: tuple[int, np.ndarray] | None = None, *, output: int | None = None) -> list[str]:
    """The printed report. The first condition's stable equilibria are named A, B, ... (as in
    analysis-basins.png); ``output`` is the neuron whose firing rate is the task's answer."""
    lines = []
    named = letters(found[0]) if found else {}
    for i, a in enumerate(found):
        stable = sum(e.stable for e in a.equilibria)
        names = f": {', '.join(named.values())}" if i == 0 and named else ""
        lines.append(f"input {a.label} [{', '.join(f'{x:g}' for x in a.input)}]: {len(a.equilibria)} equilibria "
                     f"({stable} stable{names}), {len(a.cycles)} attracting cycle{'s' * (len(a.cycles) != 1)}")
        if len(a.equilibria) % 2 == 0:
            lines.append("    (an even count: at least one equilibrium was missed, see docs/analysis.md)")
        lines += [_eq_line(e, named.get(k, "") if i == 0 else "") for k, e in enumerate(a.equilibria[:12])]
        if len(a.equilibria) > 12:
            lines.append(f"    ... {len(a.equilibria) - 12} more in analysis.json")
        for c in a.cycles:
            lines.append(f"    cycle: period {c.period:.3g}, neuron 0's state between "
                         f"{np.min(c.orbit[:, 0]):.3g} and {np.max(c.orbit[:, 0]):.3g}, "
                         f"largest Floquet multiplier besides the trivial 1: {c.max_multiplier:.3g}")
    lines += _sweep_lines(bif, name) if bif is not None else ["no sweep: the network has no input to vary"]
    if basins is not None:
        every, which = basins
        shares = ", ".join(f"{chr(65 + k)} {np.mean(which == k):.0%}" for k in range(int(which.max(initial=-1)) + 1))
        off = found[0].label
        lines.append(f"recorded trials: with input {off} held from each step on, the state would settle in "
                     + (shares or "no stable equilibrium")
                     + (f", none {np.mean(which < 0):.0%}" if (which < 0).any() and shares else ""))
        if named:
            attractors = [e for e in found[0].equilibria if e.stable]
            where = ""
            if output is not None:
                where = (f" (output neuron {output} at "
                         + ", ".join(f"{e.outputs[output]:.2f} in {chr(65 + k)}" for k, e in enumerate(attractors))
                         + ")")
            kind = "equilibria" if len(named) > 1 else "equilibrium"
            lines.append(f"    {', '.join(named.values())}: the stable {kind} of input {off}, marked above{where}"
                         + ("; none: no stable equilibrium reached (a cycle, or one not found)"
                            if (which < 0).any() else ""))
    if table is not None:
        # The lesions' score is a judged success rate (the weakest target's), not the fitness.
        lines.append(f"lesions ({table.trials} fresh trials, seed {table.seed}): intact rate "
                     f"{table.score:.3f} ({table.verdict})")
        for x in sorted(table.lesions, key=lambda x: -x.drop)[:8]:
            lines.append(f"    {x.name:<22} rate {x.score:.3f}  drop {x.drop:+.3f}  {x.verdict}")
    return lines
