"""Argument checks shared by the task and analysis modules."""

from __future__ import annotations

import numbers
from typing import TypeVar

import numpy as np

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError, InvalidArgumentError

T = TypeVar("T")


def nonnegative(name: str, value: int) -> int:
    """``value`` if it is an integer in [0, 2**64), else an :class:`InvalidArgumentError` naming
    it."""
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value < 2**64:
        raise InvalidArgumentError(f"{name} is {value!r}; it must be an integer in [0, 2**64)")
    return value


def index(name: str, value: object, size: int, of: str) -> int:
    """``value`` as an index in 0..size-1 (an integer, Python's or NumPy's, not a bool), else an
    :class:`InvalidArgumentError` naming it and saying what it indexes (``of``, e.g. "this
    network has 3 sensors")."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral) \
            or not 0 <= int(value) < size:
        allowed = f"so it must be an integer in 0..{size - 1}" if size else "so nothing can be indexed"
        raise InvalidArgumentError(f"{name} is {value!r}; {of}, {allowed}")
    return int(value)


def bounded_count(name: str, value: int) -> int:
    """``value`` if it is an integer in [1, MAX_COUNT] (the Rust core's limit on any count of
    trials, chains or environments, 2**20), else an :class:`InvalidArgumentError` naming it: a
    larger count is a typing error that would otherwise make the core allocate terabytes."""
    limit = _core.MAX_COUNT
    if not isinstance(value, int) or isinstance(value, bool) or not 1 <= value <= limit:
        raise InvalidArgumentError(f"{name} is {value!r}; it must be an integer in [1, {limit}]")
    return value


def builtin(config: EvolutionConfig, task: str, kind: type[T]) -> T:
    """``config``'s built-in task object (a ``_core`` class of type ``kind``), built once per
    config; ``config.task`` must be ``task``."""
    if config.task != task:
        raise ConfigError(f"config.task is {config.task!r}; expected {task!r}")
    built = config.native.builtin()
    if not isinstance(built, kind):  # pragma: no cover - the core maps each name to its class
        raise ConfigError(f"the {task} task was built as a {type(built).__name__}")
    return built
