"""What a task is on the Python side: the names and functions every task module defines, so that
the layers above (``dnnevo assess``, ``plot``, ``sweep``, ``reproduce``) never branch on a
task's name. The built-in tasks' modules (:mod:`dnnevo.tasks.sequence`, :mod:`.nav1d`,
:mod:`.landmark`) each implement it, and :mod:`dnnevo.tasks.registry` maps names to them, as
``crates/tasks`` does in Rust.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo.evaluation.assessment import Assessment
from dnnevo.runs import RunDir

__all__ = ["Task"]


class Task(Protocol):
    """A task's Python home: its success rule, its assessment, its report text and its figures."""

    NAME: str
    """The task's name, as ``config.task`` and the Rust registry spell it."""
    THRESHOLD: float
    """The rate the task's success rule needs."""
    DEFAULT_TRIALS: int
    """``dnnevo assess``'s default trial count, in :attr:`UNIT`."""
    UNIT: str
    """What a trial count counts (trials per target, trials per landmark, chains)."""
    ROBOT_LIKE: bool
    """Whether the task has a robot-like test (``dnnevo assess --robot-like``)."""
    INPUT_NAMES: list[str]
    """The network's inputs, in order."""
    ANALYSIS_CONDITIONS: dict[str, list[float]]
    """The constant input conditions ``dnnevo analyze`` looks at by default."""
    MAIN_INPUT: int
    """The input (index into :attr:`INPUT_NAMES`) a bifurcation sweep varies by default."""
    OUTPUT_NEURON: int
    """The neuron whose firing rate is the task's answer."""

    def judge(self, config: EvolutionConfig, net: _core.Network, trials: int, seed: int, *,
              robot_like: bool = False) -> Assessment:
        """``net`` judged on ``trials`` fresh conditions drawn from ``seed``."""

    def preface(self, where: Path, a: Assessment) -> list[str]:
        """``dnnevo assess``'s first lines: what was run, and the task's own table."""

    def rate_column(self, a: Assessment) -> tuple[str, dict[str, str]] | None:
        """An extra column of ``assess``'s rate table: its header and its cells by rate name."""

    def overall(self, a: Assessment) -> str:
        """``assess``'s verdict line."""

    def evaluate_extra(self, config: EvolutionConfig, champion: _core.Network, seed: int) -> dict[str, Any]:
        """Further tests ``assess`` runs on a champion, as JSON types (``{}`` for none)."""

    def extra_lines(self, extra: dict[str, Any]) -> list[str]:
        """The text of :meth:`evaluate_extra`'s tests."""

    def draw(self, run: RunDir, config: EvolutionConfig, seed: int, *, animate: bool = False) -> list[str]:
        """Writes the task's figures of the run's champion into its folder; returns their names."""

    def recorded_trials(self, config: EvolutionConfig, net: _core.Network, *,
                        seed: int) -> list[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
        """Real trials drawn from ``seed`` as (firing rates (T, N), inputs (T, M)), for the
        dynamical analysis."""
