"""A closed-loop task named in a config, so that ``dnnevo run``, ``resume`` and ``evolve`` build
it from ``config.toml`` alone.

``config.task = "python:module.Class"`` names the environment class; ``task_params`` holds the
rollout's ``episodes`` and ``max_steps``, optionally the size of the validation set the champion
is chosen on (``validation_episodes``, default 40), the most episodes run at once (``rows``,
default all) and, besides them, the keyword arguments of
the class;
``config.integrator`` says how the networks are integrated. For example, ``config.toml``::

    task = "python:light.Light"
    n_inputs = 1
    [task_params]
    episodes = 4
    max_steps = 300
    speed = 0.1      # Light(speed=0.1)

A run's ``config.toml`` also records a digest of the class's source, the environment's
attributes and the rollout's settings (``fitness_sha256``): ``resume`` and ``assess`` refuse a
task that no longer matches it.

Building the task imports ``module``: a run folder that names a Python task names code to run,
as a pickle does. Only the commands that run a task import it (``run``, ``resume``, ``assess``,
``plot``, ``analyze``); ``dnnevo show`` never does. The module is looked up on ``sys.path`` and then in the current
folder.
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Mapping
from typing import Any

from dnnevo.closedloop.environment import sensors, whole_size
from dnnevo.closedloop.fitness import ROLLOUT_KEYS, ClosedLoop, close_copy
from dnnevo.config import PYTHON_TASK, EvolutionConfig
from dnnevo.errors import ConfigError, TaskError, did_you_mean, with_article

__all__ = ["ROLLOUT_KEYS", "check_own_task", "class_preset", "closed_loop", "environment_class", "is_closed_loop",
           "is_python_task", "observation_size", "refuse_fitness_function"]

#: The methods a class needs to be a task (the :class:`~dnnevo.closedloop.Environment` protocol);
#: its ``observation_size`` may be set per instance (:class:`~dnnevo.closedloop.gym.GymEnvironment`
#: counts the kept observations), so it is checked on the environment made from the class.
_MEMBERS = ("reset", "step")


def is_python_task(task: str) -> bool:
    """Whether ``task`` names a task written in Python (``"python:..."``)."""
    return task.startswith(PYTHON_TASK)


def is_closed_loop(config: EvolutionConfig) -> bool:
    """Whether ``config`` names a Python task class that the command line can build (its
    ``task_params`` say the rollout's ``max_steps``), without importing anything."""
    return is_python_task(config.task) and "max_steps" in config.task_params


def refuse_fitness_function(config: EvolutionConfig, folder: object, why: str) -> None:
    """Raises a :class:`~dnnevo.ConfigError` when ``config`` is the run in ``folder`` of a Python
    fitness function, which the command line cannot call again (a task class's it can); ``why``
    ends the sentence: what the command needs and where else to get it."""
    if is_python_task(config.task) and not is_closed_loop(config):
        raise ConfigError(f"{folder} was evolved with a Python fitness function ({config.task}), {why}")


def environment_class(task: str) -> type:
    """The class that ``task`` (``"python:module.Class"``) names, imported and checked against the
    protocol before anything of it is called; a :class:`~dnnevo.ConfigError` says what is wrong."""
    path = task.removeprefix(PYTHON_TASK)
    module_name, _, attr = path.rpartition(".")
    if not module_name or not attr:
        raise ConfigError(f"task {task!r} names no class; expected python:module.Class")
    if module_name == "__main__" and not hasattr(sys.modules.get("__main__"), attr):
        # The script that defined the class has it; any other process (the dnnevo command) not.
        raise ConfigError(f"task {task!r} is a class defined in a script, which no other process "
                          f"can import: move {attr} into a module of its own to run, judge or draw "
                          "it from the command line, or do so from that script (docs/closed-loop.md)")
    module = _import(module_name, task)
    cls = getattr(module, attr, None)
    if cls is None:
        # Name the file: a module named like one of the standard library's (code, test, ...)
        # is that one, not the user's.
        where = getattr(module, "__file__", None)
        classes = [k for k, v in vars(module).items() if isinstance(v, type) and not k.startswith("_")]
        raise ConfigError(f"task {task!r}: module {module_name}"
                          f"{f' ({where})' if where else ''} has no {attr}{did_you_mean(attr, classes)}")
    missing = [m for m in _MEMBERS if not hasattr(cls, m)]
    if not isinstance(cls, type) or missing:
        what = (with_article(type(cls).__name__) if not isinstance(cls, type)
                else f"a class without {', '.join(missing)}")
        raise ConfigError(f"task {task!r} is {what}; a task is a class with observation_size, "
                          "reset(episodes, rng) and step(rates, active) (docs/closed-loop.md)")
    return cls


def class_preset(task: str) -> dict[str, Any]:
    """The settings that the class ``task`` names declares as its own preset, a class attribute
    ``preset`` that holds what a config file would (``{"size": 3, "selection": "rank",
    "task_params": {"max_steps": 300, "episodes": 4}}``), checked: the command line and
    :func:`dnnevo.evolve` start from them, before ``--set``. Empty when the class declares none.

    >>> class_preset("python:dnnevo.closedloop.FarSeeker")
    {}
    """
    cls = environment_class(task)
    preset = getattr(cls, "preset", None)
    if preset is None:
        return {}
    where = f"{cls.__name__}.preset"
    if not isinstance(preset, Mapping):
        raise ConfigError(f"{where} is {with_article(type(preset).__name__)}; expected a dict of settings "
                          "as in config.toml, e.g. {\"size\": 3, \"task_params\": {\"max_steps\": 300}}")
    if "task" in preset:
        raise ConfigError(f"{where} sets task; the class is the task, so leave it out")
    try:
        EvolutionConfig.from_dict({**preset, "task": task})
    except ConfigError as e:
        raise ConfigError(f"{where}: {e}") from None
    return dict(preset)


def _import(module_name: str, task: str) -> Any:
    """Imports ``module_name``, looking in the current folder too, as ``python -m`` would."""
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as e:
        here = os.getcwd()
        if e.name != module_name.split(".")[0] or here in sys.path:
            hint = (f"; run the command from the folder that holds {e.name}.py, or put that folder "
                    "on PYTHONPATH" if e.name == module_name.split(".")[0] else "")
            raise ConfigError(f"task {task!r}: cannot import {module_name}: {e}{hint}") from None
        sys.path.append(here)  # after everything else, so that it shadows no other module
        return _import(module_name, task)
    except Exception as e:
        raise ConfigError(f"task {task!r}: importing {module_name} raised "
                          f"{type(e).__name__}: {e}") from e


def observation_size(task: str, task_params: Mapping[str, Any] | None = None) -> int | None:
    """The ``observation_size`` of the environment that ``task`` names (importing its module),
    the ``n_inputs`` its networks need: that of an instance made with ``task_params`` (less the
    rollout's settings), as :func:`closed_loop` makes it, since an instance may set its own (a
    :class:`~dnnevo.robots.RobotWorld` counts its sensors); else the class's. None when neither
    is a whole number >= 0 (a mistake that :func:`closed_loop` then names)."""
    cls = environment_class(task)
    params = {k: v for k, v in (task_params or {}).items() if k not in ROLLOUT_KEYS}
    try:
        size = whole_size(getattr(cls(**params), "observation_size", None))
    except Exception:  # noqa: BLE001 - closed_loop names what is wrong with the arguments
        size = None
    return size if size is not None else whole_size(getattr(cls, "observation_size", None))


def closed_loop(config: EvolutionConfig, *, digest: str | None = None,
                parts: Mapping[str, str] | None = None) -> ClosedLoop:
    """The fitness function of the task that ``config`` names (see the module docs). With
    ``digest`` (a run's ``fitness_sha256``), it must be the run's own task; ``parts`` (its
    ``fitness_parts``, when it has them) let the refusal say what differs."""
    cls = environment_class(config.task)
    params = dict(config.task_params)
    settings = {k: params.pop(k) for k in ROLLOUT_KEYS if k in params}
    if "max_steps" not in settings:
        raise ConfigError(f"task {config.task!r} needs task_params.max_steps, the longest episode "
                          "in time steps (and task_params.episodes, default 1)")
    try:
        env = cls(**params)
    except TypeError as e:
        raise ConfigError(f"{cls.__name__}(**task_params) failed: {e}") from None
    except Exception as e:
        raise TaskError(f"{cls.__name__}(**task_params) raised {type(e).__name__}: {e}") from e
    try:
        return _checked_loop(config, cls, env, settings, digest, parts)
    except BaseException:
        close_copy(env)  # the refused task's environment
        raise


def _checked_loop(config: EvolutionConfig, cls: type, env: Any, settings: dict[str, Any],
                  digest: str | None, parts: Mapping[str, str] | None) -> ClosedLoop:
    """:func:`closed_loop`'s checks of the environment it made, and the task around it."""
    size = sensors(env)
    if size != config.n_inputs:
        raise ConfigError(f"n_inputs is {config.n_inputs}; {cls.__name__}.observation_size is "
                          f"{env.observation_size} (set n_inputs = {env.observation_size})")
    i = config.integrator
    loop = ClosedLoop(env, **settings, dt=i.dt, substeps=i.substeps, method=i.method,
                      precision=config.precision, name=config.task)
    if digest is not None and digest not in loop.digests():
        raise ConfigError(f"the run was evolved with another version of {config.task} "
                          f"({what_differs(loop, parts)})")
    return loop


DIFFERENCES = {
    "source": "the class's source, or what it reads from its module, was edited since the run "
              "(comments, docstrings and layout count only for runs recorded before dnnevo left "
              "them out); a success rule added or changed counts: it is part of the task",
    "attributes": "the environment's attributes differ: task_params, or the run began from Python "
                  "with an environment made with arguments config.toml could not record, or one "
                  "that had run episodes before ClosedLoop wrapped it",
    "settings": "the rollout's settings differ: episodes, max_steps, validation_episodes, rows, "
                "precision or the integrator",
}
"""What each part of a task's digest (:meth:`ClosedLoop.part_digests`) differing means."""


def what_differs(loop: ClosedLoop, parts: Mapping[str, str] | None) -> str:
    """Which parts of the task differ from the run's (its ``fitness_parts``), said; all three
    possibilities for a run that recorded no parts."""
    if isinstance(parts, Mapping):  # a damaged [run] table says nothing more
        differ = [k for k, v in loop.part_digests().items() if parts.get(k) != v]
        if differ:
            return "; ".join(DIFFERENCES[k] for k in differ)
    return ("its source, the environment's attributes or the rollout's settings differ, or the run "
            "began from Python with an environment made with other arguments")


def check_own_task(config: EvolutionConfig, table: dict[str, Any]) -> None:
    """Raises a :class:`~dnnevo.ConfigError` unless the task class that a run's ``config``
    names is still the one it was evolved with (``table``, its ``[run]`` table, holds the
    digest); nothing for a built-in task or a fitness function. What judges or draws a run's
    champion (``assess``, ``plot``, ``analyze``) calls it first: an edited class would judge the
    champion in another task."""
    if is_closed_loop(config):
        closed_loop(config, digest=table.get("fitness_sha256"), parts=table.get("fitness_parts"))
