"""Gymnasium's Pendulum-v1, a task with a continuous action: a CTRNN swings the pendulum up and
holds it.

The network senses ``cos theta``, ``sin theta`` and the angular velocity (divided by 8, its
limit) and sets the torque continuously: neuron 0's firing rate, in [0, 1], scaled onto
Pendulum's [-2, 2] (``actions="box"``). Each seed evolves 5-neuron CTRNNs on the mean return of
``--episodes`` episodes of 200 steps (one Euler step of 0.1 per environment step), with the
sub-environments seeded episode by episode, so that every network meets the same starts; its
champion, chosen on the run's validation set of 40 other starts, is then judged on 100 fresh
episodes from a seed no run used, beside a network that never pushes (torque 0)::

    pip install "dnnevo[gym]"
    python examples/pendulum.py --seeds 10 --out pendulum.png

prints one row per seed (the fresh mean return with a 95% bootstrap interval, and the share of
fresh episodes that end with the pendulum within 10 degrees of upright), then the median, how
many seeds beat torque 0 and the range of the upright counts, and draws every seed's fresh
returns. ``--record JSON`` also writes the table and those lines for the docs
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
from dnnevo import plot
from dnnevo.closedloop import ClosedLoop, rollout
from dnnevo.closedloop.gym import GymEnvironment
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.runs import save_figure

SCALE = [1.0, 1.0, 1.0 / 8.0]
STEPS = 200  # Pendulum-v1's own episode length
FRESH = 100
FRESH_SEED = 70_000  # seed s's champion is judged on episodes from seed FRESH_SEED + s
UPRIGHT = np.cos(np.deg2rad(10.0))


class Pendulum(GymEnvironment):
    """Pendulum-v1 through the protocol, remembering each row's last observation."""

    def __init__(self) -> None:
        super().__init__("Pendulum-v1", actions="box", observation_scale=SCALE,
                         vectorization_mode="sync")

    def reset(self, episodes: np.ndarray, rng: np.random.Generator) -> Any:
        self.last = np.array(super().reset(episodes, rng), dtype=np.float64)
        return self.last

    def step(self, rates: np.ndarray, active: np.ndarray) -> tuple[Any, Any, Any]:
        obs, reward, done = super().step(rates, active)
        self.last = np.where(active[:, None], obs, self.last)
        return obs, reward, done


def judge(net: dnnevo.Network, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Fresh episodes of ``net``: each return, and whether it ended near upright."""
    env = Pendulum()
    fresh = rollout([net], env, episodes=FRESH, max_steps=STEPS, substeps=1,
                    seed=FRESH_SEED + seed, purpose="evaluate")
    return fresh.returns[0], env.last[:, 0] >= UPRIGHT


def one_seed(seed: int, population: int, generations: int, episodes: int) -> dict[str, Any]:
    started = time.perf_counter()
    config = dnnevo.EvolutionConfig(population=population, generations=generations, size=5,
                                    n_inputs=3, selection="rank", elitism=5, mutation_rate=0.05)
    fitness = ClosedLoop(Pendulum(), episodes=episodes, max_steps=STEPS, substeps=1)
    result = dnnevo.evolve(fitness, config, seed=seed, progress=False)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    returns, upright = judge(result.best, seed)
    rng = np.random.default_rng(seed)
    means = rng.choice(returns, size=(2000, len(returns))).mean(axis=1)
    return {"seed": seed, "returns": returns, "upright": int(upright.sum()),
            "interval": np.percentile(means, [2.5, 97.5]), "seconds": time.perf_counter() - started}


def idle_returns() -> np.ndarray:
    """A network whose output sits at 0.5 (torque 0) on the first seed's fresh episodes."""
    idle = dnnevo.Network(tau=[1.0], theta=[0.0], weights=[[0.0]], sensor_weights=[[0.0, 0.0, 0.0]])
    return judge(idle, 0)[0]


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=int, default=10, help="seeds 0 .. N-1 (default 10)")
    p.add_argument("--population", type=int, default=100)
    p.add_argument("--generations", type=int, default=50)
    p.add_argument("--episodes", type=int, default=3, help="episodes per network per generation")
    p.add_argument("--out", type=Path, help="write the figure here")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="also write the table here, for the docs (docs/results/examples/pendulum.json)")
    args = p.parse_args(argv)
    if args.seeds < 1:
        p.error(f"--seeds is {args.seeds}; it must be at least 1")
    idle = idle_returns()
    print(f"torque 0 throughout: fresh mean return {idle.mean():.1f}")
    print("seed  fresh mean return (95% interval)   ends upright          seconds")
    rows = []
    for seed in range(args.seeds):
        r = one_seed(seed, args.population, args.generations, args.episodes)
        rows.append(r)
        lo, hi = r["interval"]
        ulo, uhi = wilson(r["upright"], FRESH)
        print(f"{seed:4d}  {r['returns'].mean():8.1f} ({lo:7.1f} to {hi:7.1f})   "
              f"{r['upright']:3d}/{FRESH} ({ulo:.0%}-{uhi:.0%})  {r['seconds']:7.0f}", flush=True)
    means = [r["returns"].mean() for r in rows]
    upright = [r["upright"] for r in rows]
    lines = [f"median of the seeds' fresh mean returns: {np.median(means):.1f}",
             f"{sum(m > idle.mean() for m in means)} of {len(rows)} champions have a higher fresh mean "
             f"return than torque 0 throughout ({idle.mean():.1f})",
             f"fresh episodes that end within 10 degrees of upright: {min(upright)} to {max(upright)} "
             f"of {FRESH}, by seed"]
    print("\n".join(lines))
    if args.record:
        table = []
        for r in rows:
            lo, hi = r["interval"]
            ulo, uhi = wilson(r["upright"], FRESH)
            table.append([r["seed"], f"{r['returns'].mean():.1f} ({lo:.1f} to {hi:.1f})",
                          f"{r['upright']}/{FRESH} ({ulo:.0%}-{uhi:.0%})"])
        examples.write(args.record, command=examples.command("examples/pendulum.py", argv),
                       columns=["seed", "fresh mean return (95% bootstrap interval)",
                                "ends within 10 degrees of upright"], rows=table, summary=lines)
    if args.out:
        fig, ax = plot.subplots(figsize=(7, 3.5), layout="constrained")
        ax.boxplot([r["returns"] for r in rows], positions=[r["seed"] for r in rows])
        ax.axhline(idle.mean(), color="k", lw=0.8, ls="--", label="torque 0")
        ax.set_xlabel("seed")
        ax.set_ylabel(f"return, {FRESH} fresh episodes")
        ax.set_title("Pendulum-v1: evolved CTRNN champions")
        ax.legend(loc="lower right", fontsize=8)
        save_figure(fig, args.out)
        plot.close(fig)


if __name__ == "__main__":
    main()
