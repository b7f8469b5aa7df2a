"""Beer and Gallagher's one-legged walker: how fast do evolved CTRNNs walk, and do they walk by a
central pattern generator or by reflexes?

Each seed runs the ``legged-walker`` preset (``dnnevo presets``): a population of 5-neuron CTRNNs
(neuron 0 the foot, 1 and 2 the forward and backward swing) evolved on the average velocity of ``--episodes`` episodes from random starting angles
(:class:`dnnevo.classic.LeggedWalker`), with the leg's angle sensed (``--no-sensor``: never
sensed, so that only a central pattern generator can walk). Its champion, chosen on the run's
validation set of 40 other starts, is then judged on 50 fresh starts:

- its average velocity, against the model's optimal controller
  (:func:`dnnevo.classic.walker.optimal_velocity`), and how many of the 50 walk (at least half
  the optimum), with the 95% Wilson interval;
- the same at half the time step (0.05, body and network alike);
- with the sensor cut (input 0): a walker that keeps walking is a central pattern generator,
  one that stops depends on its sensor (a reflexive or mixed pattern generator);
- whether the network, its sensor held at 0, has an attracting limit cycle
  (:func:`dnnevo.analysis.limit_cycles`): the rhythm a central pattern generator makes alone::

    python examples/legged_walker.py --seeds 10 --out walker.png
    python examples/legged_walker.py --seeds 10 --no-sensor --out walker-cpg.png

prints one row per seed and a summary, and draws each seed's velocities and the best seed's
gait: the leg's angle with the foot down (thick) and up (thin), sensed and with the sensor cut.
``--record JSON`` also writes the table and the summary for the docs
(:mod:`dnnevo.experiments.examples`).
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

import dnnevo
from dnnevo import plot, presets
from dnnevo.analysis import limit_cycles
from dnnevo.classic import LeggedWalker
from dnnevo.classic import walker as lw
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.runs import save_figure

DT = 0.1  # the preset's step: one Euler step of the network and the body per control step
FINE_DT = 0.05
TEST_EPISODES = 50
TEST_SEED = 2_000_003  # no run uses it: fresh starts for every champion
GAIT_TIME = 150.0  # the gait drawn: the first 150 of the 220 units of time


def config(population: int, generations: int, episodes: int, sensor: bool) -> dnnevo.EvolutionConfig:
    """The ``legged-walker`` preset with this script's options."""
    overrides = [f"population={population}", f"generations={generations}",
                 f"task_params.episodes={episodes}", f"task_params.sensor={str(sensor).lower()}"]
    return presets.get("legged-walker", overrides=overrides)


def one_seed(seed: int, population: int, generations: int, episodes: int,
             sensor: bool) -> dict[str, Any]:
    """Evolves one seed and judges its champion."""
    started = time.perf_counter()
    result = dnnevo.evolve("legged-walker", config(population, generations, episodes, sensor), seed=seed,
                           progress=False)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    net = result.best
    walking = lw.WALKING * lw.optimal_velocity(DT)
    judged = {
        "sensed": lw.velocities(net, sensor=sensor, episodes=TEST_EPISODES, seed=TEST_SEED),
        "fine": lw.velocities(net, sensor=sensor, episodes=TEST_EPISODES, seed=TEST_SEED,
                              dt=FINE_DT),
        "cut": lw.velocities(net, sensor=False, episodes=TEST_EPISODES, seed=TEST_SEED),
    }
    cycles = limit_cycles(net, [0.0])
    return {"seed": seed, "network": net, "sensor": sensor,
            **{k: float(v.mean()) for k, v in judged.items()},
            **{f"{k}_walks": int((v >= walking).sum()) for k, v in judged.items()},
            "period": cycles[0].period if cycles else None,
            "seconds": time.perf_counter() - started}


def kind(row: dict[str, Any]) -> str:
    """What makes the rhythm, from the champion's walking with its sensor cut."""
    if row["sensed_walks"] < LeggedWalker.success_rate * TEST_EPISODES:
        return "does not walk"
    if not row["sensor"] or row["cut_walks"] >= LeggedWalker.success_rate * TEST_EPISODES:
        return "central"
    return "needs its sensor"


def _walks(k: int) -> str:
    lo, hi = wilson(k, TEST_EPISODES)
    return f"{k:2d}/{TEST_EPISODES} ({lo:.0%}-{hi:.0%})"


def summary(rows: list[dict[str, Any]], sensor: bool) -> list[str]:
    """The lines that sum the seeds up."""
    best = lw.optimal_velocity(DT)
    good = [r for r in rows if kind(r) != "does not walk"]
    lo, hi = wilson(len(good), len(rows))
    central = sum(kind(r) == "central" for r in rows)
    sensed = [r["sensed"] for r in rows]
    lines = [f"{len(good)} of {len(rows)} seeds walk in at least 90% of fresh starts (95% interval "
             f"{lo:.0%}-{hi:.0%})" + (f"; {central} of them walk with the sensor cut" if sensor else ""),
             f"median velocity: {np.median(sensed):.4f} ({np.median(sensed) / best:.0%} of optimal)",
             f"velocities from {min(sensed):.4f} to {max(sensed):.4f} "
             f"({min(sensed) / best:.0%}-{max(sensed) / best:.0%} of optimal)"]
    if sensor:
        cut = [r["cut"] for r in rows]
        lines.append(f"with the sensor cut: velocities from {min(cut):.4f} to {max(cut):.4f}; "
                     f"{sum(r['cut_walks'] for r in rows)} of {TEST_EPISODES * len(rows)} starts walk")
    periods = [r["period"] for r in rows if r["period"] is not None]
    lines.append(f"{len(periods)} of {len(rows)} networks oscillate with their input at 0"
                 + (f" (periods {min(periods):.2f} to {max(periods):.2f})" if periods else ""))
    need = LeggedWalker.success_rate * TEST_EPISODES
    change = max(rows, key=lambda r: abs(r["fine"] - r["sensed"]))
    verdicts = sum((r["fine_walks"] >= need) != (r["sensed_walks"] >= need) for r in rows)
    lines.append(f"at dt {FINE_DT}: velocities change by at most {abs(change['fine'] - change['sensed']):.4f} "
                 f"({abs(change['fine'] - change['sensed']) / change['sensed']:.1%}, seed {change['seed']}); "
                 f"{verdicts} of {len(rows)} seeds change whether they walk in at least 90% of starts")
    return lines


