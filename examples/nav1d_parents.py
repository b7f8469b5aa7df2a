"""What a near seeker brings to the single network it founds, at generation 0.

`dnnevo reproduce` seeds each `nav1d-single-incremental` run with its own seed's near seeker
(`nav1d-near-chained`) and 3 spare neurons. For each near-seeker run folder given, this builds
that run's first population exactly as `dnnevo sweep nav1d-single-incremental --seed-from RUN
--spare-neurons 3 --seeds S` does (S is the near seeker's own seed), and scores it on the
single-network task: the founder on generation 0's trials and, averaged, on the trials of
generations 1-30 (fresh chains), and the whole population (its best, its mean, and the share of
mutants that score at least as well as the founder)::

    dnnevo sweep nav1d-near --seeds 0-9 --set task_params.chained=true \\
        --set task_params.reinforcement_input=true --set n_inputs=2 --set generations=100 \\
        --threads 1 --out runs/near-chained
    python examples/nav1d_parents.py runs/near-chained/seed-{0,1,2,3,4,5,6,7,8,9}
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

import numpy as np

import dnnevo
from dnnevo import presets
from dnnevo.evolution.seeding import Seeding
from dnnevo.experiments import plan
from dnnevo.runs import RunDir

_EXPERIMENT = plan.experiment("nav1d-single-incremental")
assert _EXPERIMENT.preset is not None
PRESET, SPARE = _EXPERIMENT.preset, _EXPERIMENT.spare_neurons
FRESH_GENERATIONS = 30


def founded(run: Path) -> tuple[int, dict[str, float]]:
    """The near seeker's seed and the generation-0 figures of the run it founds."""
    _, table = RunDir(run).read_config()
    seed = int(table["seed"])
    cfg = presets.get(PRESET)
    ga = dnnevo.GeneticAlgorithm(cfg, seed=seed, founders=Seeding((run,), False, 0.0, SPARE).networks(cfg.size, seed))
    genomes = ga.ask().genomes
    scores = dnnevo.evaluate(cfg.task, genomes, generation=0, seed=seed, config=cfg)
    fresh = [dnnevo.evaluate(cfg.task, genomes[:1], generation=g, seed=seed, config=cfg)[0]
             for g in range(1, FRESH_GENERATIONS + 1)]
    return seed, {"founder": float(scores[0]), "founder, fresh trials": float(np.mean(fresh)),
                  "population best": float(scores.max()), "population mean": float(scores.mean()),
                  "share >= founder": float(np.mean(scores >= scores[0]))}


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="+", type=Path, help="nav1d-near-chained run folders")
    a = p.parse_args(argv)
    rows = [founded(run) for run in a.runs]
    names = list(rows[0][1])
    print("| seed | " + " | ".join(names) + " |")
    print("|---" * (len(names) + 1) + "|")
    for seed, figures in rows:
        print(f"| {seed} | " + " | ".join(f"{figures[n]:.3f}" for n in names) + " |")


if __name__ == "__main__":
    main()
