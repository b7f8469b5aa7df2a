"""Ctrl-C while the ``dnnevo`` command starts up: deferred until the command runs, then one line.

An interrupt can land anywhere in the seconds the command spends importing NumPy, matplotlib and
the core, and Python does not always deliver it as a ``KeyboardInterrupt``: a C extension that is
being imported may turn it into an ``ImportError``, and Python 3.11 wraps one raised while a class
is created in a ``RuntimeError``. So when this process is the command (the console script or
``python -m dnnevo``), SIGINT is blocked from the first line of ``dnnevo/__init__.py`` until
``dnnevo.cli.command.main`` starts, which unblocks it inside its own ``KeyboardInterrupt`` handler. A
program that merely imports dnnevo is left alone.
"""

from __future__ import annotations

import os
import signal
import sys
from types import TracebackType

from dnnevo.errors import DnnevoError

_BLOCKABLE = hasattr(signal, "pthread_sigmask")


def is_the_command() -> bool:
    """Whether this process was started as ``dnnevo ...`` or ``python -m dnnevo ...``."""
    argv = getattr(sys, "orig_argv", [])
    if any(a == "-m" and b == "dnnevo" for a, b in zip(argv, argv[1:], strict=False)):
        return True
    script = sys.argv[0] if sys.argv else ""
    if os.path.basename(script) not in ("dnnevo", "dnnevo.exe"):
        return False
    try:  # the console script pip writes imports dnnevo.cli; a user's own "dnnevo" script does not
        with open(script, "rb") as f:
            return b"dnnevo.cli" in f.read(4096)
    except OSError:
        return False


def defer_interrupts() -> None:
    """Blocks SIGINT if this process is the command and the platform allows it."""
    if _BLOCKABLE and is_the_command():
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})


def allow_interrupts() -> None:
    """Unblocks SIGINT; one that arrived while it was blocked is raised now."""
    if _BLOCKABLE:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def interrupted_import(kind: type[BaseException], value: BaseException, tb: TracebackType | None) -> None:
    """The exception hook while dnnevo imports (e.g. the ``dnnevo`` command starting up): Ctrl-C
    is one line. Python may wrap the interrupt in another error (3.11 turns one raised while a
    class is created into a RuntimeError from ``__set_name__``), so the whole chain of causes is
    looked at."""
    sys.excepthook = sys.__excepthook__
    seen: BaseException | None = value
    while seen is not None and not isinstance(seen, KeyboardInterrupt):
        seen = seen.__cause__ or seen.__context__
    if issubclass(kind, KeyboardInterrupt) or seen is not None:
        sys.stderr.write("dnnevo: interrupted\n")
    elif isinstance(value, DnnevoError) and is_the_command():
        sys.stderr.write(f"dnnevo: error: {value}\n")  # e.g. a bad DNNEVO_SIMD
    else:
        sys.__excepthook__(kind, value, tb)


def begin_import() -> None:
    """The first thing ``import dnnevo`` does: Ctrl-C deferred (:func:`defer_interrupts`) and
    reported in one line (:func:`interrupted_import`) until :func:`end_import`."""
    defer_interrupts()
    if sys.excepthook is sys.__excepthook__:
        sys.excepthook = interrupted_import


def end_import() -> None:
    """The last thing ``import dnnevo`` does: the ordinary exception hook again."""
    if sys.excepthook is interrupted_import:
        sys.excepthook = sys.__excepthook__
