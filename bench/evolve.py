"""Benchmark: what the generation loop costs around the evaluation, at the paper's size
(preset sequence-1bit: P = 1000, N = 5, 4 trials of 10 triggers).

(a) GA overhead per generation, as a share of dnnevo's evaluation time (target < 1 %):
  evaluate      dnnevo.evaluate("sequence", genomes, ...) of the current population (median)
  GA step       ga.tell(fitness) with a fixed fitness vector: proportional selection,
                crossover, mutation and the champion/statistics bookkeeping, in Rust (median)
  loop          dnnevo.evolve("sequence", ..., out=folder) for --generations generations: wall
                time per generation minus the evaluate median (= GA step + the validation of the
                champion's candidates, measured alone in (c) + Python bookkeeping: run log,
                best.json, checkpoints, progress); and, from the run's own history,
                the Python bookkeeping alone (time between generations outside the Rust step)
  numpy GA      the same operators in NumPy (selection by cumsum + searchsorted, one-point
                crossover at neuron boundaries, per-gene resampling, statistics and champion)

(b) Evaluations per second inside dnnevo.evolution.evolve: the built-in "sequence" task against a Python
  fitness callable (tests/sequence_reference.py, batched NumPy, with the same timings), for a few
  generations each. Both runs start from the same seed; their per-generation mean fitness is
  compared as a check that the callable computes the same fitness.

(c) What validated champions cost: for each task, the wall time per generation of a run with the
  default validation_candidates (10) against the same run with validation_candidates = 0
  (evolution is bit-identical, so the difference is the validation and the success checks of the
  champions it picks), and of the same run with champion_step_check = true (would-be champions
  validated again at dt/10; its overhead is over the validated run), runs interleaved, medians
  of --validation-repeats.

    python bench/evolve.py [--generations 40] [--py-generations 3] [--repeats 30] [--quick]
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import dnnevo
import dnnevo.tasks.sequence
from dnnevo.evolution.evolve import CHECKPOINT_SECONDS, LOG_SECONDS
from dnnevo.runs import RunDir
from _common import describe_machine, load_reference, median_time

TARGET_SHARE = 0.01
GENERATIONS = 500  # the paper's 1-bit run


ref = load_reference()


class NumpyGA:
    """The paper's GA operators over a (P, G) genome array, written in NumPy."""

    def __init__(self, cfg, genomes, seed=0):
        n, m = cfg.size, cfg.n_inputs
        self.pop = np.array(genomes, dtype=np.float64)
        self.p, self.g = self.pop.shape
        self.rng = np.random.default_rng(seed)
        self.crossover_rate = cfg.crossover_rate
        self.mutation_rate = cfg.mutation_rate
        r = cfg.ranges
        block = [r.tau, r.theta] + [r.sensor_weights] * m + [r.weights] * n
        lo_hi = np.array(block * n, dtype=np.float64)
        self.low, self.span = lo_hi[:, 0], lo_hi[:, 1] - lo_hi[:, 0]
        self.neuron = np.arange(self.g) // (2 + m + n)  # which neuron each gene belongs to
        self.n = n
        self.best = (-np.inf, None, -1)
        self.generation = 0

    def tell(self, fitness):
        f = np.asarray(fitness, dtype=np.float64)
        stats = dict(best=f.max(), mean=f.mean(), std=f.std(), min=f.min())
        i = int(np.argmax(f))
        if f[i] > self.best[0]:
            self.best = (f[i], self.pop[i].copy(), self.generation)
        rng, p = self.rng, self.p
        # Fitness-proportional selection (uniform when every fitness is 0).
        cum = np.cumsum(f)
        if cum[-1] > 0:
            pick = lambda k: np.minimum(np.searchsorted(cum, rng.random(k) * cum[-1],
                                                        side="right"), p - 1)
        else:
            pick = lambda k: rng.integers(0, p, k)
        first = pick(p)
        child = self.pop[first]
        # One-point crossover at a neuron boundary: neurons < x from the first parent.
        cross = np.flatnonzero(rng.random(p) < self.crossover_rate)
        if len(cross) and self.n > 1:
            second = self.pop[pick(len(cross))]
            cut = rng.integers(1, self.n, len(cross))
            from_second = self.neuron[None, :] >= cut[:, None]
            child[cross] = np.where(from_second, second, child[cross])
        # Mutation: each gene resampled uniformly over its range with probability mutation_rate.
        rows, cols = np.nonzero(rng.random((p, self.g)) < self.mutation_rate)
        child[rows, cols] = self.low[cols] + self.span[cols] * rng.random(len(cols))
        self.pop = child
        self.generation += 1
        return stats


