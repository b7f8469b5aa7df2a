"""Helpers shared by the benchmark scripts in bench/ (integrate.py, sequence.py, evolve.py).

The scripts are run as `python bench/X.py`, so Python puts bench/ first on sys.path and they
import this module as `_common`.
"""

from __future__ import annotations

import importlib.util
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

import dnnevo


def load_reference():
    """tests/sequence_reference.py (the batched NumPy reference of the sequence task), loaded
    as a module by path (tests/ is not a package)."""
    path = Path(__file__).resolve().parent.parent / "tests" / "sequence_reference.py"
    spec = importlib.util.spec_from_file_location("dnnevo_bench_sequence_reference", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def threads() -> int:
    """Number of CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def describe_machine() -> None:
    """Print the versions, CPU model and vector extensions, dnnevo's kernel, usable threads and the
    thread-related environment variables that are set."""
    print(f"python {platform.python_version()}, numpy {np.__version__}, "
          f"dnnevo {getattr(dnnevo, '__version__', '?')}, {platform.machine()}")
    try:
        with open("/proc/cpuinfo") as f:
            info = f.read()
        model = next(line.split(":", 1)[1].strip() for line in info.splitlines()
                     if line.startswith("model name"))
        flags = set(next(line.split(":", 1)[1].split() for line in info.splitlines()
                         if line.startswith("flags")))
        vector = "avx512f" if "avx512f" in flags else "avx2" if "avx2" in flags else "no avx2"
        print(f"cpu: {model} ({vector})")
    except (OSError, StopIteration):
        pass
    build = dnnevo.build_info()
    print(f"dnnevo kernel: {build['kernel']} (this CPU can run {', '.join(build['kernels'])}; "
          f"DNNEVO_SIMD forces one)")
    print(f"threads: {threads()} usable by this process ({os.cpu_count()} logical CPUs)")
    for var in ("RAYON_NUM_THREADS", "OPENBLAS_CORETYPE", "OMP_NUM_THREADS"):
        if var in os.environ:
            print(f"{var}={os.environ[var]}")


def timed(fn):
    """(seconds of one call `fn()`, its result)."""
    start = time.perf_counter()
    result = fn()
    return time.perf_counter() - start, result


# Warm-up before timing: calls until this much time has passed (at least one call). A cold start
# (clocks ramping up, idle worker threads, the allocator's first pages) makes the first few
# calls of a few-millisecond workload up to twice as slow as the rest.
WARMUP_SECONDS = 0.25


def warm_up(fn):
    """Calls `fn()` until WARMUP_SECONDS have passed (at least once); the last result."""
    start = time.perf_counter()
    result = fn()
    while time.perf_counter() - start < WARMUP_SECONDS:
        result = fn()
    return result


def median_time(fn, repeats: int):
    """(median seconds of `repeats` timed calls `fn(i)`, i = 0 .. repeats-1, after warm-up
    calls `fn(0)` for at least WARMUP_SECONDS; the last call's result)."""
    result = warm_up(lambda: fn(0))
    times = []
    for i in range(repeats):
        t, result = timed(lambda: fn(i))
        times.append(t)
    return statistics.median(times), result


# Timed calls of one contender in a row in `interleaved_medians`, after its own warm-up.
TURN_CALLS = 7


def interleaved_medians(fns: dict, repeats: int) -> dict:
    """Median seconds of `repeats` timed calls of each `fns[name]()`. The contenders take turns,
    so that a burst of load from other jobs hits every contender alike; a turn is a warm-up
    (WARMUP_SECONDS) and then up to TURN_CALLS timed calls. Turns of one call each would time
    every call just after another contender's: after a call of the C anchor its OpenMP thread
    spins for a while on one core, and dnnevo at N = 5 measured 0.31x the anchor that way
    against 0.89x with warmed-up turns (2026-11-27, Zen 5)."""
    times: dict[str, list[float]] = {name: [] for name in fns}
    while any(len(t) < repeats for t in times.values()):
        for name, fn in fns.items():
            calls = min(TURN_CALLS, repeats - len(times[name]))
            warm_up(fn)
            times[name] += [timed(fn)[0] for _ in range(calls)]
    return {name: statistics.median(t) for name, t in times.items()}
