"""The exceptions dnnevo raises. Every one derives from :class:`DnnevoError`.

Errors about bad values also derive from :class:`ValueError`, so ``except ValueError`` works too.
"""

from __future__ import annotations

__all__ = [
    "DnnevoError",
    "InvalidNetworkError",
    "InvalidArgumentError",
    "FormatError",
    "ConfigError",
    "FitnessError",
]


class DnnevoError(Exception):
    """Base class of every dnnevo error."""


class InvalidNetworkError(DnnevoError, ValueError):
    """A network parameter has the wrong shape or an invalid value (NaN, tau <= 0, ...)."""


class InvalidArgumentError(DnnevoError, ValueError):
    """An argument other than a network parameter is invalid (dt, substeps, inputs, ...)."""


class FormatError(DnnevoError):
    """A network file or dict is not a valid ``dnnevo-network`` document."""


class ConfigError(DnnevoError, ValueError):
    """An evolution or task setting is invalid."""


class FitnessError(DnnevoError, ValueError):
    """A fitness value cannot be selected on (NaN, or negative under proportional selection)."""