def part_a(cfg, args):
    ga = dnnevo.GeneticAlgorithm(cfg, seed=0)
    genomes = ga.ask().genomes
    t_eval, _ = median_time(lambda g: dnnevo.evaluate("sequence", genomes, generation=g, seed=0,
                                                      config=cfg), args.eval_repeats)
    fitness = np.random.default_rng(1).random(cfg.population)
    t_tell, _ = median_time(lambda _: ga.tell(fitness), args.repeats)
    npga = NumpyGA(cfg, genomes)
    t_numpy, _ = median_time(lambda _: npga.tell(fitness), args.repeats)

    run_cfg = dataclasses.replace(cfg, generations=args.generations)
    with tempfile.TemporaryDirectory(dir=args.out_dir) as tmp:
        start = time.perf_counter()
        result = dnnevo.evolve("sequence", run_cfg, seed=0, out=Path(tmp) / "run", progress=False)
        total = time.perf_counter() - start
        # Late in the paper's run: the log rewritten with 500 rows, and a checkpoint.
        run = RunDir(Path(tmp) / "run")
        rows = [{k: float(v[i % args.generations]) for k, v in result.history.items()}
                for i in range(GENERATIONS)]
        t_log, _ = median_time(lambda _: run.write_log(rows), 5)
        t_ckpt, _ = median_time(lambda _: run.write_checkpoint(ga.state_dict(), rows, {"seed": ga.seed},
                                                               ga.seed), 3)
    h = result.history
    per_gen = float(h["elapsed_s"][-1]) / args.generations  # the loop, without the run's setup
    step = cfg.population / h["evals_per_s"]  # seconds of each generation's Rust step
    between = np.diff(np.concatenate([[0.0], h["elapsed_s"]]))  # wall time of each generation
    bookkeeping = statistics.median(between - step)
    return dict(eval=t_eval, tell=t_tell, numpy=t_numpy, per_gen=per_gen, total=total,
                step=statistics.median(step), bookkeeping=bookkeeping,
                setup=total - float(h["elapsed_s"][-1]), log500=t_log, ckpt=t_ckpt)


def part_b(cfg, args):
    run_cfg = dataclasses.replace(cfg, generations=args.py_generations)
    p = cfg.task_params
    n_trials = len(p["targets"]) * p["trials_per_target"]
    seed = 0
    generation = 0

    def fitness(networks):
        nonlocal generation
        timings = [dnnevo.tasks.sequence.timings(cfg, seed, generation, t) for t in range(n_trials)]
        generation += 1
        f, _ = ref.fitness(ref.stack_networks(networks), p["targets"], timings,
                           p["trials_per_target"], perf_base=p["perf_base"],
                           dt=cfg.integrator.dt, substeps=cfg.integrator.substeps)
        return f

    start = time.perf_counter()
    py = dnnevo.evolve(fitness, run_cfg, seed=seed, progress=False)
    t_py = time.perf_counter() - start
    start = time.perf_counter()
    rust = dnnevo.evolve("sequence", run_cfg, seed=seed, progress=False)
    t_rust = time.perf_counter() - start
    return dict(py=py, rust=rust, t_py=t_py, t_rust=t_rust)


# (preset, overrides, generations): a generation of each task at its paper size.
VALIDATION_RUNS = (
    ("sequence-1bit", [], 20),
    ("nav1d-classifier", [], 10),
    ("landmark", ["elitism=5"], 60),
)


