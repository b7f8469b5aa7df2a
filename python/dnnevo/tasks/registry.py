"""The built-in tasks by name, mirroring the Rust registry (``_core.task_names()``), and the one
entry point that judges a network for whatever task its config names.

>>> from dnnevo.tasks import registry
>>> registry.names()
['landmark', 'nav1d', 'sequence']
>>> registry.get("nav1d").UNIT
'chains'
"""

from __future__ import annotations

import difflib

from dnnevo import _core
from dnnevo._checks import nonnegative
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError, InvalidArgumentError
from dnnevo.evaluation.assessment import Assessment
from dnnevo.closedloop import named
from dnnevo.tasks import landmark, nav1d, sequence
from dnnevo.tasks.protocol import Task
from dnnevo.tasks.user import UserTask

__all__ = ["DEFAULT_TRIALS", "THRESHOLDS", "UNITS", "assess", "find", "get", "names"]

_TASKS: dict[str, Task] = {t.NAME: t for t in (landmark, nav1d, sequence)}

THRESHOLDS = {name: t.THRESHOLD for name, t in _TASKS.items()}
"""Each task's success threshold, by name."""
DEFAULT_TRIALS = {name: t.DEFAULT_TRIALS for name, t in _TASKS.items()}
"""``dnnevo assess``'s default trial count of each task, by name."""
UNITS = {name: t.UNIT for name, t in _TASKS.items()}
"""What each task's trial count counts, by name."""

if sorted(_TASKS) != sorted(_core.task_names()):  # pragma: no cover - a build that lost a task
    raise ImportError(f"the Python tasks {sorted(_TASKS)} are not the core's {_core.task_names()}")


def names() -> list[str]:
    """The built-in tasks' names, sorted."""
    return sorted(_TASKS)


def find(name: str) -> Task | None:
    """The task called ``name``, or None (a Python fitness function's run has none)."""
    return _TASKS.get(name)


def get(name: str) -> Task:
    """The task called ``name``, a built-in one or a Python task (``"python:module.Class"``,
    judged by its class's own rule); an unknown name is a :class:`~dnnevo.ConfigError` that lists
    the tasks and suggests the closest."""
    if named.is_python_task(name):
        return UserTask(name)
    task = _TASKS.get(name)
    if task is None:
        close = difflib.get_close_matches(name, _TASKS, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise ConfigError(f"task {name!r} has no success rule to judge{hint}; tasks with one: "
                          f"{', '.join(names())}")
    return task


def assess(config: EvolutionConfig, net: _core.Network, trials: int | None = None, *, seed: int,
           robot_like: bool = False) -> Assessment:
    """Judges ``net`` on fresh conditions drawn from ``seed`` by the rule of ``config.task``:
    ``trials`` per target, per landmark or chains (default :data:`DEFAULT_TRIALS`).
    ``robot_like`` applies to tasks with a robot-like test (landmark)."""
    task = get(config.task)
    if robot_like and not task.ROBOT_LIKE:
        raise ConfigError(f"robot_like applies to landmark runs; this is a {config.task} run")
    nonnegative("seed", seed)
    if trials is None:
        trials = task.DEFAULT_TRIALS
    if not isinstance(trials, int) or isinstance(trials, bool) or trials < 1:
        raise InvalidArgumentError(f"trials is {trials!r}; it must be an integer >= 1")
    return task.judge(config, net, trials, seed, robot_like=robot_like)
