"""What a task is on the Python side: the names and functions every task module defines, so that
the layers above (``dnnevo assess``, ``plot``, ``sweep``, ``reproduce``) never branch on a
task's name. The built-in tasks' modules (:mod:`dnnevo.tasks.sequence`, :mod:`.nav1d`,
:mod:`.landmark`) each implement it, and :mod:`dnnevo.tasks.registry` maps names to them, as
``crates/tasks`` does in Rust.

A Python task (``"python:module.Class"``, :mod:`dnnevo.tasks.user`) is analysed by ``dnnevo
analyze`` when its class declares what the analysis needs, an :class:`Analysis` as its
``analysis`` attribute: the same names and trials the built-in tasks' modules define.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo.evaluation.assessment import Assessment
from dnnevo.runs import RunDir

__all__ = ["Analysis", "Task", "View", "ViewResult", "views"]


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

    def assess_extra(self, config: EvolutionConfig, champion: _core.Network, seed: int) -> dict[str, Any]:
        """Further tests ``assess`` runs on a champion, as JSON types (``{}`` for none)."""

    def extra_lines(self, extra: dict[str, Any]) -> list[str]:
        """The text of :meth:`assess_extra`'s tests."""

    def draw(self, run: RunDir, config: EvolutionConfig, seed: int, *, animate: bool = False) -> list[str]:
        """Writes the task's figures of the run's champion into its folder; returns their names."""

    def recorded_trials(self, config: EvolutionConfig, net: _core.Network, *,
                        seed: int) -> list[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
        """Real trials drawn from ``seed`` as (firing rates (T, N), inputs (T, M)), for the
        dynamical analysis."""


@dataclass(frozen=True)
class ViewResult:
    """What a task's own view of a champion (:attr:`Analysis.views`) found: its numbers for
    ``analysis.json`` (under :attr:`key`), its summary lines, and its figures by file name
    (``analyze`` writes them into the run folder, atomically, and closes them)."""

    key: str
    doc: dict[str, Any]
    lines: list[str]
    figures: dict[str, Any] = field(default_factory=dict)


View = Callable[[EvolutionConfig, _core.Network, int, str], ViewResult]
"""A task's own view of a champion: ``view(config, net, seed, title)`` (``title`` names the run
in the figures) records what it needs on fresh episodes drawn from ``seed``."""


@dataclass(frozen=True)
class Analysis:
    """What ``dnnevo analyze`` needs of a Python task, which its class declares as
    ``analysis = Analysis(...)``: the names the built-in tasks' modules define
    (:attr:`Task.INPUT_NAMES`, :attr:`Task.ANALYSIS_CONDITIONS`, :attr:`Task.MAIN_INPUT`,
    :attr:`Task.OUTPUT_NEURON`), how many fresh episodes to record for the phase and basins
    figures and the lesions' clamps, and the task's own views. Lesioned networks are judged by
    the class's own success rule, as ``dnnevo assess`` judges the champion."""

    input_names: Sequence[str]
    """The network's inputs, in order (one per sensor)."""
    conditions: Mapping[str, Sequence[float]]
    """The constant input vectors analysed by default, by name (the first one colours the
    basins figure)."""
    main_input: int
    """The input a bifurcation sweep varies by default."""
    output_neuron: int
    """The neuron whose firing rate is the task's answer (:attr:`Task.OUTPUT_NEURON`), which the
    basins figure draws and the summary quotes at each attractor; for a robot, one of its
    wheels."""
    episodes: int = 4
    """Fresh episodes recorded for the phase and basins figures and the clamps' mean rates."""
    views: Sequence[View] = ()
    """The task's own views of a champion, each run by ``analyze`` after the generic analysis."""


def views(task: Any) -> Sequence[View]:
    """The task's own views of a champion (:attr:`Analysis.views`); none for the built-in tasks."""
    return tuple(getattr(task, "ANALYSIS_VIEWS", ()))
