"""Benchmark: dnnevo's population integrator against the hand-written C anchor and NumPy.

Workload (per network size N in {5, 10, 30}):
  P = 1000 random networks (dnnevo.Network.random(N, 2, seed=k)), T = 1000 forward-Euler steps
  (substeps=1, dt=0.1), M = 2 inputs shared by every network: input 0 is a square pulse train
  (10 steps on, 10 off), input 1 a slower one (50 on, 50 off).

Contenders, each in network-steps per second (P x steps / seconds):
  - dnnevo: run_population(..., record=False) on all cores, with the kernel it picks (printed);
  - the C anchor (bench/_anchor.py; found in ../shared/anchors, or --anchor DIR): SIMD across
    networks, libmvec's vector exp, -ffast-math, OpenMP on 2 threads, on the same networks.
    Its inputs are its own (a pulse and a state-dependent second input, computed each step),
    slightly more work than dnnevo's. dnnevo and C take turns (each turn a warm-up, then a few
    timed calls; see _common.interleaved_medians), and the medians of --repeats calls are
    compared: the goal is dnnevo >= 1.0x C at N = 5 and 10 (issue #49; at N = 30 its goal is a
    share of the L2 streaming peak, which the anchor's c/peak measures);
  - dnnevo in single precision: run_population(..., precision="f32"), timed in the same turns as
    the f64 run; the goals are f32 >= 1.8x f64 and f32 >= 1.0x the float C anchor at every N
    (issue #49). The float anchor is the C anchor copied into bench/anchor_f32 and adapted to
    float (its source's header says what changed), built here each run; it runs the double
    anchor's inputs on the same networks, and its final states are compared with the double
    anchor's (its max |diff| is printed, as a check that it computes the same thing). Its accuracy: the largest
    |f32 - f64| state difference over the whole T-step trajectory of the first ACCURACY_NETWORKS
    networks (all of them, each network's largest, and the median of those);
  - NumPy with the same equations, batched over the population with einsum, on one core
    (NumPy's einsum does not thread), median of at most 3 runs. NumPy may be timed over fewer
    steps (--numpy-steps): the figure is a per-step throughput.
Each contender is warmed up for a quarter second first. The final states of dnnevo and NumPy
after the full T steps are compared network by network (rtol = atol = 1e-9). A few random
networks are chaotic and amplify rounding differences over 1000 steps; a mismatch is reported as
such (not as a disagreement) when NumPy with a different summation order misses by as much. The
C anchor's results are not compared (fast-math, other inputs).

    python bench/integrate.py [--repeats 21] [--quick] [--numpy-steps 200] [--anchor DIR]

Exits with 1 if dnnevo and NumPy disagree; a ratio below its target is reported, not an error.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import _anchor
import dnnevo
from _common import describe_machine, interleaved_medians, median_time

SIZES = (5, 10, 30)
POPULATION, STEPS = 1000, 1000  # networks and Euler steps of the full workload
TARGETS = {5: 20.0, 10: 16.0, 30: 10.0}  # minimum dnnevo / numpy speed-up
ANCHOR_TARGET = 1.0  # minimum dnnevo / C anchor speed-up at the sizes below (issue #49)
ANCHOR_TARGET_SIZES = (5, 10)  # (at N = 30 the goal is a share of the L2 streaming peak)
F32_TARGET = 1.8  # minimum dnnevo f32 / dnnevo f64 speed-up, every N
F32_ANCHOR_TARGET = 1.0  # minimum dnnevo f32 / float C anchor speed-up, every N
ACCURACY_NETWORKS = 100  # networks whose f32 and f64 trajectories are compared
DT = 0.1
N_INPUTS = 2


def pulse_inputs(steps: int) -> np.ndarray:
    """(steps, 2): a square pulse train (period 20) and a slower one (period 100), values 0/1."""
    t = np.arange(steps)
    fast = (t // 10) % 2 == 0
    slow = (t // 50) % 2 == 0
    return np.stack([fast, slow], axis=1).astype(np.float64)


def numpy_final_states(params, inputs, dt=DT):
    """Forward Euler over the rows of `inputs` (T, M), batched over P networks with einsum.

    v += dt/tau * (-v + W f(v - theta) + S I), f(x) = 1 / (1 + exp(-x)). Returns v (P, N).
    """
    tau, theta, weights, sensor, v = params
    v = v.copy()
    h = dt / tau
    with np.errstate(over="ignore"):  # exp overflow -> rate 0, the right limit
        return _euler_loop(v, h, theta, weights, sensor, inputs)


def _euler_loop(v, h, theta, weights, sensor, inputs):
    for row in inputs:
        rates = 1.0 / (1.0 + np.exp(theta - v))
        drive = np.einsum("pij,pj->pi", weights, rates)
        drive += np.einsum("pik,k->pi", sensor, row)
        drive -= v
        drive *= h
        v += drive
    return v


def numpy_final_states_reordered(params, inputs, dt=DT):
    """The same Euler steps, summing each neuron's inputs in reverse order.

    Used only to tell rounding-sensitive networks apart: where two NumPy summation orders
    already differ by more than the tolerance after T steps, the network amplifies rounding
    (it is chaotic), and dnnevo cannot be expected to match either order more closely.
    """
    tau, theta, weights, sensor, v = params
    v = v.copy()
    h = dt / tau
    w_rev = np.ascontiguousarray(weights[:, :, ::-1])
    with np.errstate(over="ignore"):
        for row in inputs:
            rates = 1.0 / (1.0 + np.exp(theta - v))
            drive = (w_rev * rates[:, None, ::-1]).sum(axis=2)
            drive += np.einsum("pik,k->pi", sensor, row)
            v = v + h * (drive - v)
    return v


def compare(ours, theirs, params, inputs, tol=1e-9):
    """Per-network agreement of final states (P, N): (agreeing, rounding-sensitive, unexplained).

    A network agrees if every state is within rtol = atol = `tol`. A network that does not is
    rounding-sensitive if NumPy with another summation order misses by at least 1/100 of
    dnnevo's miss (rounding differences, amplified the same way); otherwise its mismatch is
    unexplained: a real disagreement.
    """
    def miss(a, b):  # per network, in units of the tolerance
        return (np.abs(a - b) / (tol + tol * np.abs(b))).max(axis=1)

    ours_miss = miss(ours, theirs)
    bad = np.flatnonzero(ours_miss > 1.0)
    if bad.size == 0:
        return len(ours), bad, bad
    subset = tuple(x[bad] for x in params)
    self_miss = miss(numpy_final_states_reordered(subset, inputs), theirs[bad])
    explained = self_miss * 100.0 >= ours_miss[bad]
    return len(ours) - bad.size, bad[explained], bad[~explained]


def random_population(n: int, population: int):
    """The workload's networks of size `n` (Network.random with seeds 0 .. population-1) and
    their stacked parameters (tau, theta, weights, sensor_weights, state)."""
    nets = [dnnevo.Network.random(n, N_INPUTS, seed=k) for k in range(population)]
    params = tuple(np.stack([getattr(net, name) for net in nets])
                   for name in ("tau", "theta", "weights", "sensor_weights", "state"))
    return nets, params


def bench_size(n: int, args, anchor, anchor_f32) -> dict:
    nets, params = random_population(n, args.population)
    inputs = pulse_inputs(args.steps)
    p = len(nets)

    def run_dnnevo(precision="f64"):
        return dnnevo.run_population(nets, inputs, dt=DT, substeps=1, method="euler",
                                     record=False, precision=precision)

    contenders = {"dnnevo": run_dnnevo, "f32": lambda: run_dnnevo("f32")}
    if anchor is not None:
        c_params = _anchor.params(*params)
        contenders["c"] = lambda: anchor.run_simd_omp(c_params, args.steps)
        contenders["c32"] = lambda: anchor_f32.run_simd_omp(c_params, args.steps)
    times = interleaved_medians(contenders, args.repeats)
    c32_diff = None
    if anchor is not None:
        c32_diff = float(np.abs(anchor_f32.run_simd_omp(c_params, args.steps)
                                - anchor.run_simd_omp(c_params, args.steps)).max())
    ours = run_dnnevo()
    np_steps = min(args.numpy_steps, args.steps)
    np_inputs = inputs[:np_steps]
    t_numpy, theirs = median_time(lambda _: numpy_final_states(params, np_inputs),
                                  args.numpy_repeats)

    # Agreement over the full workload.
    ours = np.asarray(ours)
    if np_steps < args.steps:
        theirs = numpy_final_states(params, inputs)
    n_close, sensitive, unexplained = compare(ours, theirs, params, inputs)
    few = nets[:ACCURACY_NETWORKS]
    traj = {prec: dnnevo.run_population(few, inputs, dt=DT, substeps=1, method="euler",
                                        record=True, precision=prec)
            for prec in ("f64", "f32")}
    per_net = np.abs(traj["f32"] - traj["f64"]).max(axis=(1, 2))
    return dict(
        n=n,
        p=p,
        dnnevo=p * args.steps / times["dnnevo"],
        f32=p * args.steps / times["f32"],
        f32_max=float(per_net.max()),
        f32_median=float(np.median(per_net)),
        f32_nets=len(few),
        c=p * args.steps / times["c"] if "c" in times else None,
        c32=p * args.steps / times["c32"] if "c32" in times else None,
        c32_diff=c32_diff,
        numpy=p * np_steps / t_numpy,
        n_close=n_close,
        sensitive=sensitive,
        unexplained=unexplained,
        max_diff=float(np.max(np.abs(ours - theirs))),
    )


def met(ratio: float, target: float) -> str:
    """'yes' if a speed-up reaches its target, else 'NO'."""
    return "yes" if ratio >= target else "NO"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=21,
                    help="timed dnnevo runs per size; the median is reported (default 21)")
    ap.add_argument("--quick", action="store_true",
                    help="a smoke run: fewer networks, steps and repeats (figures are rougher)")
    ap.add_argument("--numpy-steps", type=int, default=None,
                    help="steps of the timed NumPy runs (default: all T; fewer save time)")
    ap.add_argument("--anchor", default=None, metavar="DIR",
                    help=f"the C anchor's folder (default: ${_anchor.ENV}, else "
                         "../shared/anchors next to the repository)")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats must be >= 1")
    args.population, args.steps = POPULATION, STEPS
    args.numpy_repeats = max(1, min(args.repeats, 3))
    if args.quick:
        args.population, args.steps = 200, 200
        args.repeats, args.numpy_repeats = min(args.repeats, 3), 1
    if args.numpy_steps is None:
        args.numpy_steps = args.steps
    if args.numpy_steps < 1:
        ap.error("--numpy-steps must be >= 1")

    describe_machine()
    folder = _anchor.locate(args.anchor)
    anchor = _anchor.load(folder) if folder else None
    anchor_f32 = _anchor.load_f32(DT) if folder else None
    print(f"C anchor: {folder} (block {anchor.BLOCK}); float C anchor: {_anchor.F32_SOURCE} "
          f"(block {anchor_f32.BLOCK})" if anchor else
          f"C anchor: not found (--anchor DIR or ${_anchor.ENV}); NumPy only")
    print(f"workload: P = {args.population} networks, T = {args.steps} Euler steps, dt = {DT}, "
          f"M = {N_INPUTS} shared pulse-train inputs; median of {args.repeats} (dnnevo) / "
          f"{args.numpy_repeats} (numpy, {min(args.numpy_steps, args.steps)} steps) runs"
          f"{' [quick]' if args.quick else ''}")
    print()
    header = (f"{'N':>3}  {'dnnevo':>9}  {'C anchor':>9}  {'vs C':>6}  {'met':>3}  "
              f"{'NumPy':>9}  {'vs NumPy':>8}  {'met':>3}   (network-steps/s; targets: "
              f"{ANCHOR_TARGET:g}x C at N = {', '.join(map(str, ANCHOR_TARGET_SIZES))}, {'/'.join(f'{t:g}x' for t in TARGETS.values())} NumPy)")
    print(header)
    print("-" * len(header))
    start = time.perf_counter()
    results = []
    for n in SIZES:
        r = bench_size(n, args, anchor, anchor_f32)
        results.append(r)
        vs_numpy = r["dnnevo"] / r["numpy"]
        if r["c"] is None:
            c_cols = f"{'-':>9}  {'-':>6}  {'-':>3}"
        else:
            vs_c = r["dnnevo"] / r["c"]
            c_cols = (f"{r['c']:>9.3g}  {vs_c:>5.2f}x  "
                      f"{met(vs_c, ANCHOR_TARGET) if n in ANCHOR_TARGET_SIZES else '-':>3}")
        print(f"{n:>3}  {r['dnnevo']:>9.3g}  {c_cols}  {r['numpy']:>9.3g}  {vs_numpy:>7.1f}x  "
              f"{met(vs_numpy, TARGETS[n]):>3}", flush=True)
    print()
    ok = True
    for r in results:
        line = (f"agreement, N = {r['n']}: {r['n_close']}/{r['p']} networks' final states agree "
                f"within rtol 1e-9 (max |diff| over all {r['max_diff']:.1e})")
        if len(r["sensitive"]):
            line += (f"; {len(r['sensitive'])} rounding-sensitive (NumPy with another summation "
                     f"order misses by a similar amount): {r['sensitive'].tolist()}")
        if len(r["unexplained"]):
            ok = False
            line += f"; DISAGREE: networks {r['unexplained'].tolist()}"
        print(line)
    print("agreement: OK" if ok else "agreement: FAILED")
    print()
    kernel = dnnevo.build_info()["kernel"]
    header = (f"{'N':>3}  {'kernel':>8}  {'f64':>9}  {'f32':>9}  {'f32/f64':>7}  {'met':>3}  "
              f"{'C float':>9}  {'vs C fl.':>8}  {'met':>3}  {'max|f32-f64|':>12}  {'median':>8}"
              f"   (network-steps/s, same turns; targets {F32_TARGET:g}x f64, "
              f"{F32_ANCHOR_TARGET:g}x C float; state distance over {args.steps} steps)")
    print(header)
    print("-" * len(header))
    for r in results:
        ratio = r["f32"] / r["dnnevo"]
        if r["c32"] is None:
            c_cols = f"{'-':>9}  {'-':>8}  {'-':>3}"
        else:
            vs_c32 = r["f32"] / r["c32"]
            c_cols = f"{r['c32']:>9.3g}  {vs_c32:>7.2f}x  {met(vs_c32, F32_ANCHOR_TARGET):>3}"
        print(f"{r['n']:>3}  {kernel:>8}  {r['dnnevo']:>9.3g}  {r['f32']:>9.3g}  {ratio:>6.2f}x  "
              f"{met(ratio, F32_TARGET):>3}  {c_cols}  {r['f32_max']:>12.2e}  "
              f"{r['f32_median']:>8.1e}")
    print(f"(max|f32-f64|: the largest state difference over every step and neuron of the first "
          f"{results[0]['f32_nets']} networks; median: of each network's largest)")
    if results[0]["c32_diff"] is not None:
        print("float C anchor against the double one, final states: max |diff| "
              + ", ".join(f"{r['c32_diff']:.1e} (N = {r['n']})" for r in results))
    print(f"total benchmark time: {time.perf_counter() - start:.1f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
