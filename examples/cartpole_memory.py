"""CartPole with its velocities hidden: a CTRNN against a reactive network of the same size.

The network sees only the cart's position and the pole's angle (Gymnasium's CartPole-v1,
observations 0 and 2); the velocities it needs must come from its own dynamics. Each seed
evolves two populations with the same GA and budget: CTRNNs of 5 neurons, and reactive networks
(the same 5 neurons with no recurrent weights and time constants equal to the step, so that
each step's output depends on that step's input alone). Each champion is then judged on 100
fresh episodes it never met (``purpose="evaluate"``, one seed per episode, a seed no run used);
each champion is the network that did best on the run's validation set of 40 other episodes
(``--no-validation``: the best by training fitness). A champion counts as solving when its mean
return is at least 475 (CartPole-v1's own line)::

    pip install "dnnevo[gym]"
    python examples/cartpole_memory.py --seeds 10 --out cartpole-memory.png

prints one row per seed and the solved counts with 95% Wilson intervals and the range of the
fresh mean returns, and draws the fresh mean returns of both kinds of network, seed by seed.
``--record JSON`` also writes the table and those lines for the docs
(:mod:`dnnevo.experiments.examples`).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

import dnnevo
from dnnevo import plot
from dnnevo.closedloop import ClosedLoop, rollout
from dnnevo.closedloop.gym import GymEnvironment
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.runs import save_figure

SEEN = [0, 2]  # the cart's position and the pole's angle; the velocities are hidden
SCALE = [1.0, 5.0]
SOLVED = 475.0  # CartPole-v1 counts as solved at this mean return over 100 episodes
#: Reactive networks: recurrent weights of (almost exactly) zero and time constants of one step.
REACTIVE = {"weights": [-1e-9, 1e-9], "tau": [0.1, 0.1 + 1e-9]}
FRESH_SEED = 50_000  # seed s's champions are judged on episodes from seed FRESH_SEED + s
CANDIDATES = dnnevo.EvolutionConfig().validation_candidates


def cartpole(mode: str = "vector_entry_point") -> GymEnvironment:
    return GymEnvironment("CartPole-v1", actions="threshold", observations=SEEN,
                          observation_scale=SCALE, vectorization_mode=mode)


def champion_return(seed: int, reactive: bool, population: int, generations: int,
                    episodes: int, candidates: int = CANDIDATES) -> float:
    """The mean return, on ``episodes`` fresh episodes, of the champion evolved with ``seed``,
    chosen among ``candidates`` per generation on the run's validation set (0: by training
    fitness)."""
    config = dnnevo.EvolutionConfig(population=population, generations=generations, size=5,
                                    n_inputs=len(SEEN), selection="rank", elitism=5,
                                    ranges=REACTIVE if reactive else {},
                                    validation_candidates=candidates)
    fitness = ClosedLoop(cartpole(), episodes=5, max_steps=500, substeps=2)
    result = dnnevo.evolve(fitness, config, seed=seed, progress=False)
    if result.interrupted:  # Ctrl-C or SIGTERM stops evolve after a generation; stop here too
        raise KeyboardInterrupt
    fresh = rollout([result.best], cartpole("sync"), episodes=episodes, max_steps=500, substeps=2,
                    seed=FRESH_SEED + seed, purpose="evaluate")
    return float(fresh.returns.mean())


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seeds", type=int, default=10, help="seeds 0 .. N-1 (default 10)")
    p.add_argument("--population", type=int, default=200)
    p.add_argument("--generations", type=int, default=60)
    p.add_argument("--episodes", type=int, default=100, help="fresh episodes per champion")
    p.add_argument("--no-validation", action="store_true",
                   help="choose each champion by training fitness, not on the validation set")
    p.add_argument("--out", type=Path, help="write the figure here (PNG)")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="also write the table here, for the docs (docs/results/examples/cartpole-memory.json)")
    args = p.parse_args(argv)
    if args.seeds < 1:
        p.error(f"--seeds is {args.seeds}; it must be at least 1")
    candidates = 0 if args.no_validation else CANDIDATES
    kinds = {"CTRNN": False, "reactive": True}
    returns: dict[str, list[float]] = {kind: [] for kind in kinds}
    print("| seed | " + " | ".join(f"{kind} fresh mean return" for kind in kinds) + " |")
    print("|---|" + "---|" * len(kinds))
    for seed in range(args.seeds):
        for kind, reactive in kinds.items():
            returns[kind].append(champion_return(seed, reactive, args.population,
                                                 args.generations, args.episodes, candidates))
        print(f"| {seed} | " + " | ".join(f"{returns[k][-1]:.1f}" for k in kinds) + " |")
    lines = []
    for kind in kinds:
        solved = sum(r >= SOLVED for r in returns[kind])
        low, high = wilson(solved, args.seeds)
        lines.append(f"{kind}: {solved} of {args.seeds} seeds solved (95% interval {low:.0%}-{high:.0%}); "
                     f"fresh mean returns from {min(returns[kind]):.1f} to {max(returns[kind]):.1f}")
    print("\n".join(lines))
    if args.record:
        table = [[seed, *(f"{returns[k][seed]:.1f}" for k in kinds)] for seed in range(args.seeds)]
        examples.write(args.record, command=examples.command("examples/cartpole_memory.py", argv),
                       columns=["seed", *(f"{kind} fresh mean return" for kind in kinds)], rows=table,
                       summary=lines)
    if args.out is not None:
        fig, ax = plot.subplots(figsize=(6, 3.5), layout="constrained")
        for i, kind in enumerate(kinds):
            ax.plot([i] * args.seeds, returns[kind], "o", alpha=0.7, label=kind)
        ax.axhline(SOLVED, color="gray", linestyle="--", linewidth=1)
        ax.set_xticks(range(len(kinds)), list(kinds))
        ax.set_xlim(-0.5, len(kinds) - 0.5)
        ax.set_ylabel(f"mean return, {args.episodes} fresh episodes")
        ax.set_title("CartPole-v1 with the velocities hidden, one point per seed")
        save_figure(fig, args.out)
        plot.close(fig)


if __name__ == "__main__":
    main()
