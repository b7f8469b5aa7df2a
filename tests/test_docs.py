"""The docs site builds strictly, and every code block of the README and of docs/*.md is tested.

What is tested, per block (a fenced block's language is the word after its opening fence):
- ``python``: the block runs, top to bottom, in a fresh namespace, from a temporary folder that
  has a copy of the repository's ``tests/data``. Each line it prints must be quoted in the same
  page (whitespace and line breaks ignored), so a changed result fails the test.
- ``bash`` and ``console``: every ``dnnevo ...`` command is parsed by the command's own argument
  parser (``dnnevo.cli.build_parser()``), never run, so a renamed or removed option fails the
  test. Lines are joined at a trailing backslash, split at ``&&``, ``||``, ``;`` and ``|``, and
  read with shlex (``#`` starts a comment); a ``console`` line's ``$ `` prompt is dropped.
  Shell variables (``$s``) stand for ``0``. Other programs (pip, cargo, bash, git, dask, python,
  mkdocs, ...) are not checked.
- Any other language (``text``, ``toml``, ``json``, ...) is not run.

The exception, to keep rare: a block that only illustrates and cannot run is preceded, on the
line just before its opening fence, by the HTML comment ``<!-- docs-test: skip -->`` (invisible
on the rendered page). Say in the page why it cannot run.
"""

from __future__ import annotations

import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
SKIP = "<!-- docs-test: skip -->"
FENCE = re.compile(r"^```([A-Za-z0-9_-]*)[^\n]*\n(.*?)^```[ \t]*$", re.S | re.M)


def blocks(page: Path, languages: tuple[str, ...]) -> list[tuple[int, str]]:
    """The (line number, code) of every fenced block of ``page`` in one of ``languages``, except
    those marked to be skipped."""
    text = page.read_text(encoding="utf-8")
    found = []
    for match in FENCE.finditer(text):
        if match.group(1) not in languages:
            continue
        before = text[: match.start()].rstrip("\n").rsplit("\n", 1)[-1].strip()
        if before == SKIP:
            continue
        found.append((text.count("\n", 0, match.start()) + 1, match.group(2)))
    return found


def run_python_blocks(page: Path, folder: Path, monkeypatch: pytest.MonkeyPatch,
                      capsys: pytest.CaptureFixture[str]) -> int:
    """Runs every Python block of ``page`` from ``folder`` and checks that what each prints is
    quoted in the page; returns how many blocks ran."""
    text = page.read_text(encoding="utf-8")
    flat = " ".join(text.split())
    shutil.copytree(ROOT / "tests" / "data", folder / "tests" / "data")
    monkeypatch.chdir(folder)
    code_blocks = blocks(page, ("python",))
    for line, code in code_blocks:
        capsys.readouterr()
        exec(compile(code, f"{page}:{line}", "exec"), {"__name__": "docs_example"})
        printed = capsys.readouterr().out.strip()
        for out in filter(None, printed.splitlines()):
            assert " ".join(out.split()) in flat, (
                f"{page.name}:{line}: the page does not quote what its example prints: {out}")
    return len(code_blocks)


@pytest.mark.parametrize("page", [p for p in PAGES if p.name != "README.md"], ids=lambda p: p.name)
def test_python_blocks_run(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                           capsys: pytest.CaptureFixture[str]) -> None:
    """Every Python block of a docs page runs and prints what the page says (the README's are
    run by tests/test_readme.py)."""
    run_python_blocks(page, tmp_path, monkeypatch, capsys)


def commands(code: str, console: bool) -> list[list[str]]:
    """The argument lists of the ``dnnevo`` commands in a shell block."""
    code = re.sub(r"\\\n", " ", code)
    found = []
    for line in code.splitlines():
        line = line.strip()
        if console:
            if not line.startswith("$ "):
                continue  # output, not a command
            line = line[2:]
        line = re.sub(r"\$\{?[A-Za-z_][A-Za-z0-9_]*\}?", "0", line)
        try:
            words = shlex.split(line, comments=True)
        except ValueError as error:
            raise AssertionError(f"cannot split shell line {line!r}: {error}") from None
        command: list[str] = []
        for word in [*words, ";"]:
            if word in ("&&", "||", ";", "|", "&") or word.endswith(";"):
                if word.endswith(";") and word != ";":
                    command.append(word[:-1])
                while command and command[0] in ("do", "then", "else", "time"):
                    command.pop(0)
                if command and command[0] == "dnnevo":
                    found.append(command[1:])
                command = []
            else:
                command.append(word)
    return found


def all_commands(page: Path) -> list[tuple[int, list[str]]]:
    found = []
    for language in ("bash", "console", "sh", "shell"):
        for line, code in blocks(page, (language,)):
            found += [(line, args) for args in commands(code, console=language == "console")]
    return found


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_dnnevo_commands_parse(page: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Every ``dnnevo`` command in a shell block is accepted by the real argument parser."""
    from dnnevo.cli import build_parser

    for line, args in all_commands(page):
        try:
            build_parser().parse_args(args)
        except SystemExit as exit_:
            error = capsys.readouterr().err.strip().splitlines()
            assert exit_.code == 0, (
                f"{page.name}, block at line {line}: `dnnevo {shlex.join(args)}` is refused: "
                f"{error[-1] if error else exit_.code}")


def test_the_parser_check_catches_a_bad_option() -> None:
    """The check above would see a removed option: the parser refuses one that never existed."""
    from dnnevo.cli import build_parser

    [args] = commands("dnnevo run sequence-1bit --no-such-option  # comment\n", console=False)
    with pytest.raises(SystemExit):
        build_parser().parse_args(args)
    assert commands("for s in 0 1; do dnnevo sweep landmark --seeds $s \\\n  --out r$s; done",
                    console=False) == [["sweep", "landmark", "--seeds", "0", "--out", "r0"]]


def test_mkdocs_build_is_strict_and_clean(tmp_path: Path) -> None:
    """The docs site builds with ``--strict``: a broken link or anchor, a page left out of the
    nav, or an API reference mkdocstrings cannot resolve fails the build."""
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
    log = done.stdout + done.stderr
    assert "No module named mkdocs" not in log, "install the docs tools: pip install '.[test]'"
    assert done.returncode == 0, log
    assert "WARNING" not in log, log
    assert (tmp_path / "site" / "api" / "index.html").is_file()
