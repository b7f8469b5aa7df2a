"""Obstacle avoidance with a 2-D robot: does an evolved CTRNN wander a room, fast and without
touching anything, from starts it never trained on?

Each seed evolves a population of small CTRNNs on :class:`dnnevo.robots.Avoid` (neurons 0 and 1
drive the left and right wheels; the eight sonars of the robot's ring are the inputs), each
network driving ``--episodes`` random starts in the room of landmark 1 per generation, for
``--steps`` steps of 0.1 s. Its champion is the network that did best on the run's validation
set (40 other starts). It is then judged on ``--fresh`` fresh episodes drawn from a seed that no
run used (``FRESH_SEED``, ``purpose="evaluate"``)::

    python examples/robot_avoid.py --seeds 5

prints one row per seed: the fresh episodes that succeeded (touched nothing and drove forwards at
a quarter of top speed or more on average) with their 95% Wilson interval, the mean return and the run's
seconds; then how many seeds' champions meet the success rule (90% of the fresh episodes), with
its interval.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Sequence

import dnnevo
from dnnevo.closedloop import ClosedLoop
from dnnevo.evaluation.stats import wilson
from dnnevo.robots import Avoid

FRESH_SEED = 1_000_003
"""The seed of the fresh episodes: far above any seed a run here uses."""


def one_seed(seed: int, population: int, generations: int, episodes: int, steps: int, size: int,
             fresh: int) -> dict:
    """Evolves one seed and judges its champion on fresh episodes."""
    started = time.perf_counter()
    env = Avoid(steps=steps)
    config = dnnevo.EvolutionConfig(population=population, generations=generations, size=size,
                                    n_inputs=env.observation_size, selection="rank", elitism=2)
    fitness = ClosedLoop(env, episodes=episodes, max_steps=steps)
    result = dnnevo.evolve(fitness, config, seed=seed, progress=False)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    ok, threshold, judged = fitness.judged(result.best, fresh, FRESH_SEED, "evaluate")
    return {"seed": seed, "successes": int(ok.sum()), "episodes": len(ok),
            "success": bool(ok.mean() >= threshold), "return": float(judged.returns.mean()),
            "seconds": time.perf_counter() - started}


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=int, default=5, help="seeds 0 .. N-1 (default 5)")
    p.add_argument("--population", type=int, default=60)
    p.add_argument("--generations", type=int, default=40)
    p.add_argument("--episodes", type=int, default=4, help="starts per network per generation")
    p.add_argument("--steps", type=int, default=300, help="steps of 0.1 s per episode (default 300)")
    p.add_argument("--size", type=int, default=4, help="neurons per network (default 4)")
    p.add_argument("--fresh", type=int, default=100, help="fresh episodes to judge each champion on")
    args = p.parse_args(argv)
    print("seed  fresh episodes succeeded  mean return  seconds")
    rows = []
    for seed in range(args.seeds):
        r = one_seed(seed, args.population, args.generations, args.episodes, args.steps,
                     args.size, args.fresh)
        rows.append(r)
        lo, hi = wilson(r["successes"], r["episodes"])
        print(f"{seed:4d}  {r['successes']:3d}/{r['episodes']} ({lo:.0%}-{hi:.0%})"
              f"{' meets the rule' if r['success'] else '':>15}  {r['return']:11.3f}  "
              f"{r['seconds']:7.0f}", flush=True)
    good = sum(r["success"] for r in rows)
    lo, hi = wilson(good, len(rows))
    print(f"{good} of {len(rows)} seeds' champions succeed in at least {Avoid.success_rate:.0%} of "
          f"their fresh episodes (95% interval {lo:.0%}-{hi:.0%})")


if __name__ == "__main__":
    main()
