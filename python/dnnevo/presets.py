"""Named experiments: each preset is an :class:`EvolutionConfig` with the paper's settings, and a
``--quick`` variant (small population, few generations) for tests and demos.

Every number of a preset lives here; ``dnnevo presets`` lists them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from dnnevo.config import EvolutionConfig, apply_overrides
from dnnevo.errors import ConfigError

__all__ = ["Preset", "get", "names", "PRESETS"]


@dataclass(frozen=True)
class Preset:
    """One named experiment."""

    summary: str
    config: EvolutionConfig
    quick: dict[str, Any] = field(default_factory=dict)
    """Overrides of the ``--quick`` variant."""


_QUICK = {"population": 60, "generations": 8}

PRESETS: dict[str, Preset] = {
    "sequence-1bit": Preset(
        "paper §5.2: learn 0* or 1* from reinforcement; 5 neurons, 1000 x 500",
        EvolutionConfig(
            task="sequence",
            population=1000,
            generations=500,
            crossover_rate=0.3,
            mutation_rate=0.01,
            size=5,
            n_inputs=2,
            task_params={"targets": ["0", "1"], "trials_per_target": 2, "perf_base": 0.5},
        ),
        _QUICK,
    ),
}


def names() -> list[str]:
    """The preset names, sorted."""
    return sorted(PRESETS)


def get(name: str, *, quick: bool = False, overrides: list[str] | None = None) -> EvolutionConfig:
    """The config of preset ``name``, optionally its quick variant, with ``key=value`` overrides."""
    try:
        preset = PRESETS[name]
    except KeyError:
        raise ConfigError(f"unknown preset {name!r}; presets: {', '.join(names())}") from None
    config = preset.config
    if quick:
        config = EvolutionConfig.from_dict({**config.to_dict(), **preset.quick})
    return apply_overrides(config, overrides or [])
