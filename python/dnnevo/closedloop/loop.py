"""Runs a population of networks in a closed-loop :class:`~dnnevo.closedloop.Environment`: the
environment's observations are the networks' inputs, their firing rates its actions.

One :class:`dnnevo.Batch` holds every episode of every network as a row; each time step is one
call of the environment and one of the batch, both vectorised over rows. Rows whose episode has
ended are left out of the integration. Whatever the environment returns is checked: a wrong
shape, a value that is not finite or an exception names the method and the problem.

>>> import dnnevo
>>> from dnnevo.closedloop import FarSeeker, rollout
>>> nets = [dnnevo.Network.random(5, 1, seed=s) for s in range(3)]
>>> result = rollout(nets, FarSeeker(), episodes=2, max_steps=10_000)
>>> result.returns.shape, result.fitness.shape
((3, 2), (3,))
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo._checks import nonnegative
from dnnevo.closedloop.environment import Environment
from dnnevo.errors import InvalidArgumentError, TaskError

__all__ = ["Rollout", "observations", "read_only", "rollout"]


@dataclass(frozen=True)
class Rollout:
    """What a rollout measured, one row per network and one column per episode."""

    returns: npt.NDArray[np.float64]
    """Each episode's summed rewards, shape ``(P, E)``."""
    lengths: npt.NDArray[np.int64]
    """Each episode's time steps, shape ``(P, E)``; ``max_steps`` where it did not end."""

    @property
    def fitness(self) -> npt.NDArray[np.float64]:
        """Each network's mean return over its episodes, shape ``(P,)``."""
        return np.asarray(self.returns.mean(axis=1), dtype=np.float64)


def rollout(
    networks: Sequence[_core.Network],
    env: Environment,
    *,
    episodes: int = 1,
    max_steps: int,
    dt: float = 0.1,
    substeps: int = 1,
    method: str = "euler",
    seed: int = 0,
    generation: int = 0,
    purpose: str = "trial",
) -> Rollout:
    """Runs ``episodes`` episodes of every network in ``env``, all at once, for at most
    ``max_steps`` time steps of ``substeps`` integration steps of ``dt`` each.

    The conditions come from ``rng = numpy.random.default_rng(condition_seed(seed,
    generation, purpose))``: the same for every network of a generation (common random numbers)
    and for every run with this seed. Evolution draws with ``purpose="trial"``; judge a champion
    on fresh conditions with ``purpose="evaluate"``, which no run draws from.
    """
    if nonnegative("episodes", episodes) < 1:
        raise InvalidArgumentError("episodes is 0; it must be at least 1")
    nonnegative("max_steps", max_steps)
    batch = _core.Batch(networks, replicas=episodes, dt=dt, substeps=substeps, method=method)
    batch.reset()
    rows, m = batch.rows, batch.n_inputs
    if getattr(env, "observation_size", m) != m:
        raise TaskError(f"{_name(env)}.observation_size is {env.observation_size}; the networks "
                        f"have {m} inputs")
    rng = np.random.default_rng(_core.condition_seed(seed, generation, purpose))
    labels = np.tile(np.arange(episodes, dtype=np.int64), batch.networks)
    obs = observations(_call(env, "reset", labels, rng), env, "reset", rows, m)
    active = np.ones(rows, dtype=bool)
    ended = np.empty(rows, dtype=bool)
    returns = np.zeros(rows)
    lengths = np.full(rows, max_steps, dtype=np.int64)  # rows still running at the limit
    rates = np.empty((rows, batch.size))
    # The environment sees read-only views: it can neither change what the loop keeps nor
    # hand the rates back as the next observations to be written over.
    seen_rates, seen_active = read_only(rates), read_only(active)
    step = env.step
    # The loop is the hot path: one call of the batch and one of the environment per time step,
    # and three whole-array operations. The checks cost nothing while the environment keeps to
    # the protocol; when it does not, the slow path finds what is wrong and says so.
    for t in range(max_steps):
        try:
            batch.step(obs, active=active, out=rates)
        except InvalidArgumentError as e:
            if not str(e).startswith("inputs["):
                raise  # not the environment's doing: an integration that diverged
            raise TaskError(f"{_name(env)}.{'step' if t else 'reset'} returned observations that "
                            f"are not finite ({e})") from None
        try:
            out = step(seen_rates, seen_active)
        except Exception as e:
            raise TaskError(f"{_name(env)}.step raised {type(e).__name__}: {e}") from e
        try:
            obs, reward, done = out
        except (TypeError, ValueError):
            raise TaskError(f"{_name(env)}.step returned {type(out).__name__}; expected a tuple "
                            "(observations, rewards, done)") from None
        if type(obs) is not np.ndarray or obs.shape != (rows, m) or obs.dtype.char not in "df":
            obs = observations(obs, env, "step", rows, m)
        if np.may_share_memory(obs, rates):
            obs = obs.copy()  # the batch writes the rates while it reads the observations
        if type(reward) is not np.ndarray or reward.shape != (rows,) or reward.dtype.kind not in "biuf":
            reward = _row_values(reward, env, rows)
        if type(done) is not np.ndarray:
            done = np.asarray(done)
        if done.shape != (rows,) or done.dtype.char != "?":
            raise TaskError(f"{_name(env)}.step returned done of type {type(done).__name__}, dtype "
                            f"{getattr(done, 'dtype', '?')} and shape {np.shape(done)}; expected a "
                            f"bool array of shape (B,) = ({rows},)")
        np.add(returns, reward, out=returns, where=active)
        np.logical_and(active, done, out=ended)
        if ended.any():  # rare: most steps end no episode
            if not np.isfinite(returns).all():
                _check_rewards(reward, returns, env, active)
            lengths[ended] = t + 1
            np.logical_xor(active, ended, out=active)
            if not active.any():
                break
    if not np.isfinite(returns).all():
        _check_rewards(reward, returns, env, active)
    shape = (batch.networks, episodes)
    return Rollout(returns=returns.reshape(shape), lengths=lengths.reshape(shape))


