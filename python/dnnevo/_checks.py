"""Argument checks shared by the task modules (``sequence``, ``nav1d``, ``landmark``)."""

from __future__ import annotations

import json

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError, InvalidArgumentError


def nonnegative(name: str, value: int) -> int:
    """``value`` if it is an integer in [0, 2**64), else an :class:`InvalidArgumentError` naming
    it."""
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value < 2**64:
        raise InvalidArgumentError(f"{name} is {value!r}; it must be an integer in [0, 2**64)")
    return value


def bounded_count(name: str, value: int) -> int:
    """``value`` if it is an integer in [1, MAX_COUNT] (the Rust core's limit on any count of
    trials, chains or environments, 2**20), else an :class:`InvalidArgumentError` naming it: a
    larger count is a typing error that would otherwise make the core allocate terabytes."""
    limit = _core.MAX_COUNT
    if not isinstance(value, int) or isinstance(value, bool) or not 1 <= value <= limit:
        raise InvalidArgumentError(f"{name} is {value!r}; it must be an integer in [1, {limit}]")
    return value


def task_params(config: EvolutionConfig, task: str) -> str:
    """The JSON parameters of ``config``'s task, which must be ``task``."""
    if config.task != task:
        raise ConfigError(f"config.task is {config.task!r}; expected {task!r}")
    return json.dumps(config.task_json())
