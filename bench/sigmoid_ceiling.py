"""How fast could dnnevo's integrator be with a free sigmoid? A ceiling for any cheaper one.

dnnevo's sigmoid is exact (its own exponential within 2 ulp, then a correctly rounded division),
so that every result has the same bits on every CPU. Issue #14 asks for 1.25x the hand-written C
anchor (../shared/anchors; libmvec's vector exp, -ffast-math) at N = 5, 10 and 30. This script
asks whether any cheaper sigmoid could get there: it builds a throwaway copy of this checkout's
HEAD whose sigmoid is replaced by a clamp to [0, 1] (about the cheapest function a step could
call; its RESULTS ARE WRONG and are never compared), installs it into a temporary virtual
environment, and times, on the same networks, the C anchor, dnnevo as installed here, and the
copy. Each round runs both builds in turn, each in its own process, which times the C anchor and
then dnnevo on each size (each warmed up, then the median of 5 calls, much as anchor.py does);
each ratio is to the C anchor timed in the same process, and the medians over rounds are
printed.

    python bench/sigmoid_ceiling.py [--rounds 7] [--one-thread] [--kernel avx2] [--anchor DIR]

A ratio below 1.25 for the free sigmoid means no cheaper sigmoid can meet the goal with the rest
of the kernel as it is. The build takes 1-2 minutes and needs the package registries (maturin,
numpy); `--keep DIR` builds into DIR once and reuses it.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import _anchor
import dnnevo
from _common import interleaved_medians
from integrate import ANCHOR_TARGET, DT, POPULATION, SIZES, STEPS, pulse_inputs, random_population

REPO = Path(__file__).resolve().parent.parent
REPEATS = 5  # timed calls per contender and size in one process
MATH = "crates/ctrnn/src/math.rs"
EXACT_SIGMOID = "    one / (one + exp_lanes(-x))\n"
FREE_SIGMOID = "    let _ = one;\n    x.clamp(0.0, 1.0)\n"


def free_sigmoid(source: str) -> str:
    """`math.rs` with the sigmoid's body replaced by a clamp; an error if the body changed."""
    if source.count(EXACT_SIGMOID) != 1:
        raise SystemExit(f"error: {MATH} no longer holds the sigmoid body {EXACT_SIGMOID.strip()!r} "
                         "once; update bench/sigmoid_ceiling.py")
    return source.replace(EXACT_SIGMOID, FREE_SIGMOID)


def build_free_copy(into: Path) -> Path:
    """Builds HEAD with the free sigmoid into `into` (unless already there); its python."""
    python = into / "venv" / "bin" / "python"
    if python.exists():
        return python
    source = into / "src"
    source.mkdir(parents=True, exist_ok=True)
    archive = subprocess.run(["git", "-C", str(REPO), "archive", "HEAD"], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(source)], input=archive, check=True)
    math = source / MATH
    math.write_text(free_sigmoid(math.read_text()))
    subprocess.run([sys.executable, "-m", "venv", str(into / "venv")], check=True)
    print(f"building the free-sigmoid copy of HEAD in {into} (1-2 min) ...", flush=True)
    subprocess.run([str(python), "-m", "pip", "install", "-q", str(source)], check=True)
    return python


