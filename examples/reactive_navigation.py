"""Reactive navigation (paper §3.2): does the hand-designed network reach the goal, and do the
static and cyclic detectors turn its failures in traps into arrivals without hurting it where it
needs no help?

Nothing is evolved. The hand-designed network (:func:`dnnevo.robots.navigation.navigator`,
shipped as ``dnnevo/robots/data/navigator.json``) drives :class:`dnnevo.robots.Navigate` in the
three shipped worlds (an open room, a U-shaped trap and a cul-de-sac), from ``--starts`` random
start poses drawn from a seed no run uses (``FRESH_SEED``, ``purpose="evaluate"``), without and
with the detectors, on the same starts. Every row is run again at half the step (the world's
0.05 s instead of 0.1 s and the network's Euler step 0.01 instead of 0.02, twice the steps):
a behaviour that vanishes at a finer step is an artefact of the step::

    python examples/reactive_navigation.py --starts 200 --figure docs/img/reactive-u-trap.png \\
        --record docs/results/examples/reactive-navigation.json

prints one row per world, detectors and step (arrivals with their 95% Wilson interval, the mean
time to arrive, the fraction of steps pressed against a wall or box, the detectors' firings per
start), then, for each world and step, whether the detectors changed the rate with intervals
apart. ``--figure`` draws the paths of the first ``--paths`` starts in the U-trap, without and
with the detectors.

**An evolved comparison**, which the paper does not make: with ``--evolve SEEDS`` the script
instead runs the ``reactive-navigation`` preset for each seed (60 networks of 6 neurons for
``--generations`` generations in the U-trap without detectors, 4 random starts per network per
generation, trials of 60 s, the champion chosen among each generation's 3 best on 10 validation
starts; the landmark GA's crossover 0.5 and mutation 0.025, rank selection, 3 elites), and judges each champion on the fresh starts of every world, beside the hand-designed
network without and with the detectors::

    python examples/reactive_navigation.py --evolve 5 --starts 200 \
        --record docs/results/examples/reactive-navigation-evolved.json
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import dnnevo
from dnnevo import plot, presets
from dnnevo.closedloop import named, rollout
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.robots import Navigate
from dnnevo.robots.navigation import INTEGRATOR, WORLDS, Integration, hand_designed, navigator
from dnnevo.runs import save_figure

FRESH_SEED = 2_000_003
"""The seed of the start poses: used by no run, and not by the predator example's 1_000_003."""

PRESET = "reactive-navigation"
"""The evolved comparison's preset."""


def evolve(seed: int, generations: int) -> dnnevo.Network:
    """One seed's champion of the ``reactive-navigation`` preset (``dnnevo presets``), run for
    ``generations``: evolved in the U-trap without detectors (see the module docs)."""
    cfg = presets.get(PRESET, overrides=[f"generations={generations}"])
    result = dnnevo.evolve(named.closed_loop(cfg), cfg, seed=seed, progress=False)
    if result.interrupted:
        raise KeyboardInterrupt
    return result.best


def network_judged(net: dnnevo.Network, world: str, starts: int, *, detectors: bool = False,
                   integrator: Integration | None = None) -> tuple[int, float]:
    """``net``'s arrivals on the fresh starts of ``world`` and the fraction of its steps in
    contact; integrated as evolution ran (10 Euler steps of 0.1) unless ``integrator`` says."""
    env = Navigate(world, detectors=detectors)
    i: Integration = integrator or {"dt": 0.1, "substeps": 10, "method": "euler"}
    r = rollout([net], env, episodes=starts, max_steps=env.steps, seed=FRESH_SEED, purpose="evaluate", **i)
    return int(env.arrived.sum()), float(env.contact_steps.sum() / r.lengths.sum())


