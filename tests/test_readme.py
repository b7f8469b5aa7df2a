"""The README is the front door: short, without dates, and its examples run as written.

Its ``dnnevo`` commands are parsed by tests/test_docs.py, with those of the docs pages.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest

from test_docs import run_python_blocks

README = Path(__file__).resolve().parent.parent / "README.md"


def test_python_example_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                             capsys: pytest.CaptureFixture[str]) -> None:
    """Every Python block runs from a folder that has the repository's ``tests/data``, and what a
    block prints is quoted in the README right after it (wrapped lines joined)."""
    assert run_python_blocks(README, tmp_path, monkeypatch, capsys), "the README has a Python example"
    assert (tmp_path / "net.json").is_file()
    assert sorted(os.listdir(tmp_path / "runs" / "py")) == [
        ".dnnevo.lock", "best.json", "checkpoint.json", "config.toml", "log.csv"]


def test_the_light_task_is_as_easy_as_the_readme_says(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """The count of generation-0 networks that already reach the light in 200 fresh episodes is
    computed here from the README's own class and config, not typed."""
    from test_docs import blocks

    from dnnevo import GeneticAlgorithm
    from dnnevo.closedloop import rollout

    text = README.read_text(encoding="utf-8")
    claim = re.search(r"The task is easy: (\d+) of the 200 random networks that `evolve` starts from",
                      " ".join(text.split()))
    assert claim, "the README's claim about the light task moved"
    code = next(code for _, code in blocks(README, ("python",)) if "class Light" in code)
    namespace: dict[str, object] = {"__name__": "readme_example"}
    monkeypatch.chdir(tmp_path)
    exec(code.split("result = ")[0], namespace)  # the imports, the class and the config
    networks = GeneticAlgorithm(namespace["config"], seed=0).ask().networks
    fresh = rollout(networks, namespace["Light"](), episodes=200, max_steps=300, purpose="evaluate")
    lengths = np.asarray(fresh.lengths).reshape(len(networks), 200)
    assert int((lengths < 300).all(axis=1).sum()) == int(claim.group(1))


def test_readme_is_short_and_undated() -> None:
    """At most 250 lines, no dates: what changed goes to CHANGELOG.md, results to docs/."""
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 250
    assert not re.findall(r"20\d\d-[01]\d-[0-3]\d", text)


def test_quick_start_commands() -> None:
    """The two set-up commands, verbatim, and the results table's markers in their section."""
    text = README.read_text(encoding="utf-8")
    assert "pip install . && dnnevo run sequence-1bit\n" in text
    assert 'pip install ".[test]" && python -m pytest && cargo test\n' in text
    results = text[text.index("\n## Results\n"):]
    begin, end = "<!-- results-table:begin -->", "<!-- results-table:end -->"
    assert results.index(begin) < results.index(end)
