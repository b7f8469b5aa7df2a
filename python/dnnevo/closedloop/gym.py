"""A Gymnasium (1.x) vector environment as a closed-loop task: ``pip install "dnnevo[gym]"``.

:class:`GymEnvironment` makes one vector environment with a sub-environment per row and maps the
networks' firing rates to its actions:

- ``"argmax"`` (a ``Discrete(n)`` space): the action is the index of the most active of the
  first ``n`` output neurons (plus the space's ``start``);
- ``"threshold"`` (``Discrete(2)``): action 1 (plus ``start``) when the first output neuron's
  rate is above 0.5;
- ``"box"`` (a ``Box`` with finite bounds): each of the first ``d`` output neurons' rates, in
  [0, 1], scaled onto the action's ``[low, high]``: float64, or rounded to the space's dtype
  for an integer box.

``outputs`` chooses the output neurons (default: neurons 0, 1, ...). ``vectorization_mode`` and
``autoreset_mode`` (``"next_step"``, ``"same_step"`` or ``"disabled"``) are passed to
``gymnasium.make_vec``, and ``make_kwargs`` to the environment. ``observations`` keeps only
some observation components (CartPole with its velocities hidden keeps 0 and 2) and
``observation_scale`` multiplies them.

**Autoreset.** Each row runs one episode and leaves the rollout when it ends, so what a vector
environment does after an episode's end is never read: with the next-step mode (Gymnasium's
default) the step after the end resets the sub-environment; with the same-step mode the last
observation is the next episode's first; with autoreset disabled, stepping an ended
sub-environment is an error, so ended sub-environments are reset at once with ``reset_mask``.
With fewer rows than episodes (``rollout(..., rows=R)``), :meth:`GymEnvironment.restart` starts
a waiting episode in an ended row (see there).

**Common random numbers.** A vector environment made of separate environments (the ``"sync"``
vectorization mode) is seeded sub-environment by sub-environment, episode number by episode
number, so every network meets the same starting conditions. A natively vectorised environment
(``"vector_entry_point"``, such as ``CartPoleVectorEnv``, about 20x faster) takes one seed for
all rows: its rows start in different conditions, and the comparison between networks is
noisier.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from dnnevo.closedloop.environment import check_neurons
from dnnevo.errors import ConfigError, counted

try:
    import gymnasium as gym
    from gymnasium.envs.registration import find_highest_version, get_env_id, parse_env_id
except ImportError as e:  # pragma: no cover - depends on the installation
    raise ImportError('dnnevo.closedloop.gym needs Gymnasium: pip install "dnnevo[gym]"') from e

__all__ = ["ACTIONS", "GymEnvironment"]

#: How firing rates become actions.
ACTIONS = ("argmax", "threshold", "box")
VECTORIZATION_MODES = ("vector_entry_point", "sync", "async")
"""``gymnasium.make_vec``'s modes."""


def _spec(env_id: str) -> Any:
    """The registered spec of ``env_id``, of its latest version when it names none (as
    ``gymnasium.make`` takes it); None when there is none (``gymnasium.make`` then says why)."""
    try:
        namespace, name, version = parse_env_id(env_id)
        if version is None:
            version = find_highest_version(namespace, name)
        return gym.spec(get_env_id(namespace, name, version))
    except Exception:  # noqa: BLE001 - not registered, or not an id
        return None