def comparison(seeds: int, generations: int, starts: int) -> tuple[list[str], list[list[str]], list[str]]:
    """The evolved comparison's table: the hand-designed network without and with detectors,
    then each seed's evolved champion, in every world."""
    columns = ["network", *(f"{w}: arrived (95% interval), in contact" for w in WORLDS), "seconds"]
    print(" | ".join(columns))
    rows, pooled = [], {w: 0 for w in WORLDS}

    def row(name: str, judge: Any, started: float) -> list[str]:
        cells = [name]
        for w in WORLDS:
            k, contact = judge(w)
            if name.startswith("evolved"):
                pooled[w] += k
            cells.append(f"{rate(k, starts)}, {contact:.1%}")
        cells.append(f"{time.perf_counter() - started:.0f}")
        print(" | ".join(cells), flush=True)
        return cells

    hand = navigator()
    for detectors in (False, True):
        rows.append(row(f"hand-designed, detectors {'on' if detectors else 'off'}",
                        lambda w: network_judged(hand, w, starts, detectors=detectors, integrator=INTEGRATOR),
                        time.perf_counter()))
    for seed in range(seeds):
        started = time.perf_counter()
        net = evolve(seed, generations)
        rows.append(row(f"evolved, seed {seed}", lambda w: network_judged(net, w, starts), started))
    summary = [f"Evolved champions pooled over {seeds} seeds, {w}: {rate(pooled[w], seeds * starts)}." for w in WORLDS]
    summary.append("Evolved in the U-trap alone, without detectors; the open room and the cul-de-sac are worlds "
                   "training never saw. The paper evolved no network for this task.")
    for line in summary:
        print(line)
    return columns, rows, summary


def judged(world: str, detectors: bool, starts: int, *, finer: int = 1, steps: int = 1200) -> dict[str, Any]:
    """The hand-designed network on ``starts`` fresh starts of ``world``
    (:func:`~dnnevo.robots.navigation.hand_designed` from ``FRESH_SEED``), with its ``wall``
    time; with ``finer`` > 1 the world's and the network's steps ``finer`` times shorter (as
    many more steps)."""
    started = time.perf_counter()
    r = hand_designed(world, starts, seed=FRESH_SEED, detectors=detectors, finer=finer, steps=steps)
    return {**r, "wall": time.perf_counter() - started}


def pct(x: float) -> str:
    """A percentage, whole unless that would hide a fraction of a percent from 0 or 100."""
    return f"{x:.1%}" if 0 < x < 0.01 or 0.99 < x < 1 else f"{x:.0%}"


def rate(k: int, n: int) -> str:
    """``k/n`` with its 95% Wilson interval."""
    lo, hi = wilson(k, n)
    return f"{k}/{n} ({pct(lo)}-{pct(hi)})"


def paths(world: str, detectors: bool, starts: int, steps: int = 1200) -> tuple[Navigate, list[np.ndarray], np.ndarray]:
    """The first ``starts`` fresh starts' paths (each (T, 2)) and which arrived."""
    env = Navigate(world, detectors=detectors, steps=steps)
    rng = np.random.default_rng(dnnevo._core.condition_seed(FRESH_SEED, 0, "evaluate"))
    obs = env.reset(np.arange(starts, dtype=np.int64), rng)
    batch = dnnevo.Batch([navigator()], replicas=starts, dt=INTEGRATOR["dt"], substeps=INTEGRATOR["substeps"])
    batch.reset()
    rates = np.empty((starts, batch.size))
    active = np.ones(starts, dtype=bool)
    trail = [env.fleet.poses[:, :2].copy()]
    ends = np.full(starts, steps)
    for t in range(steps):
        batch.step(obs, active=active, out=rates)
        obs, _, done = env.step(rates, active)
        trail.append(env.fleet.poses[:, :2].copy())
        ends[active & done] = t + 1
        active &= ~done
        if not active.any():
            break
    track = np.stack(trail, axis=1)
    return env, [track[i, :ends[i] + 1] for i in range(starts)], env.arrived.copy()


