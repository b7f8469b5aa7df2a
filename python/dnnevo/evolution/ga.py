"""Ask/tell access to the paper's genetic algorithm, for fitness functions written in Python.

>>> import numpy as np, dnnevo
>>> ga = dnnevo.GeneticAlgorithm(dnnevo.EvolutionConfig(population=20, size=2, n_inputs=1), seed=0)
>>> genomes, networks = ga.ask()
>>> genomes.shape, len(networks)
((20, 10), 20)
>>> stats = ga.tell(np.array([n.tau[0] for n in networks]))
>>> ga.generation
1
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError

__all__ = ["Ask", "GeneticAlgorithm", "Scored", "Validate"]

Validate = Callable[[list[_core.Network]], tuple[npt.ArrayLike, npt.ArrayLike]]
"""``validate(networks) -> (rates, scores)``: each network's rate in [0, 1] and finite score on a
validation set that stays the same for the whole run."""


class Ask(NamedTuple):
    """The population to score: genomes (P, G) and the same individuals as Networks."""

    genomes: npt.NDArray[np.float64]
    networks: list[_core.Network]


class Scored(NamedTuple):
    """One generation scored by a built-in task: its statistics and every individual's fitness."""

    stats: dict[str, float]
    fitness: npt.NDArray[np.float64]


class GeneticAlgorithm:
    """The paper's GA over networks of ``config.size`` neurons and ``config.n_inputs`` sensors.

    Genome layout (G = N * (2 + M + N) genes): for each neuron i in turn, its tau, its theta,
    its M sensor weights and its N incoming weights (``weights[i][:]``).
    """

    def __init__(
        self,
        config: EvolutionConfig | None = None,
        *,
        seed: int = 0,
        founders: Sequence[_core.Network] | None = None,
        seeds: Sequence[_core.Network] | None = None,
    ) -> None:
        founders = founders_argument(founders, seeds)
        self.config = config or EvolutionConfig()
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or not 0 <= seed < 2**64:
            raise ConfigError(f"seed is {seed!r}; it must be an integer in [0, 2**64)")
        self._evo = _core.Evolution(self.config.native, int(seed), list(founders or []))

    @property
    def seed(self) -> int:
        """The run's seed."""
        return self._evo.seed

    @property
    def generation(self) -> int:
        """The generation the current population belongs to."""
        return self._evo.generation

    def ask(self) -> Ask:
        """The current population."""
        return Ask(self._evo.genomes(), self._evo.networks())

    def tell(self, fitness: npt.ArrayLike, *, validate: Validate | None = None) -> dict[str, float]:
        """Scores the current population (one finite fitness each; >= 0 under proportional
        selection) and breeds the next. Returns best, mean, std and min of the scored generation.

        The champion is the best network by fitness, or, with ``validate``, by validation as
        for a built-in task: ``validate(networks) -> (rates, scores)`` judges the networks it is
        given (of the top ``config.validation_candidates`` by fitness, those not validated in
        the generation before) on a validation set that stays the same for the whole run; a
        higher rate in [0, 1] wins, then a higher finite score. It never changes evolution,
        only which network is the champion. ``champion_step_check`` is not applied here: a
        ``validate`` that should check a finer step can validate at both and report the worse.
        """
        return self._evo.tell(fitness, validate)

    def step(self, *, threads: int | None = None) -> Scored:
        """Scores the current population with the built-in task ``config.task`` and breeds the
        next, as ``dnnevo.evolve`` does each generation (the task is built once and kept). The
        GIL is released; Ctrl-C stops the scoring and raises ``KeyboardInterrupt``, leaving the
        population as it was. ``threads`` is the Rust worker count (default: all cores)."""
        stats, fitness = self._evo.step(threads)
        return Scored(stats, fitness)

    def best_succeeds(self, seed: int) -> bool | None:
        """Whether :attr:`best` meets the built-in task's success rule on fresh conditions drawn
        from ``seed`` (the task built for :meth:`step` is reused); None when there is no best yet
        or the task has no rule."""
        return self._evo.champion_success(seed)

    @property
    def best(self) -> _core.Network | None:
        """The best network scored so far, or None before the first ``tell``."""
        champ = self._evo.champion()
        return None if champ is None else champ[0]

    @property
    def best_fitness(self) -> float | None:
        """The training fitness of :attr:`best`."""
        return self._evo.champion_fitness

    @property
    def best_generation(self) -> int | None:
        """The generation :attr:`best` was scored in, or None before the first generation."""
        champ = self._evo.champion()
        return None if champ is None else champ[2]

    @property
    def best_validation(self) -> tuple[float, float] | None:
        """The validation ``(rate, score)`` of :attr:`best`, or None when it was chosen by
        training fitness (``tell`` with fitness from Python never validates)."""
        return self._evo.champion_validation()

    def state_dict(self) -> dict[str, Any]:
        """Everything needed to continue bit for bit (JSON-serialisable)."""
        return {"config": self.config.to_dict(), "evolution": self._evo.to_json()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restores a state from :meth:`state_dict`; anything else is a :class:`ConfigError`."""
        if not isinstance(state, dict) or set(state) != {"config", "evolution"}:
            got = sorted(state) if isinstance(state, dict) else type(state).__name__
            raise ConfigError(f"a GA state is a dict with 'config' and 'evolution'; got {got}")
        if not isinstance(state["evolution"], str):
            raise ConfigError("the GA state's 'evolution' must be JSON text from state_dict()")
        config = EvolutionConfig.from_dict(state["config"])
        self._evo = _core.Evolution.from_json(state["evolution"], config.native)
        self.config = config

    @classmethod
    def from_state_dict(cls, state: dict[str, Any]) -> GeneticAlgorithm:
        """A GA restored from :meth:`state_dict`."""
        ga = cls.__new__(cls)
        ga.load_state_dict(state)
        return ga


def founders_argument(founders: Sequence[_core.Network] | None,
                      seeds: Sequence[_core.Network] | None) -> Sequence[_core.Network] | None:
    """The networks placed first in the initial population, from ``founders`` or from the
    deprecated name ``seeds`` (which read as the random seed's plural), with a warning."""
    if seeds is None:
        return founders
    if founders is not None:
        raise ConfigError("give founders=, not both founders= and seeds= (its old name)")
    warnings.warn("seeds= is deprecated: the networks that found the first population are now "
                  "founders= (seed= stays the random seed)", DeprecationWarning, stacklevel=3)
    return seeds
