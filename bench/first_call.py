"""Benchmark: how much slower dnnevo's first calls in a fresh process are than its later ones.

Workload (bench/integrate.py's at N = 5): P = 1000 random networks (dnnevo.Network.random(5, 2,
seed=k)), T = 1000 forward-Euler steps of dt = 0.1, two pulse-train inputs shared by every
network, dnnevo.run_population(..., record=False) on all cores.

Each of --processes fresh Python processes (spawned, so nothing is warm) imports dnnevo, builds
the networks and inputs, and times its first --calls calls one by one; then, in the same process,
it warms up for a quarter second and times --steady calls more. The figures are, for each call
number, the median over the processes, against the steady-state median of the same processes
(the reference: the same call once the process is warm), and their ratio. The first call of a
process is where a cold start (thread pool start-up, the allocator's first pages, the kernel's
choice, clocks) shows.

    python bench/first_call.py [--processes 7] [--calls 8] [--steady 30] [--quick]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import resource
import statistics
import sys
import time

SIZE, POPULATION, STEPS, N_INPUTS = 5, 1000, 1000, 2


def faults() -> int:
    """Minor page faults of this process so far (Linux counts each fresh page touched)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def cpu_seconds() -> float:
    """CPU seconds of this process so far, every thread's."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def one_process(calls: int, steady: int) -> tuple[list[float], float, list[int], list[float]]:
    """(seconds of each of the first `calls` calls, median seconds of `steady` warm calls, page
    faults and CPU seconds of each first call), timed in this process, which must be fresh."""
    import numpy as np

    import dnnevo
    from _common import median_time

    nets = [dnnevo.Network.random(SIZE, N_INPUTS, seed=k) for k in range(POPULATION)]
    t = np.arange(STEPS)
    inputs = np.stack([(t // 10) % 2 == 0, (t // 50) % 2 == 0], axis=1).astype(np.float64)

    def call():
        return dnnevo.run_population(nets, inputs, dt=0.1, record=False)

    first, faulted, cpu = [], [], []
    for _ in range(calls):
        before, cpu_before = faults(), cpu_seconds()
        start = time.perf_counter()
        call()
        first.append(time.perf_counter() - start)
        faulted.append(faults() - before)
        cpu.append(cpu_seconds() - cpu_before)
    warm, _ = median_time(lambda _: call(), steady)
    return first, warm, faulted, cpu


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--processes", type=int, default=7,
                    help="fresh processes, one after the other; medians over them (default 7)")
    ap.add_argument("--calls", type=int, default=8, help="first calls timed in each (default 8)")
    ap.add_argument("--steady", type=int, default=30,
                    help="warm calls timed in each, after a quarter-second warm-up (default 30)")
    ap.add_argument("--quick", action="store_true", help="3 processes, 5 calls, 10 steady")
    args = ap.parse_args(argv)
    if args.quick:
        args.processes, args.calls, args.steady = 3, 5, 10
    if min(args.processes, args.calls, args.steady) < 1:
        ap.error("--processes, --calls and --steady must be >= 1")

    from _common import describe_machine

    describe_machine()
    print(f"workload: run_population, P = {POPULATION}, N = {SIZE}, T = {STEPS} Euler steps, "
          f"record=False; {args.processes} fresh processes, first {args.calls} calls each, then "
          f"{args.steady} warm calls")
    ctx = mp.get_context("spawn")
    results = []
    for _ in range(args.processes):
        with ctx.Pool(1) as pool:  # a fresh process each time
            results.append(pool.apply(one_process, (args.calls, args.steady)))
    steady = statistics.median(r[1] for r in results)
    print()
    header = (f"{'call':>4}  {'dnnevo ms (median)':>18}  {'min':>7}  {'max':>7}  {'steady ms':>9}  "
              f"{'ratio':>6}  {'page faults':>11}  {'CPU ms':>6}")
    print(header)
    print("-" * len(header))
    for k in range(args.calls):
        times = [r[0][k] for r in results]
        m = statistics.median(times)
        faulted = statistics.median(r[2][k] for r in results)
        cpu = statistics.median(r[3][k] for r in results)
        print(f"{k + 1:>4}  {m * 1e3:>18.2f}  {min(times) * 1e3:>7.2f}  {max(times) * 1e3:>7.2f}  "
              f"{steady * 1e3:>9.2f}  {m / steady:>5.2f}x  {faulted:>11.0f}  {cpu * 1e3:>6.1f}")
    firsts = [r[0][0] for r in results]
    rest = [t for r in results for t in r[0][1:]]
    print()
    print(f"first call: {statistics.median(firsts) * 1e3:.2f} ms, calls 2-{args.calls}: "
          f"{statistics.median(rest) * 1e3 if rest else float('nan'):.2f} ms, steady: "
          f"{steady * 1e3:.2f} ms (medians); first / steady = {statistics.median(firsts) / steady:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
