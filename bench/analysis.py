"""How long the dynamical analysis takes for 10- and 15-neuron networks (issue: "10-15 neurons
must finish in seconds"): equilibria, limit cycles and a 101-value sweep of one input, for
`Network.random(N, 2, seed=s)`, s = 0-4, with the default settings. Run `python bench/analysis.py`.
"""

from __future__ import annotations

import time

import dnnevo
from dnnevo import analysis
from _common import describe_machine


def main() -> None:
    describe_machine()
    print("N   equilibria (s)  limit cycles (s)  sweep (s)   equilibria / cycles / sweep events per seed")
    for n in (10, 15):
        times: dict[str, list[float]] = {"eq": [], "cyc": [], "sweep": []}
        counts = []
        for seed in range(5):
            net = dnnevo.Network.random(n, 2, seed=seed)
            t = time.perf_counter()
            eq = analysis.equilibria(net, [0.0, 0.0])
            times["eq"].append(time.perf_counter() - t)
            t = time.perf_counter()
            cycles = analysis.limit_cycles(net, [0.0, 0.0])
            times["cyc"].append(time.perf_counter() - t)
            t = time.perf_counter()
            sweep = analysis.bifurcation(net, 1, 0.0, 1.0)
            times["sweep"].append(time.perf_counter() - t)
            counts.append(f"{len(eq)}/{len(cycles)}/{len(sweep.events)}")
        span = {k: f"{min(v):.3f}-{max(v):.3f}" for k, v in times.items()}
        print(f"{n:<3} {span['eq']:<15} {span['cyc']:<17} {span['sweep']:<11} {' '.join(counts)}")


if __name__ == "__main__":
    main()