def part_c(args):
    rows = []
    for preset, overrides, generations in VALIDATION_RUNS:
        generations = max(2, generations // 4) if args.quick else generations
        cfg = dnnevo.presets.get(preset, overrides=[*overrides, f"generations={generations}"])
        runs = {"on": cfg, "off": dataclasses.replace(cfg, validation_candidates=0),
                "checked": dataclasses.replace(cfg, champion_step_check=True)}
        times: dict[str, list[float]] = {key: [] for key in runs}
        for _ in range(args.validation_repeats):
            for key, c in runs.items():
                result = dnnevo.evolve(cfg.task, c, seed=0, progress=False)
                times[key].append(float(result.history["elapsed_s"][-1]) / generations)
        rows.append((preset, cfg.validation_candidates,
                     *(statistics.median(times[key]) for key in ("on", "off", "checked"))))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--generations", type=int, default=40,
                    help="generations of the timed dnnevo.evolution.evolve run in (a) (default 40)")
    ap.add_argument("--py-generations", type=int, default=3,
                    help="generations of each run in (b) (default 3; the NumPy fitness takes "
                         "about 1-2 s per generation)")
    ap.add_argument("--repeats", type=int, default=30,
                    help="timed GA steps, dnnevo and NumPy; the median is reported (default 30)")
    ap.add_argument("--out-dir", default=None,
                    help="where the timed run folder of (a) is made (default: the system's "
                         "temporary folder); fsync costs depend on the disk")
    ap.add_argument("--validation-repeats", type=int, default=3,
                    help="interleaved runs with and without validation in (c) (default 3)")
    ap.add_argument("--quick", action="store_true", help="fewer generations and repeats")
    args = ap.parse_args(argv)
    args.eval_repeats = 7
    if args.quick:
        args.generations = min(args.generations, 8)
        args.py_generations = min(args.py_generations, 2)
        args.repeats = min(args.repeats, 10)
        args.eval_repeats = 3
        args.validation_repeats = 1
    if min(args.generations, args.py_generations, args.repeats, args.validation_repeats) < 1:
        ap.error("--generations, --py-generations, --repeats and --validation-repeats must be >= 1")

    cfg = dnnevo.presets.get("sequence-1bit")
    describe_machine()
    print(f"workload: preset sequence-1bit, P = {cfg.population}, N = {cfg.size}, crossover "
          f"{cfg.crossover_rate}, mutation {cfg.mutation_rate}{' [quick]' if args.quick else ''}")
    start = time.perf_counter()

    a = part_a(cfg, args)
    e = a["eval"]
    print()
    print(f"(a) GA overhead per generation (medians; evaluate = {e * 1e3:.1f} ms per generation)")
    header = f"{'part':<46}  {'ms/generation':>13}  {'% of evaluate':>13}  {'target':>7}  {'met':>3}"
    print(header)
    print("-" * len(header))

    def row(name, t, target=True):
        share = t / e
        met = ("yes" if share < TARGET_SHARE else "NO") if target else ""
        tgt = f"<{TARGET_SHARE:.0%}" if target else ""
        print(f"{name:<46}  {t * 1e3:>13.3f}  {share:>12.2%}  {tgt:>7}  {met:>3}")

    row(f"dnnevo GA step (tell, median of {args.repeats})", a["tell"])
    row(f"evolve loop - evaluate ({args.generations} gens, out=; with (c))", a["per_gen"] - e)
    row("  of which Python bookkeeping (from history)", a["bookkeeping"])
    row(f"  run setup + final checkpoint, / {args.generations} gens", a["setup"] / args.generations,
        False)
    row(f"log.csv rewrite at generation {GENERATIONS} ({a['log500'] * 1e3:.1f} ms) "
        f"every {LOG_SECONDS:g} s, per generation",
        a["log500"] * a["per_gen"] / LOG_SECONDS)
    row(f"checkpoint ({a['ckpt'] * 1e3:.0f} ms) every {CHECKPOINT_SECONDS:g} s, per generation",
        a["ckpt"] * a["per_gen"] / CHECKPOINT_SECONDS)
    row(f"numpy GA step (median of {args.repeats})", a["numpy"], False)
    print(f"numpy GA / dnnevo GA step: {a['numpy'] / a['tell']:.1f}x")
    print(f"evolve: {a['total']:.2f} s for {args.generations} generations, loop "
          f"({a['per_gen'] * 1e3:.1f} ms each; Rust step median {a['step'] * 1e3:.1f} ms); "
          f"'loop - evaluate' is a difference of\n  separately measured times, so noisy (it can be "
          f"negative); the history-based row is not")

    b = part_b(cfg, args)
    p = cfg.population
    print()
    print(f"(b) evaluations per second inside dnnevo.evolution.evolve, {args.py_generations} generations "
          f"of P = {p} (median over generations; wall time includes setup)")
    header = f"{'fitness':<38}  {'evals/s':>10}  {'s/generation':>12}  {'wall s':>7}"
    print(header)
    print("-" * len(header))
    for name, key, t in (("built-in 'sequence' (Rust, all cores)", "rust", b["t_rust"]),
                         ("Python callable (NumPy reference)", "py", b["t_py"])):
        eps = float(np.median(b[key].history["evals_per_s"]))
        print(f"{name:<38}  {eps:>10.0f}  {p / eps:>12.4f}  {t:>7.2f}")
    rust_eps = float(np.median(b["rust"].history["evals_per_s"]))
    py_eps = float(np.median(b["py"].history["evals_per_s"]))
    print(f"built-in / Python callable: {rust_eps / py_eps:.1f}x")
    diff = np.abs(b["py"].history["mean"] - b["rust"].history["mean"]).max()
    ok = diff <= 1e-9
    print(f"same fitness: per-generation mean fitness of the two runs differs by at most "
          f"{diff:.1e}: {'OK' if ok else 'DIFFERENT'}")

    print()
    print(f"(c) validated champions: wall time per generation (medians of "
          f"{args.validation_repeats} interleaved runs each)")
    header = (f"{'preset':<18}  {'candidates':>10}  {'with ms/gen':>11}  {'without ms/gen':>14}  "
              f"{'overhead':>8}  {'step-checked ms/gen':>19}  {'overhead':>8}")
    print(header)
    print("-" * len(header))
    for preset, k, on, off, checked in part_c(args):
        print(f"{preset:<18}  {k:>10}  {on * 1e3:>11.1f}  {off * 1e3:>14.1f}  {on / off - 1:>8.1%}  "
              f"{checked * 1e3:>19.1f}  {checked / on - 1:>8.1%}")
    print(f"total benchmark time: {time.perf_counter() - start:.1f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
