"""What a command writes besides its answer: files beside a run (a figure, an analysis), which a
folder that cannot take them (read-only, full) does not stop the answer for, and the answer itself
when its reader (``| head``) stops reading."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable

from dnnevo.errors import WriteError

__all__ = ["reader_gone", "try_write"]


def try_write(write: Callable[[], None]) -> bool:
    """Runs ``write()``; a :class:`~dnnevo.errors.WriteError` is printed as a one-line note on
    stderr instead of raised, and False returned."""
    try:
        write()
    except WriteError as e:
        sys.stderr.write(f"dnnevo: note: {e}\n")
        return False
    return True


def reader_gone() -> None:
    """Sends the rest of stdout nowhere, after a :class:`BrokenPipeError`: the reader (``| head``)
    stopped reading, which is not an error of ours, and Python must not complain at exit."""
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
