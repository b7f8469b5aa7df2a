"""Beer's categorical perception: does an evolved CTRNN catch circles and avoid diamonds at
positions it was never trained on?

Each seed runs the ``categorical-perception`` preset (``dnnevo presets``): a population of
7-neuron CTRNNs (neurons 0 and 1 the left and right motors) evolved on Beer's performance measure (:class:`dnnevo.classic.CategoricalPerception`), each generation on
``--episodes`` fresh falls (half circles, half diamonds, at random offsets within ±50, the same
for every network). Its champion is the network that classified best the run's validation set
of 40 other random falls (``--no-validation``: the best by training fitness, which is often the
luckiest draw). It is then tested on the grid of every whole offset from -50 to
50 with both shapes (202 falls), once at the training step (0.1) and once at half of it (0.05,
world and network alike): a behaviour that only exists at the coarse step is an artefact::

    python examples/categorical_perception.py --seeds 10 --out categorical.png
    python examples/categorical_perception.py --seeds 10 --no-validation    # the same evolutions

prints one row per seed (the falls classified correctly at each step, with the 95% Wilson
interval, and the mean performance), how many seeds classify at least 90% correctly at both
steps, with its interval, the median count, how far the two steps differ, the range of Beer's
performance and the best seed, and draws each seed's accuracy and the best seed's paths: the
object's offset from the agent as it falls, circles and diamonds apart. ``--record JSON`` also
writes the table and those lines for the docs (:mod:`dnnevo.experiments.examples`).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

import dnnevo
from dnnevo import plot, presets
from dnnevo.classic import CategoricalPerception
from dnnevo.classic import categorical as cp
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.runs import save_figure

DT = 0.1  # the preset's step: one Euler step of the network and the world per control step
FINE_DT = 0.05
CANDIDATES = dnnevo.EvolutionConfig().validation_candidates


def config(population: int, generations: int, episodes: int, candidates: int) -> dnnevo.EvolutionConfig:
    """The ``categorical-perception`` preset with this script's options."""
    overrides = [f"population={population}", f"generations={generations}",
                 f"task_params.episodes={episodes}", f"validation_candidates={candidates}"]
    return presets.get("categorical-perception", overrides=overrides)


def one_seed(seed: int, population: int, generations: int, episodes: int,
             candidates: int = CANDIDATES) -> dict[str, Any]:
    """Evolves one seed and tests its champion on the grid at both steps."""
    started = time.perf_counter()
    result = dnnevo.evolve("categorical-perception", config(population, generations, episodes, candidates),
                           seed=seed, progress=False)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    correct, total, performance = cp.grid_accuracy(result.best, dt=DT)
    fine, _, fine_performance = cp.grid_accuracy(result.best, dt=FINE_DT)
    return {"seed": seed, "network": result.best, "correct": correct, "fine": fine,
            "total": total, "performance": performance, "fine_performance": fine_performance,
            "seconds": time.perf_counter() - started}


def _interval(k: int, n: int) -> str:
    lo, hi = wilson(k, n)
    return f"{k:3d}/{n} ({lo:.0%}-{hi:.0%})"


