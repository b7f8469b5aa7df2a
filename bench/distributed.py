"""Benchmark: what running a sweep on Dask costs and gains (`dnnevo sweep --workers`,
`dnnevo reproduce`).

The work is a sweep of short runs: `sequence-1bit --quick` (population 60, 8 generations),
`--eval-trials 20`, no step check, one thread per run, as `dnnevo sweep` does it. The reference
is the same sweep in this process, one run after another (what `dnnevo sweep` does without
--workers). All in one process, interleaved, medians of --rounds:

(a) 8 runs: in process, and on a local Dask cluster of 1 and of 2 worker processes. Printed:
    wall time of the runs (the cluster already up), the cluster's start-up time, the speed-up of
    2 workers over in process, and the overhead per run on 1 worker
    ((1-worker wall - in-process wall) / runs).
(b) how the overhead per run grows with the number of runs: 8, 32 and 128 runs on 1 worker
    against in process.

    python bench/distributed.py [--rounds 3] [--counts 8,32,128]
"""

from __future__ import annotations

import argparse
import io
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

# This file's name is Dask's package's: bench/ goes last on the path, so that `import
# distributed` finds Dask (here and in the worker processes, which import this file again).
HERE = Path(__file__).resolve().parent
sys.path = [p for p in sys.path if Path(p or ".").resolve() != HERE] + [str(HERE)]

from _common import describe_machine  # noqa: E402

from dnnevo import presets
from dnnevo.experiments import scheduler
from dnnevo.experiments import sweep# noqa: E402
from dnnevo.experiments.runsview import RunsView  # noqa: E402

PRESET = "sequence-1bit"
EVAL_TRIALS = 20


def tasks(out: Path, count: int) -> list[scheduler.Task]:
    config = presets.get(PRESET, quick=True)
    options = {"threads": 1, "eval_trials": EVAL_TRIALS, "dt_check": False, "progress": False}
    return [scheduler.Task(f"seed-{s}", (), sweep.run_seed, (config, s, out / f"seed-{s}"), options)
            for s in range(count)]


def quiet_view(count: int) -> RunsView:
    return RunsView(count, stream=io.StringIO(), bar=False)


def in_process(root: Path, count: int) -> float:
    out = Path(tempfile.mkdtemp(dir=root))
    t0 = time.perf_counter()
    outcomes = scheduler.run_in_process(tasks(out, count), quiet_view(count))
    wall = time.perf_counter() - t0
    assert all(o.status == "done" for o in outcomes.values())
    shutil.rmtree(out)
    return wall


def on_dask(root: Path, count: int, client) -> float:
    out = Path(tempfile.mkdtemp(dir=root))
    t0 = time.perf_counter()
    outcomes = scheduler.run_on_dask(tasks(out, count), quiet_view(count), client)
    wall = time.perf_counter() - t0
    assert all(o.status == "done" for o in outcomes.values())
    shutil.rmtree(out)
    return wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--counts", default="8,32,128")
    args = parser.parse_args()
    counts = [int(c) for c in args.counts.split(",")]
    describe_machine()
    print(f"work: {PRESET} --quick runs (population 60, 8 generations), {EVAL_TRIALS} fresh trials per "
          f"target, no step check, 1 thread per run; medians of {args.rounds} interleaved rounds")
    root = Path(tempfile.mkdtemp(prefix="dnnevo-bench-dist-"))
    starts = {1: [], 2: []}
    walls = {(k, n): [] for k in ("here", 1, 2) for n in counts}
    try:
        for _ in range(args.rounds):
            for n in counts:
                walls[("here", n)].append(in_process(root, n))
            for workers in (1, 2):
                t0 = time.perf_counter()
                with scheduler.dask_client(workers=workers, scheduler=None) as client:
                    starts[workers].append(time.perf_counter() - t0)
                    on_dask(root, 2, client)  # warm-up: the workers import dnnevo
                    for n in counts if workers == 1 else counts[:1]:
                        walls[(workers, n)].append(on_dask(root, n, client))
    finally:
        shutil.rmtree(root, ignore_errors=True)
    med = {k: statistics.median(v) for k, v in walls.items() if v}
    n = counts[0]
    print(f"\n(a) {n} runs")
    print(f"  in process (reference)  {med[('here', n)]:7.2f} s  ({med[('here', n)] / n * 1000:.0f} ms per run)")
    for workers in (1, 2):
        print(f"  Dask, {workers} worker(s)        {med[(workers, n)]:7.2f} s  (cluster start-up "
              f"{statistics.median(starts[workers]):.2f} s, not included)")
    print(f"  speed-up of 2 workers over in process: {med[('here', n)] / med[(2, n)]:.2f}x")
    print(f"  overhead per run on 1 worker: {(med[(1, n)] - med[('here', n)]) / n * 1000:+.0f} ms")
    print("\n(b) overhead per run on 1 worker against in process")
    print(f"  {'runs':>5} {'in process s':>13} {'1 worker s':>11} {'overhead ms/run':>16}")
    for n in counts:
        print(f"  {n:>5} {med[('here', n)]:>13.2f} {med[(1, n)]:>11.2f} "
              f"{(med[(1, n)] - med[('here', n)]) / n * 1000:>+16.0f}")


if __name__ == "__main__":
    main()