def figure(out: Path, starts: int) -> None:
    """The U-trap seen from above: the first ``starts`` fresh starts' paths without and with the
    detectors."""
    from matplotlib.patches import Circle
    fig, axes = plot.subplots(1, 2, figsize=(10, 4.2), sharey=True)
    for ax, detectors in zip(axes, (False, True)):
        env, tracks, arrived = paths("u-trap", detectors, starts)
        w, h = env.world["room"]
        plot.plot_room(env.world, ax)
        ax.add_patch(Circle(tuple(env.goal), env.goal_radius, color="tab:green", alpha=0.4))
        for track, ok in zip(tracks, arrived):
            ax.plot(track[:, 0], track[:, 1], lw=0.9, color="tab:blue" if ok else "tab:red", alpha=0.8)
            ax.plot(*track[0], "k.", ms=4)
        ax.set_xlim(0, w)
        ax.set_ylim(0, h)
        ax.set_title(f"{'with' if detectors else 'without'} detectors: {arrived.sum()} of {starts} arrive")
        ax.set_xlabel("x (m)")
    axes[0].set_ylabel("y (m)")
    fig.tight_layout()
    save_figure(fig, out)
    plot.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--starts", type=int, default=200, help="fresh start poses per world (default 200)")
    p.add_argument("--steps", type=int, default=1200, help="steps of 0.1 s per trial (default 1200: 120 s)")
    p.add_argument("--figure", type=Path, help="draw the U-trap's paths as this PNG")
    p.add_argument("--paths", type=int, default=12, help="start poses drawn in the figure (default 12)")
    p.add_argument("--evolve", type=int, default=0, metavar="SEEDS",
                   help="instead, evolve this many seeds in the U-trap and compare their champions")
    p.add_argument("--generations", type=int, default=40, help="generations per evolved seed (default 40)")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="write the table as an example's results (docs/results/examples/NAME.json)")
    args = p.parse_args(argv)
    if args.starts < 1 or args.steps < 1 or args.paths < 1 or args.evolve < 0 or args.generations < 1:
        p.error("--starts, --steps, --paths and --generations must be at least 1, --evolve at least 0")
    if args.evolve:
        columns, table, lines = comparison(args.evolve, args.generations, args.starts)
        if args.record:
            examples.write(args.record, command=examples.command("examples/reactive_navigation.py", argv),
                           columns=columns, rows=table, summary=lines)
        return 0
    rows, results = [], {}
    columns = ["world", "detectors", "step", "arrived (95% interval)", "mean time to arrive",
               "steps in contact", "static / cyclic firings per start"]
    print(" | ".join(columns))
    for world in WORLDS:
        for finer in (1, 2):
            for detectors in (False, True):
                r = judged(world, detectors, args.starts, finer=finer, steps=args.steps)
                results[world, finer, detectors] = r
                row = [world, "on" if detectors else "off", f"{r['dt']:g} s", rate(r["arrived"], r["starts"]),
                       "-" if np.isnan(r["time"]) else f"{r['time']:.1f} s", f"{r['contact']:.1%}",
                       f"{r['static']:.2f} / {r['cyclic']:.2f}" if detectors else "-"]
                rows.append(row)
                print(" | ".join(row), f"({r['wall']:.1f} s)", flush=True)
    summary = []
    for world in WORLDS:
        for finer in (1, 2):
            off, on = results[world, finer, False], results[world, finer, True]
            lo_off, hi_off = wilson(off["arrived"], off["starts"])
            lo_on, hi_on = wilson(on["arrived"], on["starts"])
            verdict = ("higher, intervals apart" if lo_on > hi_off else "lower, intervals apart" if hi_on < lo_off
                       else "intervals overlap")
            summary.append(f"{world} at {off['dt']:g} s: without detectors {rate(off['arrived'], off['starts'])}, "
                           f"with {rate(on['arrived'], on['starts'])}: {verdict}.")
    for line in summary:
        print(line)
    if args.figure:
        figure(args.figure, args.paths)
    if args.record:
        examples.write(args.record, command=examples.command("examples/reactive_navigation.py", argv),
                       columns=columns, rows=rows, summary=summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