def measure(anchor_dir: str, one_thread: bool) -> dict:
    """In this process: {N: {"c": seconds, "dnnevo": seconds}}, each the median of REPEATS
    calls after a warm-up (one turn each of _common.interleaved_medians)."""
    anchor = _anchor.load(Path(anchor_dir), build=False)
    run_c = anchor.run_simd if one_thread else anchor.run_simd_omp
    inputs = pulse_inputs(STEPS)
    out = {"kernel": dnnevo.build_info()["kernel"]}
    for n in SIZES:
        nets, params = random_population(n, POPULATION)
        c_params = _anchor.params(*params)
        out[str(n)] = interleaved_medians({
            "c": lambda: run_c(c_params, STEPS),
            "dnnevo": lambda: dnnevo.run_population(nets, inputs, dt=DT, record=False),
        }, REPEATS)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 epilog="example: python bench/sigmoid_ceiling.py --rounds 7")
    ap.add_argument("--rounds", type=int, default=7, help="rounds of both builds (default 7)")
    ap.add_argument("--one-thread", action="store_true",
                    help="dnnevo on one thread (RAYON_NUM_THREADS=1) and the C anchor's "
                         "single-threaded kernel (default: both on every core)")
    ap.add_argument("--kernel", choices=("avx512", "avx2", "neon", "portable"),
                    help="force dnnevo's kernel (DNNEVO_SIMD); with avx2 the C anchor is "
                         "built for x86-64-v3 too")
    ap.add_argument("--anchor", metavar="DIR", help="the C anchor's folder (default: "
                    "$DNNEVO_ANCHOR, else ../shared/anchors next to the repository)")
    ap.add_argument("--keep", metavar="DIR", help="build the free-sigmoid copy here and reuse it")
    ap.add_argument("--measure", metavar="DIR", help=argparse.SUPPRESS)  # child process
    args = ap.parse_args(argv)
    if args.measure:
        print(json.dumps(measure(args.measure, args.one_thread)))
        return 0
    if args.rounds < 1:
        ap.error("--rounds must be >= 1")
    if args.kernel and args.kernel not in dnnevo.build_info()["kernels"]:
        ap.error(f"--kernel {args.kernel}: this CPU runs {', '.join(dnnevo.build_info()['kernels'])}")
    folder = _anchor.locate(args.anchor)
    if folder is None:
        raise SystemExit(f"error: no C anchor found (--anchor DIR or ${_anchor.ENV})")
    env = dict(os.environ)
    if args.kernel:
        env["DNNEVO_SIMD"] = args.kernel
        if args.kernel == "avx2":
            env["ANCHOR_MARCH"] = "x86-64-v3"
    _anchor.load(folder, env=env)  # built once, here; the measuring processes only load it
    if args.one_thread:
        env["RAYON_NUM_THREADS"] = "1"
    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="dnnevo-ceiling-"))
    try:
        free = build_free_copy(work)
        builds = {"exact": sys.executable, "free sigmoid": str(free)}
        rounds = {name: [] for name in builds}
        for r in range(args.rounds):
            for name, python in builds.items():
                child = [python, __file__, "--measure", str(folder)]
                if args.one_thread:
                    child.append("--one-thread")
                done = subprocess.run(child, env=env, check=True, capture_output=True, text=True)
                rounds[name].append(json.loads(done.stdout.splitlines()[-1]))
            print(f"round {r + 1}/{args.rounds} done", file=sys.stderr, flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    report(rounds, args)
    return 0


def report(rounds: dict, args) -> None:
    kernel = rounds["exact"][0]["kernel"]
    threads = "one thread each" if args.one_thread else "every core"
    print(f"kernel {kernel}, {threads}; P = {POPULATION}, T = {STEPS}; medians of "
          f"{args.rounds} rounds, network-steps/s; ratios to the C anchor of the same process")
    print(f"{'N':>3}  {'C anchor':>9}  {'exact':>9}  {'vs C':>5}  {'free sigmoid':>12}  "
          f"{'vs C':>5}  {'goal':>5}")
    for n in SIZES:
        def rate(name, who):
            return statistics.median(POPULATION * STEPS / x[str(n)][who] for x in rounds[name])

        def ratio(name):
            return statistics.median(x[str(n)]["c"] / x[str(n)]["dnnevo"] for x in rounds[name])
        c = statistics.median(POPULATION * STEPS / x[str(n)]["c"]
                              for name in rounds for x in rounds[name])
        print(f"{n:>3}  {c:>9.3g}  {rate('exact', 'dnnevo'):>9.3g}  {ratio('exact'):>5.2f}  "
              f"{rate('free sigmoid', 'dnnevo'):>12.3g}  {ratio('free sigmoid'):>5.2f}  "
              f"{ANCHOR_TARGET:>5.2f}")


if __name__ == "__main__":
    sys.exit(main())
