"""A user's closed-loop task (``config.task = "python:module.Class"``, see
:mod:`dnnevo.closedloop.named`) as a :class:`~dnnevo.tasks.protocol.Task`, so that ``dnnevo
assess`` judges its champions as it judges the built-in tasks'.

The success rule is the task's own: its class defines ``success_rate``, the fraction of fresh
episodes that must succeed, and ``success(returns, lengths)``, which says which episodes
succeeded from their returns and lengths (one value per row of the last rollout: shape (E,),
one network's episodes, when a champion is judged; every network's rows when a run validates
its candidates). The
fresh episodes are drawn with ``purpose="evaluate"``, which no run draws from.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from dnnevo import _core
from dnnevo.closedloop import named
from dnnevo.config import EvolutionConfig
from dnnevo.errors import ConfigError
from dnnevo.evaluation.assessment import INDEPENDENT, Assessment, rate
from dnnevo.runs import RunDir
from dnnevo.tasks.defaults import evaluate_extra, extra_lines, overall, rate_column

__all__ = ["DEFAULT_TRIALS", "UserTask"]

#: ``dnnevo assess``'s default count of fresh episodes.
DEFAULT_TRIALS = 200


class UserTask:
    """The :class:`~dnnevo.tasks.protocol.Task` of the Python task ``name``. Making one imports
    nothing; judging imports the task's module."""

    DEFAULT_TRIALS = DEFAULT_TRIALS
    UNIT = "episodes"
    ROBOT_LIKE = False
    INPUT_NAMES: list[str] = []
    ANALYSIS_CONDITIONS: dict[str, list[float]] = {}
    MAIN_INPUT = 0
    OUTPUT_NEURON = 0

    rate_column = staticmethod(rate_column)
    overall = staticmethod(overall)
    evaluate_extra = staticmethod(evaluate_extra)
    extra_lines = staticmethod(extra_lines)

    def __init__(self, name: str) -> None:
        self.NAME = name
        self.THRESHOLD = float("nan")  # the class's success_rate, known once judged

    def judge(self, config: EvolutionConfig, net: _core.Network, trials: int, seed: int, *,
              robot_like: bool = False) -> Assessment:
        """``net`` on ``trials`` fresh episodes drawn from ``seed``, by the class's rule."""
        ok, self.THRESHOLD, result = named.closed_loop(config).judged(net, trials, seed, "evaluate")
        overall_rate = rate("episodes", int(ok.sum()), trials, threshold=self.THRESHOLD)
        return Assessment(
            task=config.task, trials=trials, unit=self.UNIT, seed=seed, rates=[overall_rate],
            verdict=overall_rate.verdict or "undecided", method=INDEPENDENT,
            details={"mean_return": float(result.returns.mean()),
                     "mean_length": float(result.lengths.mean())},
        )

    def preface(self, where: Path, a: Assessment) -> list[str]:
        """What ``assess`` ran, and the episodes' mean return and length."""
        d = a.details
        return [f"{where}: champion on {a.trials} fresh episodes (seed {a.seed}); mean return "
                f"{d['mean_return']:.4g}, mean length {d['mean_length']:.1f} steps."]

    def draw(self, run: RunDir, config: EvolutionConfig, seed: int, *,
             animate: bool = False) -> list[str]:
        """No figures of its own (yet)."""
        return []

    def recorded_trials(self, config: EvolutionConfig, net: _core.Network, *,
                        seed: int) -> list[Any]:
        """No recorded trials for the dynamical analysis (yet)."""
        raise ConfigError(f"dnnevo analyze does not know the inputs of {config.task} yet")
