"""Seeding a run's first population from earlier runs: the paper's incremental route (§5.3).

The paper evolves a 2-bit learner from a population of composites, each made by fully
interconnecting a 1-bit learner with an alternating-sequence generator. :class:`Seeding` says
where the parts come from and how they are joined:

- ``runs``: the earlier run folders, in order; the first run's neuron 0 stays the output;
- ``populations``: take each run's whole last population rather than its champion, and compose
  the i-th members of the runs into the i-th seed, so the seeds pair different networks;
- ``cross_scale``: the weights between the parts are 0, or drawn per seed uniformly in
  [-cross_scale, cross_scale] from the stream ``(seed, 0, Seeding, j, 1)`` of the new run's seed,
  where ``j = member`` with two runs (``member (R - 1) + k`` for the k-th of R - 1 joins);
- ``spare``: that many more neurons, a random network (``Network.random`` with seed
  ``(seed * SPARE_SEED_STRIDE + member) mod 2**64``) composed last like another part. With no
  cross weights they cannot change the composite's output until evolution wires them in: room for
  new circuitry beside the parts. Not in the paper.

When the runs' network sizes do not add up to the new run's size, the networks are used as they
are, side by side in the population.

>>> Seeding((), cross_scale=-1.0)
Traceback (most recent call last):
  ...
dnnevo.errors.ConfigError: --cross-scale is -1.0; it must be a finite number >= 0
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dnnevo import _core
from dnnevo.errors import ConfigError
from dnnevo.evolution.ga import GeneticAlgorithm
from dnnevo.runs import RunDir

__all__ = ["SPARE_SEED_STRIDE", "Seeding", "add_arguments"]

SPARE_SEED_STRIDE = 1_000_003
"""Seed s's member m gets spare neurons from ``Network.random(..., seed=s * SPARE_SEED_STRIDE + m)``."""


@dataclass(frozen=True)
class Seeding:
    """Where a run's seed networks come from; see the module docs."""

    runs: tuple[Path, ...]
    populations: bool = False
    cross_scale: float = 0.0
    spare: int = 0

    def __post_init__(self) -> None:
        if not (isinstance(self.spare, int) and not isinstance(self.spare, bool) and self.spare >= 0):
            raise ConfigError(f"--spare-neurons is {self.spare!r}; it must be an integer >= 0")
        if not (isinstance(self.cross_scale, int | float) and math.isfinite(self.cross_scale)
                and self.cross_scale >= 0):
            raise ConfigError(f"--cross-scale is {self.cross_scale!r}; it must be a finite number >= 0")
        if not self.runs and (self.populations or self.cross_scale or self.spare):
            what = ("--seed-populations" if self.populations else "--cross-scale" if self.cross_scale
                    else "--spare-neurons")
            raise ConfigError(f"{what} needs at least one --seed-from RUN")

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> Seeding | None:
        """The seeding the options of :func:`add_arguments` ask for, or None without
        ``--seed-from``."""
        seeding = cls(tuple(args.seed_from), args.seed_populations, args.cross_scale, args.spare_neurons)
        return seeding if seeding.runs else None

    def networks(self, size: int, seed: int) -> list[_core.Network]:
        """The seed networks for a run of ``size`` neurons with ``seed``."""
        groups = [self._group(RunDir(r)) for r in self.runs]
        parts_size = sum(g[0].size for g in groups) + self.spare
        if self.spare and parts_size != size:
            raise ConfigError(f"the seed runs' networks and --spare-neurons {self.spare} make {parts_size} "
                              f"neurons; the run has {size}")
        if len(groups) + bool(self.spare) < 2 or parts_size != size:
            return [net for group in groups for net in group]
        seeds = []
        for member, parts in enumerate(zip(*groups)):
            if self.spare:
                spare_seed = (seed * SPARE_SEED_STRIDE + member) % 2**64
                parts = (*parts, _core.Network.random(self.spare, parts[0].n_inputs, seed=spare_seed))
            net = parts[0]
            for k, part in enumerate(parts[1:]):
                join = member * (len(parts) - 1) + k
                net = _core.compose(net, part, cross_scale=self.cross_scale, seed=seed, member=join)
            seeds.append(net)
        return seeds

    def info(self) -> dict[str, Any]:
        """Entries for the ``[run]`` table of the new run's config.toml."""
        info: dict[str, Any] = {"seeded_from": [str(p) for p in self.runs],
                                "seeded_with": "populations" if self.populations else "champions",
                                "cross_scale": float(self.cross_scale)}
        if self.spare:  # only then, so that earlier sweeps' settings still match
            info["spare_neurons"] = self.spare
        return info

    def _group(self, run: RunDir) -> list[_core.Network]:
        if self.populations:
            return GeneticAlgorithm.from_state_dict(run.read_checkpoint().state).ask().networks
        config, table = run.read_config()
        return [run.read_best(config, table)]


def add_arguments(p: argparse.ArgumentParser) -> None:
    """The seeding options of ``dnnevo run`` and ``dnnevo sweep``."""
    p.add_argument("--seed-from", action="append", default=[], type=Path, metavar="RUN",
                   help="seed the initial population with RUN's champion (repeatable); champions "
                        "whose sizes add up to the preset's size are composed, the first RUN's "
                        "output neuron staying the output")
    p.add_argument("--seed-populations", action="store_true",
                   help="with --seed-from: use each RUN's whole last population, not its champion; "
                        "the i-th members of the runs are composed into the i-th seed")
    p.add_argument("--cross-scale", type=float, default=0.0, metavar="S",
                   help="with --seed-from: draw each weight between composed parts uniformly in "
                        "[-S, S], per seed network, from the run's seed (default 0: no cross weights)")
    p.add_argument("--spare-neurons", type=int, default=0, metavar="K",
                   help="with --seed-from: compose K more neurons (a random network) into each seed, "
                        "joined like another part; set size to the parts' sum + K (not in the paper)")