def best_seed(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The seed that classifies most falls at both steps together (then by performance)."""
    return max(rows, key=lambda r: (r["correct"] + r["fine"], r["performance"]))


def summary(rows: list[dict[str, Any]]) -> list[str]:
    """The lines that sum the seeds up."""
    need = CategoricalPerception.success_rate
    good = sum(min(r["correct"], r["fine"]) >= need * r["total"] for r in rows)
    lo, hi = wilson(good, len(rows))
    total = rows[0]["total"]
    apart = max(rows, key=lambda r: abs(r["correct"] - r["fine"]))
    performance = [r["performance"] for r in rows]
    return [f"{good} of {len(rows)} seeds classify at least {need:.0%} of the grid correctly at both "
            f"steps (95% interval {lo:.0%}-{hi:.0%})",
            f"median correct at dt {DT}: {np.median([r['correct'] for r in rows]):.0f} of {total}",
            f"largest difference between the two steps: {abs(apart['correct'] - apart['fine'])} "
            f"falls (seed {apart['seed']})",
            f"Beer's performance: {min(performance):.3f} to {max(performance):.3f}",
            f"best seed at both steps (the figure draws its paths): {best_seed(rows)['seed']}"]


def figure(rows: list[dict[str, Any]], path: Path) -> None:
    fig, (bars, circles, diamonds) = plot.subplots(
        1, 3, figsize=(12, 3.8), layout="constrained", gridspec_kw={"width_ratios": [1.4, 1, 1]})
    seeds = np.array([r["seed"] for r in rows])
    for shift, key, label in ((-0.2, "correct", f"dt {DT}"), (0.2, "fine", f"dt {FINE_DT}")):
        rates = np.array([r[key] / r["total"] for r in rows])
        ci = np.array([wilson(r[key], r["total"]) for r in rows]).T
        bars.bar(seeds + shift, rates, width=0.4, label=label)
        bars.errorbar(seeds + shift, rates, yerr=[rates - ci[0], ci[1] - rates], fmt="none",
                      ecolor="k", lw=0.8)
    bars.axhline(CategoricalPerception.success_rate, color="k", lw=0.8, ls="--")
    bars.set_ylim(0, 1)
    bars.set_xlabel("seed")
    bars.set_ylabel("falls classified correctly (202)")
    bars.legend(loc="lower right", fontsize=8)
    best = best_seed(rows)
    height, offset, ok = cp.paths(best["network"], dt=DT)
    for ax, shape, colour in ((circles, 0, "tab:blue"), (diamonds, 1, "tab:red")):
        for e in range(shape, len(offset), 2):
            ax.plot(offset[e], height, lw=0.7, ls="-" if ok[e] else ":",
                    color=colour if ok[e] else "k")
        ax.set_xlabel("object's offset from the agent")
        ax.set_title(f"seed {best['seed']}: {'circles' if shape == 0 else 'diamonds'} "
                     f"({ok[shape::2].sum()}/{len(ok[shape::2])} right; dotted: wrong)", fontsize=9)
    circles.set_ylabel("object's height")
    save_figure(fig, path)
    plot.close(fig)


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=int, default=10, help="seeds 0 .. N-1 (default 10)")
    p.add_argument("--population", type=int, default=100)
    p.add_argument("--generations", type=int, default=300)
    p.add_argument("--episodes", type=int, default=16,
                   help="falls per network per generation, half of each shape (default 16)")
    p.add_argument("--no-validation", action="store_true",
                   help="choose each seed's champion by training fitness, not on the validation "
                        "set of 40 falls")
    p.add_argument("--out", type=Path, help="write the figure here")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="also write the table here, for the docs "
                        "(docs/results/examples/categorical.json)")
    args = p.parse_args(argv)
    candidates = 0 if args.no_validation else CANDIDATES
    if args.seeds < 1:
        p.error(f"--seeds is {args.seeds}; it must be at least 1")
    if args.episodes < 2 or args.episodes % 2:
        p.error(f"--episodes is {args.episodes}; it must be an even number >= 2")
    rows = []
    print(f"seed  correct at dt {DT}       correct at dt {FINE_DT}      performance  seconds")
    for seed in range(args.seeds):
        r = one_seed(seed, args.population, args.generations, args.episodes, candidates)
        rows.append(r)
        print(f"{seed:4d}  {_interval(r['correct'], r['total'])}  "
              f"{_interval(r['fine'], r['total'])}  {r['performance']:11.3f}  "
              f"{r['seconds']:7.0f}", flush=True)
    lines = summary(rows)
    print("\n".join(lines))
    if args.record:
        table = [[r["seed"], f"{r['correct']}/{r['total']}", f"{r['fine']}/{r['total']}",
                  f"{r['performance']:.3f}"] for r in rows]
        examples.write(args.record, command=examples.command("examples/categorical_perception.py", argv),
                       columns=["seed", f"correct, dt {DT}", f"correct, dt {FINE_DT}", "Beer's performance"],
                       rows=table, summary=lines)
    if args.out:
        figure(rows, args.out)


if __name__ == "__main__":
    main()
