"""Benchmark: one generation of the 1-bit sequence-learning experiment at the paper's size, dnnevo
against a batched NumPy implementation of the same task.

Workload (preset sequence-1bit, paper §5.2):
  P = 1000 networks of N = 5 neurons (the GA's initial population, uniform over the ranges),
  4 trials (2 per target of B = {0*, 1*}) of 10 triggers, trigger and reinforcement 10 time steps,
  delay and gap uniform in [10, 40], 10 forward-Euler steps of dt = 0.1 per time step.

Figures, in seconds per generation (median of timed runs after a quarter-second warm-up, over generations
0, 1, 2, ... so the timings vary as in a run):
  dnnevo assess   dnnevo.evaluate("sequence", genomes, generation=g, seed=0, config=cfg), all cores
                    (and with threads=1, for a per-core comparison, and with precision = "f32")
  dnnevo generation one whole generation of the GA on the Rust side (evaluate + breed), as
                    dnnevo.evolution.evolve runs it (GeneticAlgorithm.step)
  numpy evaluate    tests/sequence_reference.py, batched over P with einsum, one core, with the
                    same timings (dnnevo.tasks.sequence.timings); --numpy-repeats runs (default 1)
The projection is 500 generations (the paper's run) at that rate, against the target of 60 s.
The fitness values of dnnevo and NumPy are compared network by network (atol 1e-9).

    python bench/sequence.py [--repeats 7] [--numpy-repeats 1] [--quick]

Exits with 1 if the two codes disagree; a missed target is reported, not an error.

With --presets, it times instead the three costliest experiments of `dnnevo reproduce` at their
paper sizes (sequence-3bit, sequence-2bit-direct, sequence-2bit-direct16: P = 1000, N = 10, 10
and 16), seed 0: --warm generations run untimed (a GA's population fills with copies of its
parents over the first generations, and dnnevo scores each distinct genome once), then
each of --timed generations is timed twice, as the evaluation alone
(dnnevo.evaluate on the population) and as the whole generation on the Rust side
(GeneticAlgorithm.step: evaluation, validation of the 10 best candidates, breeding). Both wall
and CPU seconds (all threads of the process) are printed, medians over the timed generations,
with the share of distinct genomes in them and the projected wall time of the preset's whole
run. The same population is also evaluated with precision = "f32" (the same work in single
precision), and its wall time and the f64/f32 ratio are printed beside. The script uses only
public API, so the same script times an older build (without the f32 columns):

    python bench/sequence.py --presets [--warm 10] [--timed 5]
"""

from __future__ import annotations

import argparse
import dataclasses
import resource
import statistics
import sys
import time

import numpy as np

import dnnevo
import dnnevo.tasks.sequence
from _common import describe_machine, load_reference, median_time, threads, timed

GENERATIONS = 500  # the paper's 1-bit run
TARGET_S = 60.0  # the whole run, wall time
TOL = 1e-9


ref = load_reference()


def numpy_fitness(cfg, params, generation: int, seed: int):
    """The reference fitness of one generation, with the timings evolution draws."""
    p = cfg.task_params
    n_trials = len(p["targets"]) * p["trials_per_target"]
    timings = [dnnevo.tasks.sequence.timings(cfg, seed, generation, t) for t in range(n_trials)]
    f, _ = ref.fitness(params, p["targets"], timings, p["trials_per_target"],
                       perf_base=p["perf_base"], dt=cfg.integrator.dt,
                       substeps=cfg.integrator.substeps)
    return f


PRESETS = ("sequence-3bit", "sequence-2bit-direct", "sequence-2bit-direct16")


