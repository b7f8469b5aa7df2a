"""What a closed-loop task is: an environment that a batch of networks acts in, step by step.

Write a class with these three members and :func:`dnnevo.closedloop.rollout` runs a population
in it. Every method works on all rows at once (NumPy arrays with one row per episode); nothing
is called per network. A fourth, ``restart`` (:class:`RestartingEnvironment`), lets a rollout
run more episodes than it has rows.
"""

from __future__ import annotations

from collections.abc import Iterable
import numbers
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from dnnevo.errors import InvalidArgumentError, TaskError

__all__ = ["Environment", "RestartingEnvironment", "check_neurons", "checked", "whole_size", "sensors"]


class Environment(Protocol):
    """A task that networks act in: its sensors are their inputs, their firing rates its actions.

    A rollout of ``P`` networks with ``E`` episodes each has ``B = P * E`` rows; row
    ``p * E + e`` is episode ``e`` of network ``p``. Every episode starts from a network state of
    zero, as in the built-in tasks.
    """

    @property
    def observation_size(self) -> int:
        """The number of sensors ``M``: the networks' ``n_inputs`` (an attribute or a
        property)."""

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
        ``rewards`` ``(B,)`` (summed into each episode's return) and ``done`` ``(B,)`` booleans
        (or integers 0 and 1), True where the episode ended at this step.
        """


class RestartingEnvironment(Environment, Protocol):
    """An :class:`Environment` that can also start a new episode in some rows while the others
    run on, so that a rollout with fewer rows than episodes (``rollout(..., rows=R)``) keeps every
    row busy: when an episode ends, the next waiting one starts in its row.
    """

    def restart(self, rows: npt.NDArray[np.bool_], episodes: npt.NDArray[np.int64]
                ) -> npt.ArrayLike | None:
        """Starts episode ``episodes[r]`` in each row ``r`` where ``rows`` is True, after the row's
        last episode ended, and returns the observations, shape ``(B, M)``, whose chosen rows are
        the new episodes' first (the other rows' are not read).

        Give each new episode the conditions of its episode number, drawn in :meth:`reset`
        (which sees every episode number: a rollout has at least one row per number), so that
        the returns are those of a rollout that runs every episode at once.

        Return None when the environment starts the new episodes with its next :meth:`step`
        instead, as a vector environment with next-step autoreset does: those rows then sit out
        that step (``active`` is False for them), and the observations it returns for them are
        the new episodes' first.
        """


def whole_size(size: Any) -> int | None:
    """``size`` as an int when it is a whole number >= 0 (an int or a NumPy integer; a bool, a
    float or a string is not), else None.

    >>> whole_size(np.int64(3)), whole_size(0), whole_size(2.0), whole_size("2"), whole_size(True)
    (3, 0, None, None, None)
    """
    if isinstance(size, bool) or not isinstance(size, numbers.Integral) or size < 0:
        return None
    return int(size)


def sensors(env: Any) -> int:
    """``env.observation_size``, checked: the number of sensors, a whole number >= 0 (0 for a
    task that gives its networks no input, a pattern generator); a :class:`~dnnevo.TaskError`
    names what is wrong.

    >>> class Blind:
    ...     observation_size = 2.0
    >>> sensors(Blind())
    Traceback (most recent call last):
    ...
    dnnevo.errors.TaskError: Blind.observation_size is 2.0; expected the number of observations the task gives at each step, a whole number >= 0
    """
    if isinstance(env, type):
        raise TaskError(f"env is the class {env.__name__}; give an environment made from it, "
                        f"{env.__name__}(...)")
    name = type(env).__name__
    if not hasattr(env, "observation_size"):
        raise TaskError(f"{name} has no observation_size; give it the number of observations the "
                        "task gives at each step (the networks' n_inputs)")
    size = env.observation_size
    if whole_size(size) is None:
        raise TaskError(f"{name}.observation_size is {size!r}; expected the number of observations "
                        "the task gives at each step, a whole number >= 0")
    return int(size)


def checked(env: Any) -> int:
    """The number of sensors of ``env``, after checking that it is an environment: an object
    (not its class) with ``reset`` and ``step`` methods and a whole ``observation_size``; a
    :class:`~dnnevo.TaskError` names what is missing.

    >>> class Still:
    ...     observation_size = 1
    ...     def reset(self, episodes, rng): ...
    >>> checked(Still())
    Traceback (most recent call last):
    ...
    dnnevo.errors.TaskError: Still has no step method; an environment has reset(episodes, rng) and step(rates, active) (docs/closed-loop.md)
    """
    size = sensors(env)
    for method in ("reset", "step"):
        if not callable(getattr(env, method, None)):
            raise TaskError(f"{type(env).__name__} has no {method} method; an environment has "
                            "reset(episodes, rng) and step(rates, active) (docs/closed-loop.md)")
    return size


def check_neurons(rates: npt.NDArray[np.float64], neurons: Iterable[int], reader: str) -> None:
    """Raises :class:`~dnnevo.errors.InvalidArgumentError` when the networks whose ``rates``
    (``B x N``) a step receives lack one of the ``neurons`` that ``reader`` (for example
    ``"RobotWorld's wheels (left, right)"``) reads, instead of an ``IndexError`` from NumPy.

    >>> check_neurons(np.zeros((4, 1)), [0, 1], "the wheels (left, right)")
    Traceback (most recent call last):
    ...
    dnnevo.errors.InvalidArgumentError: the wheels (left, right) read neurons [0, 1]; the networks have 1 neuron: give them at least 2 (size = 2)
    """
    wanted = [int(n) for n in neurons]
    size = rates.shape[1]
    if wanted and max(wanted) >= size:
        need = max(wanted) + 1
        raise InvalidArgumentError(f"{reader} read neurons {wanted}; the networks have {size} "
                                   f"neuron{'s' if size != 1 else ''}: give them at least {need} "
                                   f"(size = {need})")
