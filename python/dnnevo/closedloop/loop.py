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

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo._checks import nonnegative
from dnnevo.closedloop.environment import Environment, checked
from dnnevo.config import IntegratorConfig
from dnnevo.errors import InvalidArgumentError, TaskError, with_article

__all__ = ["Rollout", "observations", "read_only", "rollout"]

#: The run config's default integrator, whose settings are rollout's and ClosedLoop's defaults:
#: a champion judged with ``rollout``'s defaults meets the step that evolution used.
DEFAULT_INTEGRATOR = IntegratorConfig()


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
    networks: Sequence[_core.Network] | Mapping[str, npt.ArrayLike],
    env: Environment,
    *,
    episodes: int = 1,
    max_steps: int,
    dt: float = DEFAULT_INTEGRATOR.dt,
    substeps: int = DEFAULT_INTEGRATOR.substeps,
    method: str = DEFAULT_INTEGRATOR.method,
    seed: int = 0,
    generation: int = 0,
    purpose: str = "trial",
    rows: int | None = None,
    precision: str = "f64",
) -> Rollout:
    """Runs ``episodes`` episodes of every network in ``env``, all at once, for at most
    ``max_steps`` time steps of ``substeps`` integration steps of ``dt`` each. ``dt``,
    ``substeps`` and ``method`` default to the run config's ``[integrator]`` (10 Euler steps of
    0.1 per time step), as :class:`~dnnevo.closedloop.ClosedLoop`'s do, so that a champion
    evolved with the defaults is judged at the step it was evolved with. ``networks`` is a list
    of networks or, as :class:`dnnevo.Batch` takes them, stacked arrays (``tau`` (P, N),
    ``theta`` (P, N), ``weights`` (P, N, N), ``sensor_weights`` (P, N, M)), which an optimiser of
    your own makes from its genomes with :func:`dnnevo.stack_genomes` without a network object
    per genome.

    ``rows`` runs at most that many episodes at once (at least ``episodes``; more than all
    ``P * episodes`` runs them all): when an episode ends, the next waiting one starts in its
    row, through the environment's ``restart`` method
    (:class:`~dnnevo.closedloop.Environment`). Rows then stay busy until the last episodes,
    where a vector environment that steps every row would spend most of its time on rows whose
    episode has ended. Every episode still starts from network state 0 and meets the conditions
    of its episode number, so an environment with common conditions gives the same returns
    either way.

    The conditions come from ``rng = numpy.random.default_rng(condition_seed(seed,
    generation, purpose))``: the same for every network of a generation (common random numbers)
    and for every run with this seed. Evolution draws with ``purpose="trial"``; judge a champion
    on fresh conditions with ``purpose="evaluate"``, which no run draws from.

    ``precision="f32"`` integrates the networks in single precision (:class:`dnnevo.Batch`); the
    environment still sees float64 rates, float32 values widened.
    """
    if nonnegative("episodes", episodes) < 1:
        raise InvalidArgumentError("episodes is 0; it must be at least 1")
    nonnegative("max_steps", max_steps)
    # The binding checks method, precision and purpose and names a value it does not know
    # (InvalidArgumentError): they are plain strings here, as in ClosedLoop and the configs.
    integrator: dict[str, Any] = dict(dt=dt, substeps=substeps, method=method, precision=precision)
    draw: Any = purpose
    if rows is not None:
        if nonnegative("rows", rows) < episodes:
            raise InvalidArgumentError(f"rows is {rows}; it must be at least episodes ({episodes}), "
                                       "so that the first reset sees every episode number")
        if rows < _count(networks) * episodes:
            return _queued(env, episodes=episodes, max_steps=max_steps, rows=rows,
                           rng=np.random.default_rng(_core.condition_seed(seed, generation, draw)),
                           batch=_core.Batch(networks, replicas=episodes, rows=rows, **integrator))
    batch = _core.Batch(networks, replicas=episodes, **integrator)
    batch.reset()
    rows, m = batch.rows, batch.n_inputs
    _check_sensors(env, m)
    rng = np.random.default_rng(_core.condition_seed(seed, generation, draw))
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
    # and three whole-array operations.
    for t in range(max_steps):
        _step_batch(batch, obs, active, rates, env, t)
        try:
            out = step(seen_rates, seen_active)
        except Exception as e:
            raise TaskError(f"{_name(env)}.step raised {type(e).__name__}: {e}") from e
        obs, reward, done = _outputs(out, env, rows, m, rates)
        returns += _running(reward, active)
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


