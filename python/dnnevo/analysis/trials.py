"""A task's real trials, recorded for the analysis (firing rates and inputs over time), and a
network driven again by recorded inputs (:func:`replay`). :func:`analysed_task` is the task
whose names and trials the analysis uses: a built-in task's module, or a Python task whose class
declares an :class:`~dnnevo.tasks.protocol.Analysis`.
"""

from __future__ import annotations

from typing import Literal, cast

import numpy as np
import numpy.typing as npt

from dnnevo import _core, tasks
from dnnevo._checks import nonnegative
from dnnevo.closedloop import named
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError
from dnnevo.tasks import user
from dnnevo.tasks.protocol import Task

__all__ = ["analysed_task", "recorded_trials", "replay", "trial_outputs"]

_Array = npt.NDArray[np.float64]


def recorded_trials(config: EvolutionConfig, net: _core.Network, *, seed: int) -> list[tuple[_Array, _Array]]:
    """Real trials of ``config``'s task drawn from ``seed``, each as (firing rates (T, N), inputs
    (T, M)): one trial per target (sequence), one per landmark (landmark), one fresh chain
    (nav1d) of the task's chain length (:func:`dnnevo.tasks.nav1d.chain_len`: 5 trials for nav1d-single,
    whose network learns its environment in trial 1), at least 2; for a Python task, the first
    :attr:`~dnnevo.tasks.protocol.Analysis.episodes` fresh episodes of those ``dnnevo assess``
    judges with this seed."""
    nonnegative("seed", seed)
    return analysed_task(config).recorded_trials(config, net, seed=seed)


def analysed_task(config: EvolutionConfig) -> Task:
    """The task of ``config`` as the analysis reads it (its input names, default conditions,
    main input, output neuron and recorded trials): a built-in task's module, or a Python task
    (``"python:module.Class"``) whose class declares them (:func:`dnnevo.tasks.user.analysed`,
    which imports the class). Any other task is a one-line :class:`~dnnevo.ConfigError`."""
    task = tasks.find(config.task)
    if task is not None:
        return task
    if named.is_python_task(config.task):
        return user.analysed(config)
    raise ConfigError(f"task {config.task!r} has no analysis defaults; tasks with one: "
                      f"{', '.join(tasks.names())}, and Python tasks whose class declares them")


def trial_outputs(config: EvolutionConfig, net: _core.Network, *, seed: int) -> tuple[_Array, _Array]:
    """The :func:`recorded_trials` of ``seed`` stacked: firing rates (T, N) and inputs (T, M)."""
    trials = recorded_trials(config, net, seed=seed)
    return np.vstack([o for o, _ in trials]), np.vstack([i for _, i in trials])


def replay(config: EvolutionConfig, net: _core.Network, inputs: npt.ArrayLike) -> _Array:
    """The states (T, N) of ``net`` from ``v = 0`` driven by recorded ``inputs`` (T, M), one row
    per time step, with the config's integrator and precision: a recorded sequence or landmark
    trial exactly; a nav1d trial to within the recording's time step (its landmark input is the
    fraction of a time step spent on the landmark)."""
    n = net.copy()
    n.reset()
    i = config.integrator
    method = cast(Literal["euler", "rk4"], i.method)
    precision = cast(Literal["f64", "f32"], config.precision)
    return np.asarray(n.run(np.asarray(inputs, dtype=float), dt=i.dt, substeps=i.substeps, method=method,
                            precision=precision).states)
