"""Files a reading command writes beside a run (a figure, an analysis): when the folder cannot
take them (read-only, full), the command still gives its answer and says what it did not write."""

from __future__ import annotations

import sys
from collections.abc import Callable

from dnnevo.errors import WriteError

__all__ = ["try_write"]


def try_write(write: Callable[[], None]) -> bool:
    """Runs ``write()``; a :class:`~dnnevo.errors.WriteError` is printed as a one-line note on
    stderr instead of raised, and False returned."""
    try:
        write()
    except WriteError as e:
        sys.stderr.write(f"dnnevo: note: {e}\n")
        return False
    return True
