"""A task's real trials, recorded for the analysis (firing rates and inputs over time), and a
network driven again by recorded inputs (:func:`replay`).
"""

from __future__ import annotations

from typing import Literal, cast

import numpy as np
import numpy.typing as npt

from dnnevo import _core, tasks
from dnnevo._checks import nonnegative
from dnnevo.config import EvolutionConfig
from dnnevo.errors import InvalidArgumentError

__all__ = ["recorded_trials", "replay", "trial_outputs"]

_Array = npt.NDArray[np.float64]


def recorded_trials(config: EvolutionConfig, net: _core.Network, *, seed: int) -> list[tuple[_Array, _Array]]:
    """Real trials of ``config``'s task drawn from ``seed``, each as (firing rates (T, N), inputs
    (T, M)): one trial per target (sequence), one per landmark (landmark), one fresh chain
    (nav1d) of the task's chain length (:func:`dnnevo.tasks.nav1d.chain_len`: 5 trials for nav1d-single,
    whose network learns its environment in trial 1), at least 2."""
    nonnegative("seed", seed)
    task = tasks.find(config.task)
    if task is None:
        raise InvalidArgumentError(f"task {config.task!r} has no recorded trials to analyse")
    return task.recorded_trials(config, net, seed=seed)


def trial_outputs(config: EvolutionConfig, net: _core.Network, *, seed: int) -> tuple[_Array, _Array]:
    """The :func:`recorded_trials` of ``seed`` stacked: firing rates (T, N) and inputs (T, M)."""
    trials = recorded_trials(config, net, seed=seed)
    return np.vstack([o for o, _ in trials]), np.vstack([i for _, i in trials])


def replay(config: EvolutionConfig, net: _core.Network, inputs: npt.ArrayLike) -> _Array:
    """The states (T, N) of ``net`` from ``v = 0`` driven by recorded ``inputs`` (T, M), one row
    per time step, with the config's integrator: a recorded sequence or landmark trial exactly;
    a nav1d trial to within the recording's time step (its landmark input is the fraction of a
    time step spent on the landmark)."""
    n = net.copy()
    n.reset()
    i = config.integrator
    method = cast(Literal["euler", "rk4"], i.method)
    return np.asarray(n.run(np.asarray(inputs, dtype=float), dt=i.dt, substeps=i.substeps, method=method).states)