def figure(rows: list[dict[str, Any]], path: Path) -> None:
    fig, (bars, lines) = plot.subplots(1, 2, figsize=(10, 3.8), layout="constrained")
    seeds = np.array([r["seed"] for r in rows])
    for shift, key, label in ((-0.2, "sensed", "as evolved"), (0.2, "cut", "sensor cut")):
        bars.bar(seeds + shift, [r[key] for r in rows], width=0.4, label=label)
    best = lw.optimal_velocity(DT)
    bars.axhline(best, color="k", lw=0.8, label=f"optimal controller ({best:.3f})")
    bars.axhline(lw.WALKING * best, color="k", lw=0.8, ls="--", label="walking")
    bars.set_xlabel("seed")
    bars.set_ylabel("average velocity (50 fresh starts)")
    bars.set_ylim(0, 1.25 * best)
    bars.legend(loc="upper center", fontsize=7, ncols=2)
    top = max(rows, key=lambda r: r["sensed"])
    shown = ((True, "tab:blue", "sensed"), (False, "tab:orange", "sensor cut")) if top["sensor"] \
        else ((False, "tab:blue", "no sensor"),)
    for sensor, colour, label in shown:
        t, angle, down, _ = lw.gait(top["network"], sensor=sensor, dt=DT)
        early = t <= GAIT_TIME
        lines.plot(t[early], np.degrees(angle[early]), color=colour, lw=0.6, label=label)
        planted = np.where(down & early, np.degrees(angle), np.nan)
        lines.plot(t, planted, color=colour, lw=2.2)
    lines.set_xlim(0, GAIT_TIME)
    lines.set_xlabel("time")
    lines.set_ylabel("leg angle (degrees); thick: foot down")
    lines.set_title(f"seed {top['seed']}: {kind(top)}", fontsize=9)
    lines.legend(loc="lower right", fontsize=7)
    save_figure(fig, path)
    plot.close(fig)


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=int, default=10, help="seeds 0 .. N-1 (default 10)")
    p.add_argument("--population", type=int, default=100)
    p.add_argument("--generations", type=int, default=100)
    p.add_argument("--episodes", type=int, default=4,
                   help="episodes per network per generation, from random starts (default 4)")
    p.add_argument("--no-sensor", action="store_true",
                   help="evolve without the angle sensor: only a central pattern generator walks")
    p.add_argument("--out", type=Path, help="write the figure here")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="also write the table here, for the docs (docs/results/examples/walker.json)")
    args = p.parse_args(argv)
    if args.seeds < 1:
        p.error(f"--seeds is {args.seeds}; it must be at least 1")
    rows = []
    print(f"optimal controller: {lw.optimal_velocity(DT):.4f}; walking: at least "
          f"{lw.WALKING * lw.optimal_velocity(DT):.4f}")
    print("seed  velocity  walks              at dt 0.05  sensor cut  walks cut          "
          "cycle at 0  kind")
    for seed in range(args.seeds):
        r = one_seed(seed, args.population, args.generations, args.episodes, not args.no_sensor)
        rows.append(r)
        period = f"{r['period']:.2f}" if r["period"] is not None else "none"
        print(f"{seed:4d}  {r['sensed']:8.4f}  {_walks(r['sensed_walks'])}  {r['fine']:10.4f}  "
              f"{r['cut']:10.4f}  {_walks(r['cut_walks'])}  {period:>10}  {kind(r)}", flush=True)
    lines = summary(rows, not args.no_sensor)
    print("\n".join(lines))
    if args.record:
        cut = not args.no_sensor  # without a sensor, cutting it changes nothing
        columns = ["seed", "velocity", "walks (of 50)", f"at dt {FINE_DT}", f"walks at dt {FINE_DT}",
                   *(["sensor cut", "walks, sensor cut"] if cut else []), "cycle at input 0 (period)", "kind"]
        table = [[r["seed"], f"{r['sensed']:.4f}", r["sensed_walks"], f"{r['fine']:.4f}", r["fine_walks"],
                  *([f"{r['cut']:.4f}", r["cut_walks"]] if cut else []),
                  f"{r['period']:.2f}" if r["period"] is not None else "none", kind(r)] for r in rows]
        examples.write(args.record, command=examples.command("examples/legged_walker.py", argv),
                       columns=columns, rows=table,
                       summary=[f"optimal controller: {lw.optimal_velocity(DT):.4f}", *lines])
    if args.out:
        figure(rows, args.out)


if __name__ == "__main__":
    main()
