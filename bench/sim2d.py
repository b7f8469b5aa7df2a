"""Benchmark: the 2-D world of the landmark experiment (paper §3): dnnevo's ray casts against a
vectorised NumPy slab-method implementation, and a robot trial and a generation against real time.

Workload:
  rays        K = 200 000 rays in landmark 2's world (landmark.default_world(2): room 6 x 5 m, two
              0.6 m crates centred at (2.4, 2.5) and (3.6, 2.5)); origins uniform in the room
              outside the crates, directions uniform in angle; max distance 6.5 m (the sonar's
              range). dnnevo: landmark.cast_rays(world, origins, directions, 6.5), one call (a
              serial loop over parry2d f32 ray casts on one core, including the world's JSON and
              the array copies). NumPy: the slab method batched over K rays x crates, plus the
              room's exit distance for the four walls (seen from inside), float64, one core.
              Figures in rays/s (K / median seconds). Agreement: max |diff| < 1e-4 m (parry2d
              computes in f32). A ray that passes within 1e-5 m of a crate's corner may hit in one
              code and miss in the other; such rays are reported as rounding, not disagreement.
              The largest differences (a few 1e-5 m) come from rays leaving an origin millimetres
              from a wall at a grazing angle: f32 rounding of the origin, magnified 1/sin(angle).
  trial       landmark.record(config, net, 2, seed=0, trial=k), k = 0, 1, ...: one 45 s trial
              (450 steps of 0.1 s: wall follower, 7-ray sonar, an 8-neuron network with 10 Euler
              substeps per step), including the network run and the step-by-step record's JSON
              transfer to Python (about 130 kB, most of the time). Without the JSON: evaluate of
              one network (6 trials, threads=1) / 6. Compared with the real robot's 135 s for the
              same trial (the simulated robot drives at 0.6 m/s, 3x the real robot's 0.2 m/s, as
              in the paper).
  generation  dnnevo.evaluate("landmark", genomes, generation=0, seed=0,
              config=presets.get("landmark")): P = 100 random networks (the GA's initial
              population) x 6 trials (3 per landmark), all cores and threads=1. The wall follower,
              not the network, drives the robot, so each trial's sensing is simulated once and fed
              to all P networks: a generation is 6 world simulations and 600 network runs; the
              real robot could do the same in 6 x 135 s. The cost of one more network per trial
              (the network run alone) is (generation - one network's evaluate) / (99 x 6).
record's net is the first network of that population. Every figure is the median of timed
runs after a quarter-second warm-up.

    python bench/sim2d.py [--repeats 15] [--rays 200000] [--quick]

Exits with 1 if the two ray casts disagree.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import dnnevo
from dnnevo.tasks import landmark
from dnnevo import presets
from _common import describe_machine, median_time, threads

MAX_DISTANCE = 6.5  # the sonar's range, m
TOL = 1e-4  # m; parry2d computes in f32
GRAZE = 1e-5  # m; a ray this close to a crate's corner may hit in one code and miss in the other
REAL_TRIAL_S = 135.0  # the paper: the simulated 45 s correspond to 135 s on the real robot
SIM_TRIAL_S = 45.0
LANDMARK = 2


def boxes_of(world: dict) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi), each (B, 2): the corners of the world's boxes (axis-aligned only)."""
    if any(b["angle_deg"] % 90.0 for b in world["boxes"]):
        raise ValueError("the NumPy reference handles axis-aligned boxes only")
    center = np.array([b["center"] for b in world["boxes"]], dtype=float).reshape(-1, 2)
    half = 0.5 * np.array([b["size"] if b["angle_deg"] % 180.0 == 0 else b["size"][::-1]
                           for b in world["boxes"]], dtype=float).reshape(-1, 2)
    return center - half, center + half


