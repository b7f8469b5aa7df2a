"""The package type-checks: ``python -m mypy python/dnnevo`` (its settings are pyproject.toml's
``[tool.mypy]``) finds no error, so an annotation that lies about what a function takes or
returns fails here, not in a user's checker."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.slow
def test_the_package_type_checks(tmp_path: Path) -> None:
    r = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path / "cache"),
                        str(ROOT / "python" / "dnnevo")], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.startswith("Success: no issues found")