def _name(env: Any) -> str:
    return type(env).__name__


def _call(env: Any, method: str, *args: Any) -> Any:
    """``env.method(*args)``; an exception inside it becomes a :class:`TaskError` naming both."""
    try:
        return getattr(env, method)(*args)
    except Exception as e:
        raise TaskError(f"{_name(env)}.{method} raised {type(e).__name__}: {e}") from e


def _numeric(value: Any, env: Any, what: str) -> npt.NDArray[Any]:
    arr = np.asarray(value)
    if arr.dtype.kind not in "biuf":
        raise TaskError(f"{_name(env)} returned {what} of dtype {arr.dtype}; expected numbers")
    return arr


def observations(value: Any, env: Any, method: str, rows: int, m: int) -> npt.NDArray[Any]:
    """The observations that ``env.method`` returned, as a (B, M) = (``rows``, ``m``) float array
    for the batch: the environment's own array when it is already float64 or float32 (the batch
    checks that a running row's are finite). Another shape, or values that are not numbers, is a
    :class:`~dnnevo.TaskError` naming the method."""
    obs = value if isinstance(value, np.ndarray) else _numeric(value, env, f"observations from {method}")
    if obs.shape != (rows, m):
        raise TaskError(f"{_name(env)}.{method} returned observations of shape {obs.shape}; "
                        f"expected (B, M) = ({rows}, {m})")
    if obs.dtype.kind != "f" or obs.dtype.itemsize not in (4, 8):
        obs = _numeric(obs, env, f"observations from {method}").astype(np.float64)
    return obs


def _row_values(value: Any, env: Any, rows: int) -> npt.NDArray[Any]:
    arr = _numeric(value, env, "rewards")
    if arr.shape != (rows,):
        raise TaskError(f"{_name(env)}.step returned rewards of shape {arr.shape}; expected "
                        f"(B,) = ({rows},)")
    return arr


def _check_rewards(reward: npt.NDArray[Any], returns: npt.NDArray[np.float64], env: Any,
                   active: npt.NDArray[np.bool_]) -> None:
    """Names a running row's reward that is not finite in the last step, or else the first row
    whose return is not finite (an earlier reward, or a sum that overflowed). The returns are
    checked when an episode ends and when the rollout does, not at every step."""
    bad = ~np.isfinite(reward) & active
    if bad.any():
        r = int(np.flatnonzero(bad)[0])
        raise TaskError(f"{_name(env)}.step returned rewards[{r}] = {reward[r]}; every reward of a "
                        "running episode must be finite")
    r = int(np.flatnonzero(~np.isfinite(returns))[0])
    raise TaskError(f"{_name(env)}.step returned rewards that made row {r}'s return "
                    f"{returns[r]}; every reward of a running episode must be finite, and their "
                    "sum below 1.8e308 (scale the rewards down if it overflowed)")


def read_only(array: npt.NDArray[Any]) -> npt.NDArray[Any]:
    """A read-only view of ``array``, which shows its later changes: what a task is shown."""
    view = array.view()
    view.flags.writeable = False
    return view
