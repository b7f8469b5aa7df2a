"""Benchmark: a CTRNN population on Gymnasium's CartPole-v1, end to end, against neat-python's
CTRNN on the same environment.

Workload: P = 1000 networks of 5 neurons and 4 sensors (the GA's initial population of seed 0),
one episode each, up to 500 steps, in one natively vectorised CartPoleVectorEnv of P
sub-environments (Gymnasium's NumPy code, the environment's cost included). Each environment
step is one Euler step of dt = 0.1 for the networks; action 1 when neuron 0 fires above 0.5.
  dnnevo       dnnevo.closedloop.rollout with GymEnvironment("CartPole-v1", actions="threshold").
  neat-python  the same networks as neat.ctrnn.CTRNN objects (each neuron linked to every neuron
               and sensor; neat's own model and sigmoid, so the episodes differ, but the work per
               step is the same), each advanced by CTRNN.advance(obs, 0.1, 0.1) in a Python loop
               over the running episodes, then one step of the same vector environment.
Figures: agent-steps per second (steps of running episodes / median seconds, after warm-up),
and their ratio. Random networks drop the pole within 10-70 steps, and a vector environment
steps all its sub-environments until the last episode ends, so the same work is also timed on
a population that balances: 1000 copies of a controller evolved first (whole episodes of 500
steps). Then dnnevo's whole evolution of that controller: `dnnevo.evolve` of 1000 networks x 5
episodes for 10 generations (GA, environment and bookkeeping included), in agent-steps per
second over the run, twice in turns (--repeats times each, medians): with all 5000 episodes at
once in 5000 sub-environments, and queued in 1000 or 500 (ClosedLoop(..., rows=R): an ended
episode's row starts the next waiting one). Queued rows stay busy until the queue is empty; from
then on the last, longest episodes run out while CartPoleVectorEnv still steps all R
sub-environments, so fewer rows trade a longer queue for cheaper steps in that tail.

    pip install neat-python   # for the comparison; without it, dnnevo's figures alone
    python bench/gym_cartpole.py [--population 1000] [--repeats 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np

import dnnevo
from dnnevo.closedloop import ClosedLoop, rollout
from dnnevo.closedloop.gym import GymEnvironment
from _common import describe_machine, timed, warm_up

MAX_STEPS = 500  # CartPole-v1's own episode limit
DT = 0.1


def population(size: int) -> list[dnnevo.Network]:
    config = dnnevo.EvolutionConfig(population=size, generations=1, size=5, n_inputs=4)
    return dnnevo.GeneticAlgorithm(config, seed=0).ask().networks


SCALE = [1.0, 1.0, 5.0, 1.0]  # the pole's angle, in radians, is small


def dnnevo_steps(nets: list[dnnevo.Network]) -> int:
    env = GymEnvironment("CartPole-v1", actions="threshold", observation_scale=SCALE)
    result = rollout(nets, env, max_steps=MAX_STEPS, dt=DT, substeps=1)
    env.close()
    return int(result.lengths.sum())


def neat_networks(nets: list[dnnevo.Network]):
    from neat.activations import sigmoid_activation
    from neat.aggregations import sum_aggregation
    from neat.ctrnn import CTRNN, CTRNNNodeEval

    built = []
    for net in nets:
        n, m = net.size, net.n_inputs
        inputs = [-(k + 1) for k in range(m)]
        evals = {}
        for i in range(n):
            links = [(j, float(net.weights[i, j])) for j in range(n)]
            links += [(inputs[k], SCALE[k] * float(net.sensor_weights[i, k])) for k in range(m)]
            evals[i] = CTRNNNodeEval(float(net.tau[i]), sigmoid_activation, sum_aggregation,
                                     -float(net.theta[i]), 1.0, links)
        built.append(CTRNN(inputs, [0], evals))
    return built


def neat_steps(nets) -> int:
    import gymnasium as gym

    envs = gym.make_vec("CartPole-v1", num_envs=len(nets), vectorization_mode="vector_entry_point")
    obs, _ = envs.reset(seed=0)
    for net in nets:
        net.reset()
    active = np.ones(len(nets), dtype=bool)
    steps = 0
    actions = np.zeros(len(nets), dtype=np.int64)
    for _ in range(MAX_STEPS):
        for r in np.flatnonzero(active):
            actions[r] = nets[r].advance(obs[r].tolist(), DT, DT)[0] > 0.5
        steps += int(active.sum())
        obs, _, terminated, truncated, _ = envs.step(actions)
        active &= ~(terminated | truncated)
        if not active.any():
            break
    envs.close()
    return steps


class Counted(GymEnvironment):
    """CartPole that counts the steps of running episodes."""

    steps = 0

    def step(self, rates, active):
        Counted.steps += int(active.sum())
        return super().step(rates, active)


def median_rate(fn, repeats: int) -> float:
    warm_up(fn)
    rates = []
    for _ in range(repeats):
        seconds, steps = timed(fn)
        rates.append(steps / seconds)
    return statistics.median(rates)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--population", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    describe_machine()
    nets = population(args.population)
    ours = median_rate(lambda: dnnevo_steps(nets), args.repeats)
    print(f"workload: CartPole-v1, P = {args.population} networks of 5 neurons, one episode each, "
          f"up to {MAX_STEPS} steps")
    print(f"random networks: dnnevo {ours:.3g} agent-steps/s")
    try:
        theirs_nets = neat_networks(nets)
    except ImportError:
        print("random networks: neat-python not installed (pip install neat-python)")
    else:
        theirs = median_rate(lambda: neat_steps(theirs_nets), args.repeats)
        print(f"random networks: neat-python {theirs:.3g} agent-steps/s; dnnevo / neat-python: "
              f"{ours / theirs:.1f}x")
    config = dnnevo.EvolutionConfig(population=args.population, generations=10, size=5,
                                    n_inputs=4, selection="rank", elitism=5)
    evolutions: dict[int | None, list[float]] = {None: [], args.population: [],
                                                 args.population // 2: []}
    for _ in range(args.repeats):
        for rows, rates in evolutions.items():
            env = Counted("CartPole-v1", actions="threshold", observation_scale=SCALE)
            Counted.steps = 0
            start = time.perf_counter()
            result = dnnevo.evolve(ClosedLoop(env, episodes=5, max_steps=MAX_STEPS, dt=DT, substeps=1,
                                              rows=rows), config, seed=0, progress=False)
            rates.append(Counted.steps / (time.perf_counter() - start))
            env.close()
    balancing = [result.best] * args.population
    steady = median_rate(lambda: dnnevo_steps(balancing), args.repeats)
    print(f"dnnevo, {args.population} copies of the evolved controller ({dnnevo_steps(balancing[:1])} "
          f"steps an episode): {steady:.3g} agent-steps/s")
    for rows, rates in evolutions.items():
        how = (f"{5 * args.population} episodes at once" if rows is None
               else f"episodes queued in {rows} rows")
        print(f"evolution, 10 generations of {args.population} x 5 episodes, {how}: "
              f"{statistics.median(rates):.3g} agent-steps/s end to end (median of {len(rates)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
