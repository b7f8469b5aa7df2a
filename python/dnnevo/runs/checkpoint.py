"""A run's checkpoint, validated: the GA state, the history and the run table, enough to continue
bit for bit."""

from __future__ import annotations

from typing import Any

from dnnevo.config import EvolutionConfig

__all__ = ['CHECKPOINT_FORMAT', 'CHECKPOINT_VERSION', 'Checkpoint']

CHECKPOINT_FORMAT = "dnnevo-checkpoint"
#: Version 2 added the run table and the config digest; version 1 is still read.
CHECKPOINT_VERSION = 2


class Checkpoint:
    """A validated checkpoint: the GA state, the history and the run table."""

    def __init__(self, state: dict[str, Any], history: list[dict[str, float]],
                 run: dict[str, Any] | None, config: EvolutionConfig) -> None:
        self.state = state
        self.history = history
        self.run = run
        """The ``[run]`` table (seed, version, ...); None in a version-1 checkpoint."""
        self.config = config
