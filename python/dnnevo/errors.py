"""The exceptions dnnevo raises. Every one derives from :class:`DnnevoError`.

Errors about bad values also derive from :class:`ValueError`, so ``except ValueError`` works too.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

__all__ = [
    "DnnevoError",
    "InvalidNetworkError",
    "InvalidArgumentError",
    "FormatError",
    "ConfigError",
    "FitnessError",
    "TaskError",
    "WriteError",
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


class WriteError(DnnevoError, OSError):
    """A file could not be written: the disk is full, a file-size limit was reached, or the
    folder is read-only. Files are written whole or not at all, so the file is as it was."""


class TaskError(DnnevoError, ValueError):
    """A user's task broke its protocol: a method raised, or returned a wrong shape, a wrong
    dtype or a value that is not finite. The message names the method and the problem."""


def with_article(noun: str) -> str:
    """``noun`` after its indefinite article, for messages that name a type (``ndarray`` is
    read "en-dee-array").

    >>> with_article("int"), with_article("function"), with_article("ndarray")
    ('an int', 'a function', 'an ndarray')
    """
    vowel = noun[:1].lower() in "aeiou" or noun.startswith("ndarray")
    return f"{'an' if vowel else 'a'} {noun}"


def counted(n: int, noun: str) -> str:
    """``n`` and ``noun``, the noun plural unless ``n`` is 1, for messages (as Rust's
    ``error::counted``).

    >>> counted(1, "sensor"), counted(3, "sensor")
    ('1 sensor', '3 sensors')
    """
    return f"{n} {noun}{'' if n == 1 else 's'}"


def beer_hint(name: str) -> str:
    """The hint an "unknown name" message carries when ``name`` (or its last dotted part) is a
    parameter of Beer's CTRNN code that dnnevo's networks do not have, else ``""``.

    >>> beer_hint("ranges.bias")
    ' (dnnevo has no biases or gains: theta = -bias, and a gain folds into theta and the weights; docs/network-format.md, dnnevo.beer.from_beer)'
    """
    if name.rpartition(".")[2].lower() not in ("bias", "biases", "gain", "gains"):
        return ""
    return (" (dnnevo has no biases or gains: theta = -bias, and a gain folds into theta and the "
            "weights; docs/network-format.md, dnnevo.beer.from_beer)")


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """The hint an "unknown name" message carries: `` (did you mean 'x'?)`` naming the closest
    of ``known`` (up to three when they are about as close), or ``""`` when none is close.

    >>> did_you_mean("sequence-1bti", ["landmark", "sequence-1bit", "sequence-3bit"])
    " (did you mean 'sequence-1bit'?)"
    >>> did_you_mean("maze", ["landmark", "sequence"])
    ''
    """
    matches = difflib.get_close_matches(name, list(known), n=3, cutoff=0.75)
    if not matches:
        return ""
    best = difflib.SequenceMatcher(None, name, matches[0]).ratio()
    close = [repr(k) for k in matches if difflib.SequenceMatcher(None, name, k).ratio() >= best - 0.03]
    either = close[0] if len(close) == 1 else f"{', '.join(close[:-1])} or {close[-1]}"
    return f" (did you mean {either}?)"