def _count(networks: Sequence[_core.Network] | Mapping[str, npt.ArrayLike]) -> int:
    """How many networks ``networks`` holds: a list's length, or the rows of stacked arrays'
    ``tau`` (whose shapes the batch checks)."""
    if isinstance(networks, Mapping):
        tau = np.asarray(networks.get("tau", ()))
        return len(tau) if tau.ndim else 0  # a malformed tau is the batch's to name
    return len(networks)


def _check_sensors(env: Any, m: int) -> None:
    """Refuses an environment whose ``observation_size`` is not the networks' ``m`` inputs."""
    if checked(env) != m:
        raise TaskError(f"{_name(env)}.observation_size is {env.observation_size}; the networks "
                        f"have {m} input{'' if m == 1 else 's'}")


def _queued(env: Any, *, episodes: int, max_steps: int, rows: int, rng: np.random.Generator,
            batch: _core.Batch) -> Rollout:
    """:func:`rollout` with ``rows`` rows, fewer than its episodes: a row whose episode ends
    starts the next waiting one (episode ``q`` is episode ``q % E`` of network ``q // E``)."""
    restart = getattr(env, "restart", None)
    if restart is None:
        raise TaskError(f"{_name(env)} has no restart method; without one, rows must be None or "
                        f"at least P x episodes = {batch.networks * episodes}")
    total, m = batch.networks * episodes, batch.n_inputs
    _check_sensors(env, m)
    batch.reset()
    episode = np.arange(rows, dtype=np.int64)  # the episode each row runs
    following = rows  # the next waiting episode
    obs = observations(_call(env, "reset", episode % episodes, rng), env, "reset", rows, m)
    active = np.ones(rows, dtype=bool)  # rows whose network steps
    waiting = np.zeros(rows, dtype=bool)  # rows whose episode starts with the next step's observations
    ended = np.empty(rows, dtype=bool)
    row_returns = np.zeros(rows)
    start = np.zeros(rows, dtype=np.int64)  # the step count at which each row's episode began
    returns, lengths = np.zeros(total), np.zeros(total, dtype=np.int64)
    rates = np.empty((rows, batch.size))
    seen_rates, seen_active = read_only(rates), read_only(active)
    limit = max_steps  # the step count at which the oldest running episode reaches max_steps
    t = 0
    while True:
        _step_batch(batch, obs, active, rates, env, t)
        try:
            out = env.step(seen_rates, seen_active)
        except Exception as e:
            raise TaskError(f"{_name(env)}.step raised {type(e).__name__}: {e}") from e
        obs, reward, done = _outputs(out, env, rows, m, rates)
        t += 1
        row_returns += _running(reward, active)
        np.logical_and(active, done, out=ended)
        if t >= limit:
            ended |= active & (t - start >= max_steps)
        if waiting.any():  # these rows' observations are their episodes' first
            active |= waiting
            waiting[:] = False
        if not ended.any():
            continue
        if not np.isfinite(row_returns).all():
            _check_rewards(reward, row_returns, env, active)
        finished = np.flatnonzero(ended)
        returns[episode[finished]] = row_returns[finished]
        lengths[episode[finished]] = t - start[finished]
        again = finished[:total - following]
        active[finished[len(again):]] = False
        if len(again):
            obs = _restart(env, restart, batch, again, following, episodes, obs, active, waiting)
            episode[again] = np.arange(following, following + len(again))
            following += len(again)
            row_returns[again] = 0.0
            start[again] = t + waiting[again]
        running = active | waiting
        if not running.any():
            break
        limit = int(start[running].min()) + max_steps
    shape = (batch.networks, episodes)
    return Rollout(returns=returns.reshape(shape), lengths=lengths.reshape(shape))