def cpu_seconds() -> float:
    """CPU seconds of this process so far, every thread's."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def clocked(fn):
    """(wall seconds, CPU seconds) of one call `fn()`."""
    wall, cpu = time.perf_counter(), cpu_seconds()
    fn()
    return time.perf_counter() - wall, cpu_seconds() - cpu


def presets_part(args) -> int:
    describe_machine()
    print(f"workload: the three costliest presets of dnnevo reproduce at their paper sizes, seed 0; "
          f"{args.warm} untimed generations, then {args.timed} timed (medians); all cores")
    print()
    single = "precision" in {f.name for f in dataclasses.fields(dnnevo.EvolutionConfig)}
    header = (f"{'preset':<24}  {'N':>2}  {'gens':>4}  {'distinct':>8}  {'eval wall s':>11}  "
              f"{'eval CPU s':>10}  {'gen wall s':>10}  {'gen CPU s':>9}  {'run (proj.)':>11}"
              + (f"  {'eval f32 wall s':>15}  {'f64/f32':>7}" if single else ""))
    print(header)
    print("-" * len(header))
    start = time.perf_counter()
    for name in PRESETS:
        cfg = dnnevo.presets.get(name)
        ga = dnnevo.GeneticAlgorithm(cfg, seed=0)
        for _ in range(args.warm):
            ga.step()
        evals, gens, distinct, singles = [], [], [], []
        for _ in range(args.timed):
            genomes = ga.ask().genomes
            distinct.append(len(np.unique(genomes.view(np.uint64), axis=0)) / len(genomes))
            evals.append(clocked(lambda: dnnevo.evaluate(cfg.task, genomes, generation=ga.generation,
                                                         seed=0, config=cfg)))
            if single:
                f32 = dataclasses.replace(cfg, precision="f32")
                singles.append(clocked(lambda: dnnevo.evaluate(cfg.task, genomes, generation=ga.generation,
                                                               seed=0, config=f32)))
            gens.append(clocked(ga.step))
        med = lambda xs, i: statistics.median(x[i] for x in xs)  # noqa: E731
        run = med(gens, 0) * cfg.generations
        print(f"{name:<24}  {cfg.size:>2}  {cfg.generations:>4}  {statistics.median(distinct):>8.0%}  "
              f"{med(evals, 0):>11.3f}  {med(evals, 1):>10.3f}  {med(gens, 0):>10.3f}  "
              f"{med(gens, 1):>9.3f}  {run / 60:>9.1f} m"
              + (f"  {med(singles, 0):>15.3f}  {med(evals, 0) / med(singles, 0):>6.2f}x" if single else ""))
    print(f"total benchmark time: {time.perf_counter() - start:.1f} s")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--presets", action="store_true",
                    help="time the three costliest paper presets instead (see above)")
    ap.add_argument("--warm", type=int, default=10,
                    help="with --presets: untimed generations first (default 10)")
    ap.add_argument("--timed", type=int, default=5,
                    help="with --presets: timed generations (default 5)")
    ap.add_argument("--repeats", type=int, default=7,
                    help="timed dnnevo runs; the median is reported (default 7)")
    ap.add_argument("--numpy-repeats", type=int, default=1,
                    help="timed NumPy generations (default 1; about 1-2 s each)")
    ap.add_argument("--quick", action="store_true", help="fewer repeats (figures are rougher)")
    args = ap.parse_args(argv)
    if args.presets:
        if args.quick:
            args.warm, args.timed = min(args.warm, 3), min(args.timed, 2)
        if args.warm < 0 or args.timed < 1:
            ap.error("--warm must be >= 0 and --timed >= 1")
        return presets_part(args)
    if args.quick:
        args.repeats = min(args.repeats, 3)
        args.numpy_repeats = 1
    if args.repeats < 1 or args.numpy_repeats < 1:
        ap.error("--repeats and --numpy-repeats must be >= 1")

    cfg = dnnevo.presets.get("sequence-1bit")
    seed = 0
    ga = dnnevo.GeneticAlgorithm(cfg, seed=seed)
    genomes = ga.ask().genomes
    params = ref.decode_genomes(genomes, cfg.size, cfg.n_inputs)

    describe_machine()
    print(f"workload: preset sequence-1bit, P = {cfg.population}, N = {cfg.size}, "
          f"{len(cfg.task_params['targets']) * cfg.task_params['trials_per_target']} trials x 10 "
          f"triggers, {cfg.integrator.substeps} Euler steps of dt = {cfg.integrator.dt} per time "
          f"step; median of {args.repeats} (dnnevo) / {args.numpy_repeats} (numpy) runs"
          f"{' [quick]' if args.quick else ''}")
    print()
    start = time.perf_counter()

    def dnnevo_evaluate(g):
        return dnnevo.evaluate("sequence", genomes, generation=g, seed=seed, config=cfg)

    t_eval, _ = median_time(dnnevo_evaluate, args.repeats)
    f32 = dataclasses.replace(cfg, precision="f32")
    t_eval32, _ = median_time(
        lambda g: dnnevo.evaluate("sequence", genomes, generation=g, seed=seed, config=f32), args.repeats)
    t_eval1, _ = median_time(
        lambda g: dnnevo.evaluate("sequence", genomes, generation=g, seed=seed, config=cfg,
                                  threads=1), args.repeats)

    def dnnevo_generation(_):
        return ga.step()

    t_gen, _ = median_time(dnnevo_generation, args.repeats)

    numpy_times = []
    agree = None
    for g in range(args.numpy_repeats):
        t, theirs = timed(lambda: numpy_fitness(cfg, params, g, seed))
        numpy_times.append(t)
        if g == 0:
            ours = dnnevo_evaluate(0)
            diff = np.abs(ours - theirs)
            agree = (int(np.sum(diff <= TOL)), len(diff), float(diff.max()))
    t_numpy = statistics.median(numpy_times)

    rows = [("dnnevo assess", t_eval), ("dnnevo assess, 1 thread", t_eval1),
            ("dnnevo assess, f32", t_eval32),
            ("dnnevo generation (eval + GA)", t_gen),
            ("numpy evaluate (1 core)", t_numpy)]
    header = (f"{'code':<30}  {'s/generation':>12}  {'generations/s':>13}  "
              f"{'500 gens':>10}  {'target':>7}  {'met':>3}")
    print(header)
    print("-" * len(header))
    for name, t in rows:
        total = t * GENERATIONS
        print(f"{name:<30}  {t:>12.4f}  {1.0 / t:>13.2f}  {total:>9.1f}s  "
              f"{'<=' + format(TARGET_S, 'g') + 's':>7}  {'yes' if total <= TARGET_S else 'NO':>3}")
    print()
    print(f"speed-up, dnnevo assess vs numpy: {t_numpy / t_eval:.1f}x "
          f"(one core each: {t_numpy / t_eval1:.1f}x; dnnevo on {threads()} threads: "
          f"{t_eval1 / t_eval:.2f}x its 1-thread speed)")
    print(f"speed-up, dnnevo generation vs numpy evaluate alone: {t_numpy / t_gen:.1f}x")
    print(f"speed-up, dnnevo assess in f32 vs f64 (precision = \"f32\", the same work): "
          f"{t_eval / t_eval32:.2f}x")
    print(f"GA share of a dnnevo generation: {max(0.0, t_gen - t_eval) / t_gen:.2%} "
          f"(difference of two medians; noisy)")
    n_ok, n, max_diff = agree
    ok = n_ok == n
    print(f"agreement, generation 0: {n_ok}/{n} fitness values within {TOL:g} "
          f"(max |diff| {max_diff:.1e}): {'OK' if ok else 'FAILED'}")
    print(f"total benchmark time: {time.perf_counter() - start:.1f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
