"""Settings every test module shares.

A process started in the background by a shell (``cmd &``, ``nohup``) inherits SIGINT ignored,
and so does everything it starts: Python then installs no KeyboardInterrupt handler, and the
tests that press Ctrl-C, in this process or in a ``dnnevo`` subprocess, would wait out the whole
run and fail. Python's own handler is put back here; a subprocess then starts with SIGINT at its
default, as from a terminal.

Tests marked ``slow`` (about 8 s or more on 2 cores) are collected first. pytest-xdist runs with
``--dist worksteal`` (pyproject.toml): each worker starts with an equal run of the collected
tests, and an idle worker takes half of a busy one's waiting tests, so the workers end within one
test of each other, and with the slow tests first that last test is a short one. xdist's default
(``load``) gave one worker its whole first batch: with the slow tests first, all of them, and it
ran 140 s after the other had finished; with them last, in file order, CI's pytest ended with a
core idle for 2.5 minutes.
"""

import signal

import pytest

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Puts the tests marked ``slow`` first, each group in its collection order."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)
