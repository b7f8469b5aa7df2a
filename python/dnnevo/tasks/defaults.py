"""The parts of the :class:`~dnnevo.tasks.protocol.Task` protocol that most tasks have nothing
special for: a task module imports these under the protocol's names (sequence learning, with
its switch test and mean-performance column, defines its own)."""

from __future__ import annotations

from typing import Any

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo.evaluation import assessment
from dnnevo.evaluation.assessment import Assessment

__all__ = ["assess_extra", "extra_lines", "overall", "rate_column"]


def rate_column(a: Assessment) -> tuple[str, dict[str, str]] | None:
    """No extra column beside the rates."""
    return None


def overall(a: Assessment) -> str:
    """The verdict line of the one judged, overall rate."""
    return assessment.verdict_line(a)


def assess_extra(config: EvolutionConfig, champion: _core.Network, seed: int) -> dict[str, Any]:
    """No further test."""
    return {}


def extra_lines(extra: dict[str, Any]) -> list[str]:
    """No further test to print."""
    return []
