"""Helpers for tests that run the ``dnnevo`` command.

``run_cli`` runs the command in the test's own process, through ``dnnevo.cli.command.main``, the
function the console script and ``python -m dnnevo`` call: a new interpreter costs about 0.4 s of
CPU (NumPy and every command's module), and the suite runs the command a few hundred times, so
that start-up was a minute and more of CI's wall time. What only a process shows (signals, start-up,
the environment such as DNNEVO_SIMD, resource limits) is tested on ``python -m dnnevo`` itself:
tests/test_cli.py runs the commands that way."""

from __future__ import annotations

import contextlib
import io
import subprocess
from collections.abc import Callable
from pathlib import Path

from dnnevo.cli.command import main


def run_cli(*args: object) -> subprocess.CompletedProcess[str]:
    """Runs ``dnnevo ARGS`` in this process and captures its output and exit status, as a
    process would give them."""
    return run_main(main, "dnnevo", *args)


def run_main(entry: Callable[[list[str]], int], name: str, *args: object) -> subprocess.CompletedProcess[str]:
    """Runs a command line's ``main(argv)`` (``name`` is how the result names it) in this
    process, capturing what it writes and its exit status."""
    argv = list(map(str, args))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = entry(argv)
        except SystemExit as e:  # argparse's usage errors and --help, --version
            status = _exit_status(e.code, err)
    return subprocess.CompletedProcess([name, *argv], status, out.getvalue(), err.getvalue())


def _exit_status(code: object, err: io.StringIO) -> int:
    """The exit status Python gives ``SystemExit(code)``: a message goes to stderr and is 1."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    err.write(f"{code}\n")
    return 1


def assert_png(path: Path) -> None:
    """``path`` is a non-trivial PNG file."""
    data = path.read_bytes()
    assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 1000, path


def assert_one_line_error(r: subprocess.CompletedProcess[str], *fragments: str) -> None:
    """The command failed with exit status 2 and one line on stderr holding every fragment."""
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "Traceback" not in r.stderr
    for fragment in fragments:
        assert fragment in r.stderr
