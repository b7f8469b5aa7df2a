"""Gymnasium's Pendulum-v1, a task with a continuous action: a CTRNN swings the pendulum up and
holds it.

The network senses ``cos theta``, ``sin theta`` and the angular velocity (divided by 4, half its
limit) and sets the torque continuously: neuron 0's firing rate, in [0, 1], scaled onto
Pendulum's [-2, 2] (``actions="box"``). Its neurons are fast (time constants 0.1 to 1, 10
integration steps of 0.1 per environment step), so that the torque follows the pendulum within
one step. Each seed evolves 5-neuron CTRNNs (weights and biases in [-8, 8], creep mutation,
elitism 10) on the mean return of ``--episodes`` episodes of 200 steps, with every network
meeting the same starts; evolution runs Pendulum-v1's equations in NumPy
(:class:`PendulumEquations`, the same returns as Gymnasium's bit for bit and 60 to 90
times faster). Its champion, chosen on the run's validation set of 40 other starts, is then judged on
100 fresh episodes of Gymnasium's own Pendulum-v1, from a seed no run used, beside a network that
never pushes (torque 0)::

    pip install "dnnevo[gym]"
    python examples/pendulum.py --seeds 10 --out pendulum.png

prints one row per seed (the fresh mean return with a 95% bootstrap interval, and the share of
fresh episodes that end with the pendulum within 10 degrees of upright), then the median, how
many seeds beat torque 0, the range of the upright counts and how many seeds solve it (a fresh
mean return above -200 and at least 95 of 100 episodes ending upright), and draws every seed's
fresh returns. ``--record JSON`` also writes the table and those lines for the docs
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
from dnnevo.config import IntegratorConfig, Ranges
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.runs import save_figure

SCALE = [1.0, 1.0, 1.0 / 4.0]
STEPS = 200  # Pendulum-v1's own episode length
SUBSTEPS = 10  # integration steps of 0.1 per environment step (0.05 s of the pendulum's time)
WEIGHTS = (-8.0, 8.0)  # the range of every weight and bias
TAU = (0.1, 1.0)  # fast neurons: at most one environment step behind the pendulum
ELITE = 10  # the best networks copied unchanged (fewer in a population of at most 10)
FRESH = 100
FRESH_SEED = 70_000  # seed s's champion is judged on episodes from seed FRESH_SEED + s
UPRIGHT = np.cos(np.deg2rad(10.0))
SOLVED_RETURN = -200.0  # the usual bar for Pendulum-v1; Gymnasium itself sets none
SOLVED_UPRIGHT = 95  # of the FRESH episodes, ending within 10 degrees of upright


class PendulumEquations:
    """Pendulum-v1's equations in NumPy, vectorised over rows, for evolution: the same starts
    (episode ``e``'s state drawn by ``numpy.random.default_rng(seed_e)``, as Gymnasium's
    ``reset(seed=seed_e)`` does), the same float32 observations, torques and rewards as
    :class:`Pendulum` on Gymnasium's own environment (``tests/test_examples.py`` checks every
    return), 60 to 90 times faster than Gymnasium's sub-environments, stepped one by one in
    Python. The champion is judged on Gymnasium's own."""

    observation_size = 3

    def reset(self, episodes: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        seeds = rng.integers(0, 2**31 - 1, size=int(episodes.max()) + 1)  # as GymEnvironment
        starts = np.array([np.random.default_rng(int(s)).uniform(low=[-np.pi, -1.0], high=[np.pi, 1.0])
                           for s in seeds])
        self.state = starts[episodes]
        self.t = 0
        return self._observe()

    def _observe(self) -> np.ndarray:
        theta, speed = self.state[:, 0], self.state[:, 1]
        obs = np.stack([np.cos(theta), np.sin(theta), speed], axis=1).astype(np.float32)
        return np.multiply(obs, SCALE, dtype=np.float64)

    def step(self, rates: np.ndarray, active: np.ndarray) -> tuple[Any, Any, Any]:
        u = np.clip(-2.0 + rates[:, 0] * 4.0, -2.0, 2.0)  # actions="box" onto [-2, 2]
        theta, speed = self.state[:, 0], self.state[:, 1]
        angle = ((theta + np.pi) % (2 * np.pi)) - np.pi
        cost = angle**2 + 0.1 * speed**2 + 0.001 * u**2
        speed = np.clip(speed + (3 * 10.0 / 2 * np.sin(theta) + 3.0 * u) * 0.05, -8.0, 8.0)
        self.state = np.stack([theta + speed * 0.05, speed], axis=1)
        self.t += 1
        return self._observe(), -cost, np.full(len(rates), self.t >= STEPS)


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
    fresh = rollout([net], env, episodes=FRESH, max_steps=STEPS, substeps=SUBSTEPS,
                    seed=FRESH_SEED + seed, purpose="evaluate")
    return fresh.returns[0], env.last[:, 0] >= UPRIGHT


def one_seed(seed: int, population: int, generations: int, episodes: int) -> dict[str, Any]:
    started = time.perf_counter()
    config = dnnevo.EvolutionConfig(
        population=population, generations=generations, size=5, n_inputs=3, selection="rank",
        elitism=min(ELITE, population - 1), mutation="creep", mutation_rate=0.1,
        ranges=Ranges(tau=TAU, theta=WEIGHTS, weights=WEIGHTS, sensor_weights=WEIGHTS),
        integrator=IntegratorConfig(substeps=SUBSTEPS))
    fitness = ClosedLoop(PendulumEquations(), episodes=episodes, max_steps=STEPS, substeps=SUBSTEPS)
    result = dnnevo.evolve(fitness, config, seed=seed, progress=False)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    returns, upright = judge(result.best, seed)
    rng = np.random.default_rng(seed)
    means = rng.choice(returns, size=(2000, len(returns))).mean(axis=1)
    return {"seed": seed, "returns": returns, "upright": int(upright.sum()),
            "interval": np.percentile(means, [2.5, 97.5]), "seconds": time.perf_counter() - started}


def solved(r: dict[str, Any]) -> bool:
    """Whether a seed's champion swings the pendulum up and holds it on its fresh episodes."""
    return bool(r["returns"].mean() > SOLVED_RETURN and r["upright"] >= SOLVED_UPRIGHT)


def idle_returns() -> np.ndarray:
    """A network whose output sits at 0.5 (torque 0) on the first seed's fresh episodes."""
    idle = dnnevo.Network(tau=[1.0], theta=[0.0], weights=[[0.0]], sensor_weights=[[0.0, 0.0, 0.0]])
    return judge(idle, 0)[0]


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=int, default=10, help="seeds 0 .. N-1 (default 10)")
    p.add_argument("--population", type=int, default=200)
    p.add_argument("--generations", type=int, default=500)
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
             f"of {FRESH}, by seed",
             f"{sum(solved(r) for r in rows)} of {len(rows)} champions solve it (fresh mean return above "
             f"{SOLVED_RETURN:.0f} and at least {SOLVED_UPRIGHT} of {FRESH} episodes ending upright)"]
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
        ax.axhline(SOLVED_RETURN, color="C2", lw=0.8, ls=":", label=f"{SOLVED_RETURN:.0f}, solved")
        ax.set_xlabel("seed")
        ax.set_ylabel(f"return, {FRESH} fresh episodes")
        ax.set_title("Pendulum-v1: evolved CTRNN champions")
        ax.legend(loc="lower right", fontsize=8)
        save_figure(fig, args.out)
        plot.close(fig)


if __name__ == "__main__":
    main()
