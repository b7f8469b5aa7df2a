"""What a closed-loop task is: an environment that a batch of networks acts in, step by step.

Write a class with these three members and :func:`dnnevo.closedloop.rollout` runs a population
in it. Every method works on all rows at once (NumPy arrays with one row per episode); nothing
is called per network.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import numpy.typing as npt

__all__ = ["Environment"]


class Environment(Protocol):
    """A task that networks act in: its sensors are their inputs, their firing rates its actions.

    A rollout of ``P`` networks with ``E`` episodes each has ``B = P * E`` rows; row
    ``p * E + e`` is episode ``e`` of network ``p``. Every episode starts from a network state of
    zero, as in the built-in tasks.
    """

    observation_size: int
    """The number of sensors ``M``: the networks' ``n_inputs``."""

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator) -> npt.ArrayLike:
        """Starts one episode in every row and returns the first observations, shape ``(B, M)``.

        ``episodes[r]`` is the episode number (``0 .. E-1``) of row ``r``. Draw each episode's
        conditions once, ``E`` of them, from ``rng``, then index them with ``episodes``: every
        network then meets the same ``E`` conditions (common random numbers). ``rng`` follows
        the run's seed and generation, so a generation's conditions are the same on every run.
        """

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike]:
        """Advances every row by one time step and returns ``(observations, rewards, done)``.

        ``rates`` (``B x N``) are the networks' firing rates after they integrated the last
        observations; ``active[r]`` is False once row ``r``'s episode has ended, and what
        :meth:`step` returns for such rows is ignored. ``observations`` has shape ``(B, M)``,
        ``rewards`` ``(B,)`` (summed into each episode's return) and ``done`` ``(B,)`` booleans,
        True where the episode ended at this step.
        """
