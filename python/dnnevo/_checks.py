"""Argument checks shared by the task modules (``sequence``, ``nav1d``, ``landmark``)."""

from __future__ import annotations

import json

from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError, InvalidArgumentError


def nonnegative(name: str, value: int) -> int:
    """``value`` if it is an integer in [0, 2**64), else an :class:`InvalidArgumentError` naming
    it."""
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value < 2**64:
        raise InvalidArgumentError(f"{name} is {value!r}; it must be an integer in [0, 2**64)")
    return value


def task_params(config: EvolutionConfig, task: str) -> str:
    """The JSON parameters of ``config``'s task, which must be ``task``."""
    if config.task != task:
        raise ConfigError(f"config.task is {config.task!r}; expected {task!r}")
    return json.dumps(config.task_json())