class GymEnvironment:
    """The Gymnasium environment ``env_id``, one sub-environment per row (see the module docs)."""

    def __init__(self, env_id: str, *, actions: str = "argmax", outputs: Sequence[int] | None = None,
                 observations: Sequence[int] | None = None,
                 observation_scale: float | Sequence[float] = 1.0,
                 vectorization_mode: str = "vector_entry_point", autoreset_mode: str | None = None,
                 make_kwargs: Mapping[str, Any] | None = None) -> None:
        if actions not in ACTIONS:
            raise ConfigError(f"actions is {actions!r}; expected one of {', '.join(ACTIONS)}")
        self.env_id, self.actions, self.vectorization_mode = env_id, actions, vectorization_mode
        self.make_kwargs = dict(make_kwargs or {})
        modes = {m.name.lower(): m for m in gym.vector.AutoresetMode}
        if autoreset_mode is not None and autoreset_mode not in modes:
            raise ConfigError(f"autoreset_mode is {autoreset_mode!r}; expected one of "
                              f"{', '.join(modes)} (or None: the environment's own)")
        self.autoreset_mode = modes.get(autoreset_mode or "")
        if vectorization_mode not in VECTORIZATION_MODES:
            raise ConfigError(f"vectorization_mode is {vectorization_mode!r}; expected one of "
                              f"{', '.join(VECTORIZATION_MODES)}")
        spec = _spec(env_id)
        if vectorization_mode == "vector_entry_point" and spec is not None and spec.vector_entry_point is None:
            raise ConfigError(f"{env_id} has no native vector environment (vectorization_mode "
                              "\"vector_entry_point\", the default); give vectorization_mode=\"sync\" "
                              "(or \"async\")")
        try:
            probe = gym.make(env_id, **self.make_kwargs)
        except Exception as e:  # noqa: BLE001 - an unknown id or module, a keyword the environment refuses
            # An unknown id, a misspelt keyword of make_kwargs: the environment's own words.
            raise ConfigError(f"gymnasium.make({env_id!r}, **make_kwargs) failed: {type(e).__name__}: {e}") from None
        try:
            obs_space, act_space = probe.observation_space, probe.action_space
        finally:
            probe.close()
        if obs_space.shape is None:
            raise ConfigError(f"{env_id}'s observation space has no shape; dnnevo needs a box of numbers")
        width = int(np.prod(obs_space.shape))
        self.columns = np.arange(width) if observations is None else np.asarray(observations)
        if self.columns.ndim != 1 or (self.columns.size and self.columns.dtype.kind not in "iu"):
            raise ConfigError(f"observations is {observations!r}; expected a list of component numbers")
        if self.columns.size and (self.columns.min() < 0 or self.columns.max() >= width):
            raise ConfigError(f"observations is {self.columns.tolist()}; {env_id} has {width} components")
        self.observation_size = int(self.columns.size)
        self.every_column = bool(np.array_equal(self.columns, np.arange(width)))
        try:
            self.scale = np.broadcast_to(np.asarray(observation_scale, dtype=np.float64),
                                         (self.observation_size,)).copy()
        except (ValueError, TypeError):
            raise ConfigError(f"observation_scale is {observation_scale!r}; expected a number or one per kept "
                              f"observation ({self.observation_size})") from None
        if not np.isfinite(self.scale).all():
            raise ConfigError(f"observation_scale is {observation_scale!r}; every scale must be finite")
        if actions == "box":
            if not isinstance(act_space, gym.spaces.Box):
                raise ConfigError(f"actions 'box' needs a Box action space; {env_id} has {act_space}")
            count = int(np.prod(act_space.shape))
            self.low = np.asarray(act_space.low, dtype=np.float64).reshape(-1)
            self.span = np.asarray(act_space.high, dtype=np.float64).reshape(-1) - self.low
            if not (np.isfinite(self.low).all() and np.isfinite(self.span).all()):
                raise ConfigError(f"actions 'box' maps a firing rate onto the action's bounds, which must "
                                  f"be finite; {env_id} has {act_space}")
            self.action_shape, self.action_dtype = act_space.shape, act_space.dtype
            self.start = 0
        else:
            if not isinstance(act_space, gym.spaces.Discrete):
                raise ConfigError(f"actions {actions!r} needs a Discrete action space; {env_id} has "
                                  f"{act_space}")
            count = 1 if actions == "threshold" else int(act_space.n)
            if actions == "threshold" and act_space.n != 2:
                raise ConfigError(f"actions 'threshold' needs Discrete(2); {env_id} has {act_space}")
            self.start = int(act_space.start)  # Discrete(n, start=s) takes s .. s + n - 1
        self.outputs = np.arange(count) if outputs is None else np.asarray(outputs)
        if self.outputs.size and (self.outputs.dtype.kind not in "iu" or self.outputs.min() < 0):
            raise ConfigError(f"outputs is {self.outputs.tolist()}; expected neuron numbers >= 0")
        if len(self.outputs) != count:
            raise ConfigError(f"outputs names {counted(len(self.outputs), 'neuron')}; actions {actions!r} on "
                              f"{act_space} needs {count}")
        self.envs: Any = None

    def _make(self, rows: int) -> Any:
        vector_kwargs = {}
        if self.autoreset_mode is not None:
            vector_kwargs["autoreset_mode"] = self.autoreset_mode
        if self.envs is not None:
            self.envs.close()
        self.envs = gym.make_vec(self.env_id, num_envs=rows, vectorization_mode=self.vectorization_mode,
                                 vector_kwargs=vector_kwargs, **self.make_kwargs)
        self.disabled = self.envs.metadata.get("autoreset_mode") == gym.vector.AutoresetMode.DISABLED
        return self.envs

    def reset(self, episodes: npt.NDArray[np.int64], rng: np.random.Generator) -> npt.NDArray[np.float64]:
        """A sub-environment per row, seeded per episode number where the environment allows."""
        rows = len(episodes)
        envs = self.envs if self.envs is not None and self.envs.num_envs == rows else self._make(rows)
        seeds = rng.integers(0, 2**31 - 1, size=int(episodes.max()) + 1)
        self.seeds = seeds  # each episode number's, for restart
        if self.vectorization_mode == "vector_entry_point":
            obs, _ = envs.reset(seed=int(seeds[0]))
        else:
            obs, _ = envs.reset(seed=[int(s) for s in seeds[episodes]])
        self.fresh = obs
        return self._observe(obs)

    def restart(self, rows: npt.NDArray[np.bool_], episodes: npt.NDArray[np.int64]
                ) -> npt.NDArray[np.float64] | None:
        """Starts episode ``episodes[r]`` in each sub-environment ``r`` where ``rows`` is True,
        after its last episode ended. Separate sub-environments (``"sync"``, ``"async"``) are
        reset with that episode number's seed. A natively vectorised environment is not reset
        row by row: with the next-step autoreset mode it starts the new episodes at its next
        step (None: the rollout has those rows wait it out); with the same-step mode the last
        observations are already the new episodes' first, and with autoreset disabled
        :meth:`step` has already reset the ended sub-environments."""
        if self.vectorization_mode != "vector_entry_point":
            seeds = [int(self.seeds[e]) if on else None for on, e in zip(rows, episodes, strict=True)]
            obs, _ = self.envs.reset(seed=seeds, options={"reset_mask": np.array(rows, dtype=bool)})
            return self._observe(obs)
        if self.envs.metadata.get("autoreset_mode", gym.vector.AutoresetMode.NEXT_STEP) \
                == gym.vector.AutoresetMode.NEXT_STEP:
            return None
        return self._observe(self.fresh)

    def step(self, rates: npt.NDArray[np.float64], active: npt.NDArray[np.bool_]
             ) -> tuple[npt.NDArray[np.float64], npt.NDArray[Any], npt.NDArray[np.bool_]]:
        """One step of every sub-environment with the actions the rates choose."""
        obs, reward, terminated, truncated, _ = self.envs.step(self._act(rates))
        done = np.logical_or(terminated, truncated)
        self.fresh = obs
        if self.disabled and done.any():
            # Autoreset disabled: an ended sub-environment must be reset before its next step.
            self.fresh, _ = self.envs.reset(options={"reset_mask": done})
        return self._observe(obs), np.asarray(reward), done

    def _observe(self, obs: npt.NDArray[Any]) -> npt.NDArray[np.float64]:
        """The kept components, scaled, as a new C-contiguous float64 array (the batch reads it
        without a copy)."""
        flat = obs if isinstance(obs, np.ndarray) and obs.ndim == 2 else \
            np.asarray(obs).reshape(len(obs), -1)
        if not self.every_column:
            flat = flat[:, self.columns]
        return np.multiply(flat, self.scale, out=np.empty((len(obs), self.observation_size)))

    def _act(self, rates: npt.NDArray[np.float64]) -> npt.NDArray[Any]:
        check_neurons(rates, self.outputs, f"{type(self).__name__}'s {self.actions!r} actions")
        if self.actions == "threshold":
            return (rates[:, self.outputs[0]] > 0.5).astype(np.int64) + self.start
        chosen = rates[:, self.outputs]
        if self.actions == "argmax":
            return np.argmax(chosen, axis=1) + self.start
        action = (self.low + chosen * self.span).reshape((len(rates), *self.action_shape))
        if np.issubdtype(self.action_dtype, np.integer):
            return np.rint(action).astype(self.action_dtype)
        # Float actions stay float64, as evolution has always given them: a float32 space's
        # environment computes with them as given (Pendulum-v1's returns depend on it).
        return action

    def close(self) -> None:
        """Closes the vector environment."""
        if self.envs is not None:
            self.envs.close()
            self.envs = None
