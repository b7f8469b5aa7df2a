"""How fast could dnnevo's integrator be with a cheaper sigmoid? Two cheaper exponentials, and a
free sigmoid as the ceiling for any.

dnnevo's sigmoid is exact (its own exponential within 2 ulp, then a correctly rounded division),
so that every result has the same bits on every CPU. Issue #14 asks for 1.25x the hand-written C
anchor (../shared/anchors; libmvec's vector exp, -ffast-math) at N = 5, 10 and 30, and issue 49
parity with it from a cheaper exponential that keeps the same bits on every kernel. This script
builds throwaway copies of this checkout's HEAD, each installed into a temporary virtual
environment:

- "free sigmoid": the sigmoid replaced by a clamp to [0, 1] (about the cheapest function a step
  could call; its RESULTS ARE WRONG and are never compared): the ceiling for any cheaper sigmoid;
- "exp table16" and "exp table256": the exponential of bench/patches/exp_table16.patch and
  exp_table256.patch (a table of 2^(j/16) or 2^(j/256) and a polynomial of degree 7 or 4
  instead of 13; each patch's header says what it does). Their results are exact to 2^-52 and
  the same on every x86 kernel, but they are not the shipped bits.

It times, on the same networks, the C anchor, dnnevo as installed here ("exact") and each copy.
Each round runs every build in turn, each in its own process, which times the C anchor and then
dnnevo on each size (each warmed up, then the median of 5 calls, much as anchor.py does); each
ratio is to the C anchor timed in the same process, and the medians over rounds are printed.

    python bench/sigmoid_ceiling.py [--rounds 7] [--one-thread] [--kernel avx2] [--anchor DIR]
                                    [--builds "free sigmoid" "exp table16" ...]

A ratio below the goal for the free sigmoid means no cheaper sigmoid can meet it with the rest
of the kernel as it is. Each build takes 1-3 minutes and needs the package registries (maturin,
numpy); `--keep DIR` builds into DIR once and reuses the builds.
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
from integrate import ANCHOR_TARGET, ANCHOR_TARGET_SIZES, DT, POPULATION, SIZES, STEPS, pulse_inputs, random_population

REPO = Path(__file__).resolve().parent.parent
REPEATS = 5  # timed calls per contender and size in one process
MATH = "crates/ctrnn/src/math.rs"
EXACT_SIGMOID = "    one / (one + exp_lanes(-x))\n"
FREE_SIGMOID = "    let _ = one;\n    x.clamp(0.0, 1.0)\n"
PATCHES = REPO / "bench" / "patches"
COPIES = ("free sigmoid", "exp table16", "exp table256")
"""The throwaway builds, each made by `change_source` from HEAD."""


def free_sigmoid(source: str) -> str:
    """`math.rs` with the sigmoid's body replaced by a clamp; an error if the body changed."""
    if source.count(EXACT_SIGMOID) != 1:
        raise SystemExit(f"error: {MATH} no longer holds the sigmoid body {EXACT_SIGMOID.strip()!r} "
                         "once; update bench/sigmoid_ceiling.py")
    return source.replace(EXACT_SIGMOID, FREE_SIGMOID)


def change_source(name: str, source: Path) -> None:
    """Turns the copy of HEAD in `source` into the build `name` (one of COPIES)."""
    if name == "free sigmoid":
        math = source / MATH
        math.write_text(free_sigmoid(math.read_text()))
        return
    patch = PATCHES / f"{name.replace(' ', '_')}.patch"
    before = (source / MATH).read_text()
    # Outside any repository, so that git applies the patch here even when `source` lies inside one.
    env = {**os.environ, "GIT_CEILING_DIRECTORIES": str(source.resolve().parent)}
    done = subprocess.run(["git", "apply", str(patch)], cwd=source, capture_output=True, text=True,
                          env=env)
    if done.returncode != 0 or (source / MATH).read_text() == before:
        raise SystemExit(f"error: {patch.name} no longer applies to HEAD "
                         f"({done.stderr.strip() or 'nothing changed'}); update it")


def build_copy(name: str, into: Path) -> Path:
    """Builds HEAD changed into `name` in `into` (unless already there); its python."""
    python = into / "venv" / "bin" / "python"
    if python.exists():
        return python
    source = into / "src"
    source.mkdir(parents=True, exist_ok=True)
    archive = subprocess.run(["git", "-C", str(REPO), "archive", "HEAD"], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(source)], input=archive, check=True)
    change_source(name, source)
    subprocess.run([sys.executable, "-m", "venv", str(into / "venv")], check=True)
    print(f"building the {name!r} copy of HEAD in {into} (1-3 min) ...", flush=True)
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
    ap.add_argument("--keep", metavar="DIR", help="build the copies here and reuse them")
    ap.add_argument("--builds", nargs="+", choices=COPIES, default=list(COPIES), metavar="BUILD",
                    help=f"the copies to time beside the exact build (default: all of {', '.join(map(repr, COPIES))})")
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
        builds = {"exact": sys.executable}
        for name in args.builds:
            builds[name] = str(build_copy(name, work / name.replace(" ", "-")))
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
    names = list(rounds)
    print(f"{'N':>3}  {'C anchor':>9}  " + "  ".join(f"{name:>12}  {'vs C':>5}" for name in names))
    for n in SIZES:
        def rate(name, who):
            return statistics.median(POPULATION * STEPS / x[str(n)][who] for x in rounds[name])

        def ratio(name):
            return statistics.median(x[str(n)]["c"] / x[str(n)]["dnnevo"] for x in rounds[name])
        c = statistics.median(POPULATION * STEPS / x[str(n)]["c"]
                              for name in rounds for x in rounds[name])
        print(f"{n:>3}  {c:>9.3g}  " + "  ".join(
            f"{rate(name, 'dnnevo'):>12.3g}  {ratio(name):>5.2f}" for name in names))
    print(f"goal (issue 49): at least {ANCHOR_TARGET:.2f}x the C anchor at N = "
          f"{', '.join(map(str, ANCHOR_TARGET_SIZES))}")


if __name__ == "__main__":
    sys.exit(main())
