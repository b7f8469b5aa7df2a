"""Settings every test module shares.

A process started in the background by a shell (``cmd &``, ``nohup``) inherits SIGINT ignored,
and so does everything it starts: Python then installs no KeyboardInterrupt handler, and the
tests that press Ctrl-C, in this process or in a ``dnnevo`` subprocess, would wait out the whole
run and fail. Python's own handler is put back here; a subprocess then starts with SIGINT at its
default, as from a terminal.

Tests marked ``slow`` (about 8 s or more on 2 cores) are collected first. pytest-xdist hands out
the first tests in turn to its workers, so the long ones start at once and run beside each other;
at the end of the collection order they ran last, each alone, with the other core idle: a minute
of CI's wall time.
"""

import signal

import pytest

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Puts the tests marked ``slow`` first, each group in its collection order."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)
