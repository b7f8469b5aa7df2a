"""Benchmark: a population of networks driving 2-D robots in closed loop (dnnevo.robots), against
real time.

Workload: P networks of 4 neurons (the GA's initial population of seed 0), one robot each in the
room of landmark 1 (6 x 5 m, one 1.2 x 0.6 m crate), one episode of T steps of 0.1 s (T = 3000:
five simulated minutes) that never ends early. Each step the networks integrate the robot's
sensors for 10 Euler steps of 0.1 (dnnevo.Batch), their rates set the wheel speeds, and the
fleet moves every robot and reads its sensors (dnnevo._core.Fleet, rows on all cores).
  avoid    dnnevo.robots.Avoid: a ring of 8 sonars (3 rays each), the reward in NumPy.
  pursued  the same robot with 2 pursuers chasing it (pure pursuit; capture turned off so that
           every episode lasts) and the 4-sector pursuer sensor: 12 inputs.
  world    the avoid fleet alone, stepped T times with fixed wheel speeds: the Rust world's share.
The figure is simulated seconds per wall-clock second per network ("x real time per network"):
P * T * 0.1 / seconds. The median of --repeats timed runs (after one warm-up run) is reported.
For comparison, the landmark task's 45 s trial runs at about 1.3e5x real time (bench/sim2d.py),
but there the wall follower drives the robot, so one sonar stream is shared by the whole
population; here every network drives its own robot.

    python bench/robots.py [--population 1000] [--steps 3000] [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np

import dnnevo
from dnnevo.closedloop import rollout
from dnnevo.robots import Avoid
from _common import describe_machine, threads

DT = 0.1  # seconds of the robot's world per step
SUBSTEPS = 10  # Euler steps of the network per step, of dt = 0.1 each


class Pursued(Avoid):
    """Avoid with two pursuers that never capture, and the pursuer sensor."""

    def __init__(self, steps: int) -> None:
        super().__init__(steps=steps, pursuers={"count": 2, "capture_radius": 0.0},
                         sectors={"count": 4})


def networks(population: int, n_inputs: int) -> list[dnnevo.Network]:
    config = dnnevo.EvolutionConfig(population=population, size=4, n_inputs=n_inputs)
    return dnnevo.GeneticAlgorithm(config, seed=0).ask().networks


def trial(env: Avoid, nets: list[dnnevo.Network], steps: int):
    return lambda: rollout(nets, env, episodes=1, max_steps=steps, dt=0.1, substeps=SUBSTEPS)


def world_only(env: Avoid, population: int, steps: int):
    wheels = np.random.default_rng(0).uniform(-0.2, 1.0, (population, 2))

    def run():
        env.fleet.reset(np.zeros(population, dtype=np.int64), 0)
        for _ in range(steps):
            env.fleet.step(wheels)
    return run


def median_seconds(fn, repeats: int) -> tuple[float, list[float]]:
    fn()  # warm-up: the first run pays for the thread pool and the allocator's first pages
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--population", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    if min(args.population, args.steps, args.repeats) < 1:
        parser.error("--population, --steps and --repeats must be >= 1")
    describe_machine()
    p, t = args.population, args.steps
    simulated = t * DT
    print(f"workload: P = {p} networks of 4 neurons, one robot each, {t} steps of {DT} s "
          f"({simulated:g} simulated s), {SUBSTEPS} Euler steps per step; median of "
          f"{args.repeats} runs on {threads()} threads")
    avoid = Avoid(steps=t)
    pursued = Pursued(t)
    runs = {
        "avoid": trial(avoid, networks(p, avoid.observation_size), t),
        "pursued": trial(pursued, networks(p, pursued.observation_size), t),
        "world": world_only(Avoid(steps=t), p, t),
    }
    for name, fn in runs.items():
        seconds, times = median_seconds(fn, args.repeats)
        ratio = p * simulated / seconds
        print(f"{name:8s} {seconds:7.2f} s  ({', '.join(f'{s:.2f}' for s in times)})  "
              f"{p * t / seconds:.3g} robot-steps/s  {ratio:.3g}x real time per network")
    return 0


if __name__ == "__main__":
    sys.exit(main())