def _restart(env: Any, restart: Any, batch: _core.Batch, again: npt.NDArray[np.int64],
             following: int, episodes: int, obs: npt.NDArray[Any], active: npt.NDArray[np.bool_],
             waiting: npt.NDArray[np.bool_]) -> npt.NDArray[Any]:
    """Starts episodes ``following, following + 1, ...`` in rows ``again`` (network state 0),
    and returns the next observations: ``obs`` with the restarted rows' first observations, or
    ``obs`` as it is when the environment starts them with its next step (``restart`` returned
    None; those rows then wait out that step)."""
    rows, m = len(active), batch.n_inputs
    batch.assign(again, np.arange(following, following + len(again)) // episodes)
    batch.reset(again)
    chosen = np.zeros(rows, dtype=bool)
    chosen[again] = True
    numbers = np.zeros(rows, dtype=np.int64)
    numbers[again] = np.arange(following, following + len(again)) % episodes
    try:
        first = restart(read_only(chosen), read_only(numbers))
    except Exception as e:
        raise TaskError(f"{_name(env)}.restart raised {type(e).__name__}: {e}") from e
    if first is None:
        active[again] = False
        waiting[again] = True
        return obs
    first = observations(first, env, "restart", rows, m)
    if not np.isfinite(first[again]).all():
        r = int(again[np.flatnonzero(~np.isfinite(first[again]).all(axis=1))[0]])
        raise TaskError(f"{_name(env)}.restart returned observations that are not finite "
                        f"(row {r}: {first[r].tolist()})")
    if first is obs:
        return obs
    merged = np.array(obs, dtype=np.float64)
    merged[again] = first[again]
    return merged


def _step_batch(batch: _core.Batch, obs: npt.NDArray[Any], active: npt.NDArray[np.bool_],
                rates: npt.NDArray[np.float64], env: Any, t: int) -> None:
    """One step of the rows in ``active``; observations that are not finite are the
    environment's error, a diverging integration is not."""
    try:
        batch.step(obs, active=active, out=rates)
    except InvalidArgumentError as e:
        if not str(e).startswith("inputs["):
            raise  # not the environment's doing: an integration that diverged
        raise TaskError(f"{_name(env)}.{'step' if t else 'reset'} returned observations that "
                        f"are not finite ({e})") from None


def _outputs(out: Any, env: Any, rows: int, m: int, rates: npt.NDArray[np.float64]
             ) -> tuple[npt.NDArray[Any], npt.NDArray[Any], npt.NDArray[np.bool_]]:
    """What ``env.step`` returned, checked: ``(observations, rewards, done)``. The checks cost
    nothing while the environment keeps to the protocol; when it does not, the slow path finds
    what is wrong and says so."""
    try:
        obs, reward, done = out
    except (TypeError, ValueError):
        if out is None:
            raise TaskError(f"{_name(env)}.step returned None (does it end with a return?); "
                            "expected three values (observations, rewards, done)") from None
        what = (f"a {type(out).__name__} of {len(out)}" if isinstance(out, tuple | list)
                else with_article(type(out).__name__))
        raise TaskError(f"{_name(env)}.step returned {what}; expected three values "
                        "(observations, rewards, done)") from None
    if type(obs) is not np.ndarray or obs.shape != (rows, m) or obs.dtype.char not in "df":
        obs = observations(obs, env, "step", rows, m)
    if np.may_share_memory(obs, rates):
        obs = obs.copy()  # the batch writes the rates while it reads the observations
    if type(reward) is not np.ndarray or reward.shape != (rows,) or reward.dtype.kind not in "biuf":
        reward = _row_values(reward, env, rows)
    given = done
    if type(done) is not np.ndarray:
        done = np.asarray(done)
    if done.shape != (rows,) or done.dtype.char != "?":
        flags = as_flags(done) if done.shape == (rows,) else None
        if flags is None:
            what = (f"an array of dtype {done.dtype} and shape {done.shape}" if type(given) is np.ndarray
                    else f"{with_article(type(given).__name__)} ({done.dtype}, shape {done.shape})")
            raise TaskError(f"{_name(env)}.step returned done as {what}; expected {FLAGS} of "
                            f"shape (B,) = ({rows},), one per row")
        done = flags
    return obs, reward, done


FLAGS = "booleans (or integers 0 and 1)"
"""What :func:`as_flags` takes, for messages."""


def as_flags(values: npt.NDArray[Any]) -> npt.NDArray[np.bool_] | None:
    """``values`` as booleans: a bool array as it is, an integer array holding only 0 and 1 as
    the flags it means; None for anything else (a float, or an integer such as 2, is not a
    flag, and guessing its meaning would hide a mistake)."""
    if values.dtype == np.bool_:
        return values
    if values.dtype.kind in "iu" and bool(((values == 0) | (values == 1)).all()):
        return values.astype(np.bool_)
    return None


def _running(reward: npt.NDArray[Any], active: npt.NDArray[np.bool_]) -> npt.NDArray[Any]:
    """The rewards of the running rows, 0 elsewhere (whatever an ended row's reward is, even
    NaN). Adding them gives the bits of ``np.add(..., where=active)``, since a return is never
    -0.0 and ``x + 0.0`` is ``x``, at a third of its cost."""
    return np.where(active, reward, 0.0)


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
