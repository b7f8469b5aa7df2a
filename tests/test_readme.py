"""The README's Python example runs as written."""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

import pytest

README = Path(__file__).resolve().parent.parent / "README.md"


def test_python_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                             capsys: pytest.CaptureFixture[str]) -> None:
    """Every Python block runs from a folder that has the repository's ``tests/data``, and what a
    block prints is quoted in the README right after it (wrapped lines joined)."""
    text = README.read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks, "the README has a Python example"
    shutil.copytree(README.parent / "tests" / "data", tmp_path / "tests" / "data")
    monkeypatch.chdir(tmp_path)
    flat = " ".join(text.split())
    for code in blocks:
        exec(compile(code, str(README), "exec"), {"__name__": "readme"})
        printed = capsys.readouterr().out.strip()
        for line in filter(None, printed.splitlines()):
            assert " ".join(line.split()) in flat, f"the README does not quote what its example prints: {line}"
    assert (tmp_path / "net.json").is_file()
    assert sorted(os.listdir(tmp_path / "runs" / "py")) == [
        ".dnnevo.lock", "best.json", "checkpoint.json", "config.toml", "log.csv"]