def random_rays(world: dict, k: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """K origins uniform in the room outside the boxes, and K unit directions uniform in angle."""
    rng = np.random.default_rng(seed)
    w, h = world["room"]
    lo, hi = boxes_of(world)
    origins = np.empty((0, 2))
    while len(origins) < k:
        o = rng.uniform((0.0, 0.0), (w, h), size=(2 * k, 2))
        inside = ((o[:, None, :] > lo) & (o[:, None, :] < hi)).all(axis=2).any(axis=1)
        origins = np.concatenate([origins, o[~inside]])
    angle = rng.uniform(-np.pi, np.pi, size=k)
    return np.ascontiguousarray(origins[:k]), np.stack([np.cos(angle), np.sin(angle)], axis=1)


def numpy_cast_rays(world: dict, origins: np.ndarray, directions: np.ndarray,
                    max_distance: float = MAX_DISTANCE) -> np.ndarray:
    """Distance along each ray to the nearest wall or box, or `max_distance`: the slab method.

    Walls: the room [0, w] x [0, h] seen from inside, i.e. the ray's exit distance, the smaller of
    its distances to the far x and the far y boundary. Boxes [lo, hi]: entry t_near = max over
    axes of min(t1, t2), exit t_far = min over axes of max(t1, t2) with t1, t2 the distances to
    the two slab planes; a hit when max(t_near, 0) <= t_far (an origin inside a box hits at 0).
    Batched over rays x boxes; a zero direction component gives +-inf slab distances, as it should.
    """
    w, h = world["room"]
    lo, hi = boxes_of(world)
    ox, oy = origins[:, 0:1], origins[:, 1:2]  # (K, 1)
    norm = np.hypot(directions[:, 0], directions[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        ix = (norm / directions[:, 0])[:, None]  # 1 / unit direction, (K, 1)
        iy = (norm / directions[:, 1])[:, None]
        # Walls: distance to the far boundary along each axis (inv's sign picks it, also for -0).
        tx = (np.where(ix > 0, w, 0.0) - ox) * ix
        ty = (np.where(iy > 0, h, 0.0) - oy) * iy
        best = np.minimum(np.minimum(tx, ty)[:, 0], max_distance)
        # Boxes: (K, B) slab distances.
        x1 = (lo[:, 0] - ox) * ix
        x2 = (hi[:, 0] - ox) * ix
        y1 = (lo[:, 1] - oy) * iy
        y2 = (hi[:, 1] - oy) * iy
        t_near = np.maximum(np.minimum(x1, x2), np.minimum(y1, y2))
        t_far = np.minimum(np.maximum(x1, x2), np.maximum(y1, y2))
    np.maximum(t_near, 0.0, out=t_near)
    t_box = np.where(t_near <= t_far, t_near, np.inf).min(axis=1)
    return np.minimum(best, t_box)


def grazes_corner(world: dict, origins: np.ndarray, directions: np.ndarray,
                  eps: float = GRAZE) -> np.ndarray:
    """Whether each ray passes within `eps` of a box corner ahead of its origin."""
    lo, hi = boxes_of(world)
    corners = np.concatenate([lo, hi, np.stack([lo[:, 0], hi[:, 1]], 1),
                              np.stack([hi[:, 0], lo[:, 1]], 1)])  # (4B, 2)
    d = directions / np.hypot(directions[:, 0], directions[:, 1])[:, None]
    rel = corners[None, :, :] - origins[:, None, :]  # (K, C, 2)
    along = rel[..., 0] * d[:, None, 0] + rel[..., 1] * d[:, None, 1]
    across = np.abs(rel[..., 0] * d[:, None, 1] - rel[..., 1] * d[:, None, 0])
    return ((along > 0) & (across < eps)).any(axis=1)


def bench_rays(world: dict, args) -> dict:
    origins, directions = random_rays(world, args.rays)
    t_dnnevo, ours = median_time(
        lambda _: landmark.cast_rays(world, origins, directions, MAX_DISTANCE), args.repeats)
    t_numpy, theirs = median_time(
        lambda _: numpy_cast_rays(world, origins, directions, MAX_DISTANCE), args.repeats)
    diff = np.abs(np.asarray(ours) - theirs)
    bad = np.flatnonzero(diff >= TOL)
    grazing = grazes_corner(world, origins[bad], directions[bad]) if bad.size else np.zeros(0, bool)
    return dict(
        k=args.rays,
        dnnevo=args.rays / t_dnnevo,
        numpy=args.rays / t_numpy,
        max_diff=float(diff.max()),
        max_diff_ok=float(np.delete(diff, bad).max()) if bad.size < diff.size else 0.0,
        grazing=bad[grazing],
        unexplained=bad[~grazing],
        at_max=int(np.sum(theirs >= MAX_DISTANCE)),
    )


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=15,
                    help="timed runs of each figure; the median is reported (default 15)")
    ap.add_argument("--rays", type=int, default=200_000, help="rays per batch (default 200000)")
    ap.add_argument("--quick", action="store_true",
                    help="a smoke run: 50 000 rays and 3 repeats (figures are rougher)")
    args = ap.parse_args(argv)
    if args.quick:
        args.rays, args.repeats = min(args.rays, 50_000), min(args.repeats, 3)
    if args.repeats < 1 or args.rays < 1:
        ap.error("--repeats and --rays must be >= 1")
    trial_repeats = max(args.repeats, 9)  # cheap; at least 9 even with --quick

    cfg = presets.get("landmark")
    world = landmark.default_world(LANDMARK)
    batch = dnnevo.GeneticAlgorithm(cfg, seed=0).ask()
    genomes, net = batch.genomes, batch.networks[0]
    n_trials = 2 * cfg.task_params["trials_per_landmark"]

    describe_machine()
    print(f"workload: landmark-{LANDMARK} world (room {world['room'][0]:g} x "
          f"{world['room'][1]:g} m, {len(world['boxes'])} crates), K = {args.rays} rays, max "
          f"{MAX_DISTANCE} m; {SIM_TRIAL_S:g} s trials (landmark.record, {trial_repeats} trials); "
          f"preset landmark: P = {cfg.population}, N = {cfg.size}, {n_trials} trials per network; "
          f"median of {args.repeats} runs{' [quick]' if args.quick else ''}")
    print()
    start = time.perf_counter()

    # 1. Ray casts.
    r = bench_rays(world, args)
    print(f"ray casts, one core each: dnnevo {r['dnnevo']:.4g} rays/s, numpy (slab method) "
          f"{r['numpy']:.4g} rays/s, ratio {r['dnnevo'] / r['numpy']:.2f}x "
          f"({r['at_max']} of {r['k']} rays reach {MAX_DISTANCE} m)")
    ok = len(r["unexplained"]) == 0
    line = (f"agreement: {r['k'] - len(r['grazing']) - len(r['unexplained'])}/{r['k']} distances "
            f"within {TOL:g} m (max |diff| {r['max_diff_ok']:.1e} m)")
    if len(r["grazing"]):
        line += (f"; {len(r['grazing'])} rays graze a crate's corner (within {GRAZE:g} m) and hit "
                 f"in one code only (f32 rounding; max |diff| {r['max_diff']:.2g} m)")
    if len(r["unexplained"]):
        line += f"; DISAGREE: rays {r['unexplained'][:10].tolist()}"
    print(line + (": OK" if ok else ": FAILED"))
    print()

    # 2. A 45 s trial and a generation.
    t_record, rec = median_time(
        lambda k: landmark.record(cfg, net, LANDMARK, seed=0, trial=k), trial_repeats)
    steps = len(rec.input)

    def evaluate(threads_=None):
        return lambda _: dnnevo.evaluate("landmark", genomes, generation=0, seed=0, config=cfg,
                                         threads=threads_)

    t_gen, fitness = median_time(evaluate(), args.repeats)
    t_gen1, fitness1 = median_time(evaluate(1), args.repeats)
    if not np.array_equal(fitness, fitness1):
        print("note: evaluate with threads=1 scored differently from all threads")
    t_one, _ = median_time(
        lambda _: dnnevo.evaluate("landmark", genomes[:1], generation=0, seed=0, config=cfg,
                                  threads=1), trial_repeats)
    t_trial_eval = t_one / n_trials
    t_net = max(0.0, t_gen1 - t_one) / ((cfg.population - 1) * n_trials)
    real_gen = n_trials * REAL_TRIAL_S
    print(f"45 s trial ({steps} steps), landmark.record (network run + JSON transfer included): "
          f"{t_record * 1e3:.2f} ms, {REAL_TRIAL_S / t_record:.4g}x real time "
          f"(real robot: {REAL_TRIAL_S:g} s)")
    print(f"45 s trial inside evaluate, no JSON (one network's {n_trials} trials, threads=1, / "
          f"{n_trials}): {t_trial_eval * 1e3:.2f} ms, {REAL_TRIAL_S / t_trial_eval:.4g}x real "
          f"time; one more network on a shared trial (network run alone): {t_net * 1e6:.0f} us")
    print(f"generation (P = {cfg.population} x {n_trials} trials, sensing shared): {t_gen:.4f} s "
          f"on {threads()} threads, {t_gen1:.4f} s on 1 ({t_gen1 / t_gen:.2f}x); "
          f"{cfg.generations} generations (the preset's run): {t_gen * cfg.generations:.1f} s; "
          f"real robot: {n_trials} x {REAL_TRIAL_S:g} s = {real_gen:g} s")
    print()

    # 3. Summary.
    rows = [
        ("ray casts (rays/s, 1 core)", f"{r['dnnevo']:.4g}", "numpy slab method",
         f"{r['numpy']:.4g}", r["dnnevo"] / r["numpy"]),
        ("45 s trial, record() (s)", f"{t_record:.4g}", "real robot", f"{REAL_TRIAL_S:g}",
         REAL_TRIAL_S / t_record),
        ("45 s trial in evaluate, no JSON (s)", f"{t_trial_eval:.4g}", "real robot",
         f"{REAL_TRIAL_S:g}", REAL_TRIAL_S / t_trial_eval),
        (f"generation, {threads()} threads (s)", f"{t_gen:.4g}", f"real robot, {n_trials} trials",
         f"{real_gen:g}", real_gen / t_gen),
        ("generation, 1 thread (s)", f"{t_gen1:.4g}", f"real robot, {n_trials} trials",
         f"{real_gen:g}",
         real_gen / t_gen1),
    ]
    header = (f"{'figure':<38}  {'dnnevo':>10}  {'reference':<20}  {'ref. figure':>11}  "
              f"{'ratio':>9}")
    print(header)
    print("-" * len(header))
    for name, ours, ref_name, theirs, ratio in rows:
        print(f"{name:<38}  {ours:>10}  {ref_name:<20}  {theirs:>11}  {ratio:>8.3g}x")
    print()
    print("agreement: OK" if ok else "agreement: FAILED")
    print(f"total benchmark time: {time.perf_counter() - start:.1f} s")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
