"""Double-pole balancing without velocities, the classic neuroevolution benchmark: how many
episodes dnnevo's GA runs before a CTRNN solves it.

Each seed runs the ``double-pole`` preset (``dnnevo presets``; change it with ``--set
key=value``) on :class:`dnnevo.classic.DoublePole`. Whenever the champion changes and has
balanced at least half of its training steps, it takes the benchmark's test
(:func:`dnnevo.classic.double_pole.solves`): at least 200 of the 625 generalisation starts, and
100,000 steps from the standard start. A seed's cost is the episodes it ran until its champion
first passed, training and validation together (an episode is one of the benchmark's
evaluations: up to 1,000 steps of one network); a seed that spends ``--budget`` episodes without
passing counts as not solved::

    python examples/double_pole.py --seeds 20 --out double-pole.png
    python examples/double_pole.py --seeds 10 --velocities    # the Markovian task
    python examples/double_pole.py --seeds 10 --set task_params.start=standard --set task_params.episodes=1 \\
        --set validation_candidates=0    # the benchmark's own training: one episode from the standard start

prints one row per seed (episodes, generations, and the best generalisation score of a tested
champion with its long-test steps, 0 where the long test did not run), the solved count with its
95% Wilson interval and the median episodes of the solved seeds, and draws each seed's best
generalisation score.
"""

from __future__ import annotations

import argparse
import dataclasses
import shlex
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

import dnnevo
from dnnevo import plot, presets
from dnnevo.classic import double_pole as dp
from dnnevo.closedloop import ClosedLoop, named
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.runs import save_figure

PRESET = "double-pole"
TESTED = 0.05  # a champion takes the test once its mean training fitness shows 500 balanced steps


class Counted:
    """A closed-loop task that counts the episodes it runs, for training and for validation."""

    def __init__(self, loop: ClosedLoop) -> None:
        self.loop, self.episodes = loop, 0

    def __call__(self, networks: Sequence[dnnevo.Network], *, generation: int = 0,
                 seed: int = 0) -> np.ndarray:
        self.episodes += len(networks) * self.loop.settings["episodes"]
        return self.loop(networks, generation=generation, seed=seed)

    def validate(self, networks: Sequence[dnnevo.Network], *, seed: int) -> tuple[np.ndarray, np.ndarray]:
        self.episodes += len(networks) * self.loop.validation_episodes
        return self.loop.validate(networks, seed=seed)


def config(budget: int, overrides: Sequence[str]) -> dnnevo.EvolutionConfig:
    """The preset with ``overrides``, and generations enough for ``budget`` training episodes."""
    base = presets.get(PRESET, overrides=list(overrides))
    per_generation = base.population * int(base.task_params.get("episodes", 1))
    return presets.get(PRESET, overrides=[*overrides, f"generations={-(-budget // per_generation)}"])


