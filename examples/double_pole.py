"""Double-pole balancing without velocities, the classic neuroevolution benchmark: how many
network evaluations dnnevo's GA needs before a CTRNN solves it.

Each seed evolves a population of 5-neuron CTRNNs on Gruau et al.'s damping fitness
(:class:`dnnevo.classic.DoublePole`, one 1,000-step episode from the standard start). Whenever
the champion changes and has balanced a whole training episode, it takes the benchmark's test
(:func:`dnnevo.classic.double_pole.solves`): at least 200 of the 625 generalisation starts, and
100,000 steps from the standard start. The evaluations a seed needed are the population size times
the generations run when its champion first passed; a seed that spends ``--budget`` evaluations
without passing counts as not solved::

    python examples/double_pole.py --seeds 10 --out double-pole.png
    python examples/double_pole.py --seeds 10 --velocities    # the Markovian task

prints one row per seed (evaluations, and the best generalisation score of a tested champion with
its long-test steps, 0 where the long test did not run), the solved count with its 95% Wilson
interval and the median evaluations of the solved seeds, and draws each seed's best
generalisation score.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

import dnnevo
from dnnevo import plot
from dnnevo.classic import DoublePole
from dnnevo.classic import double_pole as dp
from dnnevo.closedloop import ClosedLoop
from dnnevo.evaluation.stats import wilson
from dnnevo.runs import save_figure

SIZE = 5
BALANCED_EPISODE = 0.1  # the damping fitness of a whole 1,000-step episode is above 0.1


def config(population: int, generations: int, velocities: bool) -> dnnevo.EvolutionConfig:
    return dnnevo.EvolutionConfig(population=population, generations=generations, size=SIZE,
                                  n_inputs=6 if velocities else 3, selection="rank", elitism=5,
                                  mutation_rate=0.05, validation_candidates=0)


def one_seed(seed: int, population: int, budget: int, velocities: bool = False) -> dict[str, Any]:
    """Evolves until the champion solves the task or ``budget`` evaluations are spent."""
    tested: dict[int, tuple[bool, int, int]] = {}
    found: dict[str, int] = {}

    def check(stats: dict[str, float], ga: dnnevo.GeneticAlgorithm) -> bool:
        generation = ga.best_generation
        if ga.best is None or generation is None or generation in tested:
            return False
        if (ga.best_fitness or 0.0) <= BALANCED_EPISODE:
            return False
        tested[generation] = dp.solves(ga.best, velocities=velocities)
        if tested[generation][0]:
            found["evaluations"] = population * ga.generation
            return True
        return False

    started = time.perf_counter()
    fitness = ClosedLoop(DoublePole(velocities=velocities), episodes=1,
                         max_steps=dp.GENERALIZATION_STEPS)
    result = dnnevo.evolve(fitness, config(population, budget // population, velocities), seed=seed,
                           progress=False, callback=check)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    # The champion that solved it, else the one that came closest.
    best = max(tested.values(), key=lambda t: (t[0], t[2], t[1]), default=(False, 0, 0))
    return {"seed": seed, "evaluations": found.get("evaluations"), "long": best[1],
            "generalization": best[2], "tests": len(tested),
            "seconds": time.perf_counter() - started}


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=int, default=10, help="seeds 0 .. N-1 (default 10)")
    p.add_argument("--population", type=int, default=100)
    p.add_argument("--velocities", action="store_true",
                   help="the Markovian task: the network also senses the three velocities")
    p.add_argument("--budget", type=int, default=50_000, help="evaluations per seed (default 50000)")
    p.add_argument("--out", type=Path, help="write the figure here")
    args = p.parse_args(argv)
    rows = []
    print("seed  evaluations  generalisation  long-test steps  tests  seconds")
    for seed in range(args.seeds):
        r = one_seed(seed, args.population, args.budget, args.velocities)
        rows.append(r)
        shown = r["evaluations"] if r["evaluations"] is not None else f">{args.budget}"
        print(f"{seed:4d}  {shown!s:>11}  {r['generalization']:14d}  {r['long']:15d}  "
              f"{r['tests']:5d}  {r['seconds']:7.0f}", flush=True)
    solved = [r["evaluations"] for r in rows if r["evaluations"] is not None]
    lo, hi = wilson(len(solved), len(rows))
    print(f"solved {len(solved)} of {len(rows)} seeds within {args.budget} evaluations "
          f"(95% interval {lo:.0%}-{hi:.0%})")
    if solved:
        print(f"median evaluations of the solved seeds: {np.median(solved):.0f}")
    if args.out:
        fig, ax = plot.subplots(figsize=(7, 3.5), layout="constrained")
        ax.bar([r["seed"] for r in rows], [r["generalization"] for r in rows],
               color=["tab:green" if r["evaluations"] is not None else "tab:gray" for r in rows])
        ax.axhline(dp.GENERALIZATION_NEEDED, color="k", lw=0.8, ls="--",
                   label="200 of 625: the generalisation test")
        ax.set_ylim(0, len(dp.GRID))
        ax.set_xlabel("seed")
        ax.set_ylabel("best champion's generalisation score")
        task = "with velocities" if args.velocities else "no velocities"
        ax.set_title(f"double pole, {task}: {len(solved)}/{len(rows)} solved within "
                     f"{args.budget} evaluations")
        ax.legend(loc="lower right", fontsize=8)
        save_figure(fig, args.out)
        plot.close(fig)


if __name__ == "__main__":
    main()
