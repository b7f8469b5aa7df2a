"""Benchmark: a closed-loop task written in NumPy through dnnevo's Environment protocol, against
the same task built into the Rust core.

Workload: the paper's landmark-far goal seeker (§4.2, preset nav1d-far): P networks of 5 neurons
and 1 sensor (the GA's initial population of seed 0), 2 episodes each (goal left, goal right),
up to 10 000 integration steps of dt = 0.1 per episode, the world updated at every step.
  built-in  dnnevo.evaluate("nav1d-far", networks, generation=0, seed=0): the Rust task, blocks of
            16 networks on all cores.
  protocol  dnnevo.closedloop.rollout(networks, FarSeeker(), episodes=2, max_steps=10_000, substeps=1):
            the same world in NumPy (python/dnnevo/closedloop/far_seeker.py), one dnnevo.Batch
            step and one environment step per time step, over all 2P episodes at once.
Both must give the same fitness bit for bit (the script exits with 1 if not). Figures are
medians of timed runs taken in turns, after warm-up; the ratio is built-in time / protocol
time, so 1.0 would be as fast as the Rust task. Agent-steps/s counts the steps the episodes
actually ran (an ended episode stops counting).

    python bench/closed_loop.py [--population 1000] [--repeats 5]
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

import dnnevo
from dnnevo.closedloop import FarSeeker, rollout
from _common import describe_machine, interleaved_medians

MAX_STEPS = 10_000  # nav1d's max_steps (1000 time steps) x 10 integration steps per time step


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--population", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    describe_machine()
    config = dnnevo.presets.get("nav1d-far")
    config = dnnevo.EvolutionConfig(**{**config.to_dict(), "population": args.population})
    networks = dnnevo.GeneticAlgorithm(config, seed=0).ask().networks

    def built_in():
        return dnnevo.evaluate("nav1d-far", networks, generation=0, seed=0, config=config)

    def protocol():
        return rollout(networks, FarSeeker(), episodes=2, max_steps=MAX_STEPS, dt=0.1, substeps=1)

    result = protocol()
    same = np.array_equal(built_in(), result.fitness)
    times = interleaved_medians({"built-in": built_in, "protocol": protocol}, args.repeats)
    steps = int(result.lengths.sum())
    print(f"workload: nav1d-far, P = {args.population} networks x 2 episodes, "
          f"{steps} agent-steps (up to {MAX_STEPS} per episode)")
    for name, seconds in times.items():
        print(f"{name:9s} {seconds * 1e3:8.1f} ms  {steps / seconds:.3g} agent-steps/s")
    print(f"protocol / built-in speed: {times['built-in'] / times['protocol']:.2f}")
    print(f"same fitness bit for bit: {'yes' if same else 'NO'}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
