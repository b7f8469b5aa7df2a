"""Helpers for tests that run the ``dnnevo`` command in a subprocess."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def run_cli(*args: object) -> subprocess.CompletedProcess[str]:
    """Runs ``python -m dnnevo ARGS`` and captures its output."""
    return subprocess.run([sys.executable, "-m", "dnnevo", *map(str, args)], capture_output=True,
                          text=True, timeout=300)


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
