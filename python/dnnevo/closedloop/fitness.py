"""A closed-loop :class:`~dnnevo.closedloop.Environment` as a fitness function for
:func:`dnnevo.evolve`: each network's mean return over its episodes, on conditions that follow
the run's seed and generation.

>>> import dnnevo
>>> from dnnevo.closedloop import ClosedLoop, FarSeeker
>>> fitness = ClosedLoop(FarSeeker(), episodes=2, max_steps=10_000)
>>> config = dnnevo.EvolutionConfig(population=20, generations=2, size=5, n_inputs=1)
>>> result = dnnevo.evolve(fitness, config, seed=1, progress=False)
>>> result.history["best"].shape
(2,)
"""

from __future__ import annotations

import inspect
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.closedloop.environment import Environment
from dnnevo.closedloop.loop import rollout

__all__ = ["ClosedLoop"]


class ClosedLoop:
    """``fitness(networks, *, generation, seed)``: the networks' mean returns in ``env``, for
    ``episodes`` episodes of at most ``max_steps`` time steps of ``substeps`` integration steps
    of ``dt``. A run folder names it after the environment's class, and ``resume`` accepts it
    again only with the same class source and the same settings.
    """

    def __init__(self, env: Environment, *, episodes: int = 1, max_steps: int, dt: float = 0.1,
                 substeps: int = 1, method: str = "euler") -> None:
        self.env = env
        self.settings = dict(episodes=episodes, max_steps=max_steps, dt=dt, substeps=substeps,
                             method=method)
        # What evolve records of a fitness function: the environment's name, and a text whose
        # digest changes with its source, its parameters or the rollout's settings.
        kind = type(env)
        self.__module__ = kind.__module__
        self.__qualname__ = kind.__qualname__
        try:
            source = inspect.getsource(kind)
        except (OSError, TypeError):
            source = kind.__qualname__
        self.fitness_source = f"{source}\n{vars(env)!r}\n{self.settings!r}"

    def __call__(self, networks: Sequence[_core.Network], *, generation: int = 0,
                 seed: int = 0) -> npt.NDArray[np.float64]:
        return rollout(networks, self.env, seed=seed, generation=generation, **self.settings).fitness

    def __repr__(self) -> str:
        settings = ", ".join(f"{k}={v!r}" for k, v in self.settings.items())
        return f"ClosedLoop({type(self.env).__name__}(), {settings})"
