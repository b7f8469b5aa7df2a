"""An example's record names the code that made it: the extension's commit and, from an editable
checkout at another commit, the Python code's."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from dnnevo.experiments import examples


def git(repo: Path, *args: str) -> str:
    return subprocess.run(["git", "-C", str(repo), *args], check=True, capture_output=True, text=True).stdout.strip()


def test_the_source_commit_is_the_checkout_s_and_says_when_it_is_dirty(tmp_path: Path) -> None:
    git(tmp_path, "init", "-q")
    code = tmp_path / "code.py"
    code.write_text("x = 1\n")
    git(tmp_path, "add", "code.py")
    git(tmp_path, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "one")
    head = git(tmp_path, "rev-parse", "--short=12", "HEAD")
    assert examples.source_commit(code) == head
    # A new module not yet added to the checkout makes it dirty, as a changed one does.
    (tmp_path / "new_module.py").write_text("y = 1\n")
    assert examples.source_commit(code) == f"{head}-dirty"
    (tmp_path / "new_module.py").unlink()
    assert examples.source_commit(code) == head
    code.write_text("x = 2\n")
    assert examples.source_commit(code) == f"{head}-dirty"
    # A file the checkout does not track (an installed wheel's copy) names no commit.
    (tmp_path / "site-packages").mkdir()
    copy = tmp_path / "site-packages" / "code.py"
    copy.write_text("x = 1\n")
    assert examples.source_commit(copy) is None
    assert examples.source_commit(Path("/") / "code.py") is None


@pytest.mark.parametrize("python_commit", [None, "fedcba987654"])
def test_a_record_names_the_python_code_s_commit_when_it_differs(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, python_commit: str | None) -> None:
    monkeypatch.setattr(examples, "source_commit", lambda module: python_commit)
    path = tmp_path / "demo.json"
    examples.write(path, command="python examples/demo.py", columns=["a"], rows=[["1"]], summary=["s"])
    doc = examples.read(path)
    text = examples.markdown(doc)
    assert doc["made"].get("python_commit") == python_commit
    assert (f"its Python code at commit {python_commit}" in text) == (python_commit is not None)