def one_seed(seed: int, budget: int, overrides: Sequence[str]) -> dict[str, Any]:
    """Evolves until the champion solves the task or ``budget`` episodes are spent."""
    cfg = config(budget, overrides)
    velocities = bool(cfg.task_params.get("velocities", False))
    integrator = dataclasses.asdict(cfg.integrator)  # the test integrates as training did
    fitness = Counted(named.closed_loop(cfg))
    tested: dict[int, tuple[bool, int, int]] = {}
    found: dict[str, int] = {}

    def check(stats: dict[str, float], ga: dnnevo.GeneticAlgorithm) -> bool:
        if fitness.episodes >= budget:
            return True
        generation = ga.best_generation
        if ga.best is None or generation is None or generation in tested:
            return False
        if (ga.best_fitness or 0.0) < TESTED:
            return False
        tested[generation] = dp.solves(ga.best, velocities=velocities, **integrator)
        if tested[generation][0]:
            found.update(episodes=fitness.episodes, generations=ga.generation)
            return True
        return False

    started = time.perf_counter()
    result = dnnevo.evolve(fitness, cfg, seed=seed, progress=False, callback=check)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    # The champion that solved it, else the one that came closest.
    best = max(tested.values(), key=lambda t: (t[0], t[2], t[1]), default=(False, 0, 0))
    return {"seed": seed, "episodes": found.get("episodes"), "generations": found.get("generations"),
            "long": best[1], "generalization": best[2], "tests": len(tested),
            "seconds": time.perf_counter() - started}


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number >= 1")
    return value


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=_positive, default=20, help="seeds 0 .. N-1 (default 20)")
    p.add_argument("--velocities", action="store_true",
                   help="the Markovian task: the network also senses the three velocities")
    p.add_argument("--budget", type=_positive, default=100_000,
                   help="episodes per seed, training and validation (default 100000)")
    p.add_argument("--workers", type=_positive, default=1,
                   help="run this many seeds at once, each in a process of its own (default 1)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a setting of the preset (repeatable), as for dnnevo run")
    p.add_argument("--out", type=Path, help="write the figure here")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="also write the table here, for the docs (docs/results/examples/double-pole.json)")
    args = p.parse_args(argv)
    overrides = [*args.set, *(["task_params.velocities=true", "n_inputs=6"] if args.velocities else [])]
    rows = []
    print("seed     episodes  generations  generalisation  long-test steps  tests  seconds")
    for r in examples.seeds_run(one_seed, args.seeds, args.workers, args.budget, overrides):
        rows.append(r)
        shown = r["episodes"] if r["episodes"] is not None else f">{args.budget}"
        print(f"{r['seed']:4d}  {shown!s:>11}  {r['generations'] or '-'!s:>11}  {r['generalization']:14d}  "
              f"{r['long']:15d}  {r['tests']:5d}  {r['seconds']:7.0f}", flush=True)
    solved = [r["episodes"] for r in rows if r["episodes"] is not None]
    lo, hi = wilson(len(solved), len(rows))
    summary = [f"solved {len(solved)} of {len(rows)} seeds within {args.budget} episodes "
               f"(95% interval {lo:.0%}-{hi:.0%})"]
    if solved:
        summary.append(f"episodes of the solved seeds: median {np.median(solved):.0f}, "
                       f"mean {np.mean(solved):.0f}")
    print("\n".join(summary))
    if args.record:
        given = list(sys.argv[1:] if argv is None else argv)
        if "--record" in given:  # the command that makes the table, without where it was written
            del given[given.index("--record"):given.index("--record") + 2]
        given = [a for a in given if not a.startswith("--record=")]
        table = [[r["seed"], r["episodes"] or f"not within {args.budget}", r["generations"] or "-",
                  r["generalization"], r["long"]] for r in rows]
        examples.write(args.record, command=shlex.join(["python", "examples/double_pole.py", *given]),
                       columns=["seed", "episodes", "generations", "generalisation (of 625)",
                                "long test (steps)"], rows=table, summary=summary)
    if args.out:
        fig, ax = plot.subplots(figsize=(7, 3.5), layout="constrained")
        ax.bar([r["seed"] for r in rows], [r["generalization"] for r in rows],
               color=["tab:green" if r["episodes"] is not None else "tab:gray" for r in rows])
        ax.axhline(dp.GENERALIZATION_NEEDED, color="k", lw=0.8, ls="--",
                   label="200 of 625: the generalisation test")
        ax.set_ylim(0, len(dp.GRID))
        ax.set_xlabel("seed")
        ax.set_ylabel("best champion's generalisation score")
        task = "with velocities" if args.velocities else "no velocities"
        ax.set_title(f"double pole, {task}: {len(solved)}/{len(rows)} solved within "
                     f"{args.budget} episodes")
        ax.legend(loc="lower right", fontsize=8)
        save_figure(fig, args.out)
        plot.close(fig)


if __name__ == "__main__":
    main()
