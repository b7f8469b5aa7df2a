"""The shell blocks of the docs that a reader would run first are run, and what they print is
compared with what the page quotes.

tests/test_docs.py parses every ``dnnevo`` command of every shell block. The blocks marked here
are also *run*, as a reader would type them:

- A ``bash`` block preceded, on the line just before its opening fence, by the HTML comment
  ``<!-- docs-test: run -->`` runs line by line (a trailing backslash joins lines) in ``bash``,
  from one temporary folder per page (holding a copy of ``tests/data``), in page order, so a
  block may read what an earlier block of its page wrote. ``dnnevo`` is the installed command.
  A line must exit with status 0; ``dnnevo assess`` may also give its verdicts' statuses, 1
  (fail) and 3 (undecided), unless its comment quotes `pass`. Each line runs under ``set -e``.
  A slow command does not belong in such a block: CI runs them all (the slowest marked block,
  docs/dynamics.md's landmark run, takes about half a minute on 2 cores).
- In a run block, a command's comment may quote what it prints in code spans: every span (its
  whitespace normalised) must be in the command's output.
- A ``text`` block preceded by ``<!-- docs-test: output -->`` quotes what the last command of the
  page's previous run block printed: each of its lines must be a line of that output, except
  that durations (``0.4 s``) stand for any duration.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from test_docs import FENCE, PAGES, ROOT

RUN = "<!-- docs-test: run -->"
OUTPUT = "<!-- docs-test: output -->"
VERDICT_STATUSES = (0, 1, 3)  # dnnevo assess: pass, fail, undecided (2 is an error)
DURATION = re.compile(r"\d+(?:\.\d+)? s\b")


def marked(page: Path) -> list[tuple[int, str, str]]:
    """The (line number, marker, code) of the page's run and output blocks, in page order. A
    marker that is not on the line just before a fence fails: it would silently run nothing."""
    text = page.read_text(encoding="utf-8")
    markers = sum(line.strip() in (RUN, OUTPUT) for line in text.splitlines())
    found = []
    for match in FENCE.finditer(text):
        before = text[: match.start()].rstrip("\n").rsplit("\n", 1)[-1].strip()
        line = text.count("\n", 0, match.start()) + 1
        if before == RUN:
            assert match.group(1) == "bash", f"{page.name}:{line}: only bash blocks run"
        elif before == OUTPUT:
            assert match.group(1) == "text", f"{page.name}:{line}: an output block is text"
        else:
            continue
        found.append((line, before, match.group(2)))
    assert len(found) == markers, f"{page.name}: a docs-test marker is not just before a fence"
    return found


def split_comment(line: str) -> tuple[str, str]:
    """A shell line's command and its trailing comment (a ``#`` outside quotes, at a word's
    start)."""
    quote = ""
    for i, char in enumerate(line):
        if quote:
            quote = "" if char == quote else quote
        elif char in "'\"":
            quote = char
        elif char == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].strip(), line[i + 1:].strip()
    return line.strip(), ""


def shell_lines(code: str) -> list[tuple[str, str]]:
    """The (command, comment) of each line of a block, continuation lines joined."""
    joined = re.sub(r"\\\n", " ", code)
    return [split_comment(line) for line in joined.splitlines() if split_comment(line)[0]]


def flat(text: str) -> str:
    return " ".join(text.split())


def run_line(command: str, folder: Path) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ, MPLBACKEND="Agg", COLUMNS="100")
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    return subprocess.run(["bash", "-c", f"set -e -o pipefail; {command}"], cwd=folder, env=env,
                          capture_output=True, text=True, timeout=300, check=False)


def missing_quotes(comment: str, output: str) -> list[str]:
    """The code spans of a command's comment that its output does not hold."""
    return [span for span in re.findall(r"`([^`]+)`", comment) if flat(span) not in flat(output)]


def missing_lines(quoted: str, output: str) -> list[str]:
    """The lines of an output block that are not lines of ``output`` (durations aside)."""
    printed = {DURATION.sub("D s", flat(line)) for line in output.splitlines()}
    return [q for q in filter(None, (flat(line) for line in quoted.splitlines()))
            if DURATION.sub("D s", q) not in printed]


PAGES_THAT_RUN = [p for p in PAGES if marked(p)]


@pytest.mark.parametrize("page", PAGES_THAT_RUN, ids=lambda p: p.name)
@pytest.mark.slow
def test_marked_shell_blocks_run_and_print_what_the_page_quotes(page: Path,
                                                                tmp_path: Path) -> None:
    shutil.copytree(ROOT / "tests" / "data", tmp_path / "tests" / "data")
    last_output = None
    for line, marker, code in marked(page):
        where = f"{page.name}, block at line {line}"
        if marker == OUTPUT:
            assert last_output is not None, f"{where}: an output block with no run block before it"
            missing = missing_lines(code, last_output)
            assert not missing, (
                f"{where}: the command does not print {missing}; it printed:\n{last_output}")
            continue
        for command, comment in shell_lines(code):
            done = run_line(command, tmp_path)
            output = done.stdout + done.stderr
            # A verdict quoted as `pass` must be the exit status too.
            allowed = (VERDICT_STATUSES if command.startswith("dnnevo assess ")
                       and "`pass`" not in comment else (0,))
            assert done.returncode in allowed, (
                f"{where}: `{command}` exited with {done.returncode}:\n{output[-3000:]}")
            assert "Traceback" not in output, f"{where}: `{command}`:\n{output[-3000:]}"
            missing = missing_quotes(comment, output)
            assert not missing, (
                f"{where}: `{command}` does not print {missing}; it printed:\n{output[-3000:]}")
            last_output = done.stdout


def test_the_checks_read_commands_comments_and_quotes() -> None:
    """The parsing the test above relies on: comments, quotes, continuations, durations."""
    assert shell_lines("dnnevo run x \\\n  --out 'a # b'  # prints `c`\n\n# only a comment\n") == [
        ("dnnevo run x    --out 'a # b'", "prints `c`")]
    assert split_comment("echo a#b") == ("echo a#b", "")
    assert DURATION.sub("D s", "8 generations in 0.4 s; run") == "8 generations in D s; run"
    assert DURATION.sub("D s", "1000 x 500") == "1000 x 500"


def test_a_failing_or_misquoting_command_is_caught(tmp_path: Path) -> None:
    """The runner sees a command that fails, and output that differs from the page's quotes."""
    assert run_line("dnnevo run no-such-preset --quick", tmp_path).returncode == 2
    done = run_line("dnnevo run sequence-1bit --quick --out demo", tmp_path)
    assert done.returncode == 0
    assert missing_quotes("`8 generations`, `run folder demo`", done.stdout) == []
    assert missing_quotes("`9 generations`", done.stdout) == ["9 generations"]
    assert missing_lines("8 generations in 12.5 s; run folder demo\n", done.stdout) == []
    assert missing_lines("8 generations in 0.4 s; run folder elsewhere", done.stdout) == [
        "8 generations in 0.4 s; run folder elsewhere"]
