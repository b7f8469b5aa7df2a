"""The results of the example scripts (``examples/*.py``), kept as files so that the docs' tables
are made from them by a command, never typed.

A script run with ``--record docs/results/examples/NAME.json`` writes its table there with the
command that made it (:func:`command`: its own command line without the ``--record``) and the
machine it ran on (:func:`write`); ``python -m
dnnevo.experiments.results render`` then fills every ``<!-- results:example:NAME:begin -->`` ...
``<!-- results:example:NAME:end -->`` pair of the docs from that file (:func:`blocks`), and
``render --check`` fails when a page differs from it.

>>> import tempfile, pathlib
>>> path = pathlib.Path(tempfile.mkdtemp()) / "demo.json"
>>> write(path, command="python examples/demo.py --seeds 2", columns=["seed", "score"],
...       rows=[[0, "0.5"], [1, "0.7"]], summary=["2 seeds"])
>>> print(markdown(read(path)).split("(made by")[0], end="")
`python examples/demo.py --seeds 2`:
<BLANKLINE>
| seed | score |
|---|---|
| 0 | 0.5 |
| 1 | 0.7 |
<BLANKLINE>
2 seeds
<BLANKLINE>
"""

from __future__ import annotations

import concurrent.futures
import json
import multiprocessing
import platform
import shlex
import subprocess
import sys
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, TypeGuard

from dnnevo import _core
from dnnevo.experiments import report
from dnnevo.runs.files import RunFileError, read_json, write_atomic

__all__ = ["EXAMPLES_DIR", "blocks", "command", "markdown", "read", "seeds_run", "source_commit", "write"]

EXAMPLES_DIR = Path("examples")
"""Where, under the results folder (``docs/results``), the examples' results live."""

FORMAT = "dnnevo-example-results/1"


def command(script: str, argv: Sequence[str] | None = None) -> str:
    """The command line that ran ``script`` with ``argv`` (default ``sys.argv[1:]``), without
    its ``--record JSON`` (or ``--record=JSON``, or an abbreviation argparse accepted, such as
    ``--rec``): the command that makes the table, wherever the table was written.

    >>> command("examples/demo.py", ["--seeds", "2", "--record", "x.json", "--out", "a b.png"])
    "python examples/demo.py --seeds 2 --out 'a b.png'"
    >>> command("examples/demo.py", ["--rec=x.json", "--seeds", "2"])
    'python examples/demo.py --seeds 2'
    """
    given = list(sys.argv[1:] if argv is None else argv)
    kept, skip = [], False
    for arg in given:
        if skip:
            skip = False
            continue
        name, eq, _ = arg.partition("=")
        if len(name) > 2 and "--record".startswith(name):
            skip = not eq  # the path is the next argument unless given with "="
            continue
        kept.append(arg)
    return shlex.join(["python", script, *kept])


def seeds_run(one_seed: Callable[..., Any], seeds: int, workers: int, *args: Any) -> Iterator[Any]:
    """``one_seed(seed, *args)`` for seeds 0 .. ``seeds`` - 1, in seed order, as each comes: one
    after another here, or ``workers`` at a time in processes of their own (the same results
    either way; ``one_seed`` must be a module-level function). Spawned, not forked: a fork of a
    process that runs threads (rayon's, a test runner's) can inherit a lock held by one of them
    and hang. On Ctrl-C the seeds not yet started never start."""
    if workers <= 1:
        for seed in range(seeds):
            yield one_seed(seed, *args)
        return
    spawn = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(workers, mp_context=spawn) as pool:
        running = [pool.submit(one_seed, seed, *args) for seed in range(seeds)]
        try:
            for future in running:
                yield future.result()
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            raise


def source_commit(module: Path) -> str | None:
    """The commit of the git checkout that the Python file ``module`` is tracked in (an editable
    install runs the checkout's Python code), with ``-dirty`` when the checkout has uncommitted
    changes or files it does not track (and does not ignore); None when the file is tracked by none (an installed wheel) or git is missing."""

    def git(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(["git", "-C", str(module.parent), *args], capture_output=True, text=True, timeout=30)

    try:
        if git("ls-files", "--error-unmatch", module.name).returncode != 0:
            return None
        head = git("rev-parse", "--short=12", "HEAD")
        status = git("status", "--porcelain")  # a new module not yet added is a change too
    except (OSError, subprocess.SubprocessError):
        return None
    if head.returncode != 0 or status.returncode != 0:
        return None
    return head.stdout.strip() + ("-dirty" if status.stdout.strip() else "")


def write(path: Path, *, command: str, columns: Sequence[str], rows: Sequence[Sequence[Any]],
          summary: Sequence[str]) -> None:
    """Writes an example's table (``rows`` of cells, shown as ``str`` of each), the lines that
    sum it up, the ``command`` that made it and the dnnevo that ran it, atomically. The commit
    is the extension's (:func:`dnnevo.build_info`); when the Python code comes from a checkout at
    another commit (an editable install), that one is recorded too, as ``python_commit``."""
    info = _core.build_info()
    made = {"commit": info["commit"], "version": info["version"], "kernel": info["kernel"],
            "arch": platform.machine()}
    python = source_commit(Path(__file__))
    if python is not None and python != info["commit"]:
        made["python_commit"] = python
    doc = {"format": FORMAT, "command": command, "columns": [str(c) for c in columns],
           "rows": [[str(c) for c in row] for row in rows], "summary": [str(s) for s in summary],
           "made": made}
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(path, json.dumps(doc, indent=1) + "\n")


def read(path: Path) -> dict[str, Any]:
    """An example's results, checked: a :class:`~dnnevo.runs.RunFileError` names what is wrong."""
    if not path.exists() and not path.is_symlink():
        raise RunFileError(f"{path} does not exist; make it with the example's --record")
    doc = read_json(path)
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise RunFileError(f"{path}: not an example's results (format is not {FORMAT})")
    columns, rows = doc.get("columns"), doc.get("rows")
    made = doc.get("made", {})
    ok = (isinstance(doc.get("command"), str) and _strings(columns) and _strings(doc.get("summary"))
          and isinstance(rows, list) and all(_strings(r) and len(r) == len(columns) for r in rows)
          and isinstance(made, dict) and _strings(list(made.values())))
    if not ok:
        raise RunFileError(f"{path}: an example's results need a command, columns, rows of as many "
                           "cells, summary lines and what made them, all text")
    return doc


def _strings(value: Any) -> TypeGuard[list[str]]:
    return isinstance(value, list) and all(isinstance(v, str) for v in value)


def blocks(doc: dict[str, Any]) -> list[report.Block]:
    """The command, the table, the summary lines and the dnnevo that made them."""
    table = report.Block("table", rows=(tuple(doc["columns"]), *(tuple(r) for r in doc["rows"])))
    made = doc.get("made") or {}
    python = f", its Python code at commit {made['python_commit']}" if "python_commit" in made else ""
    source = (f"(made by dnnevo {made.get('version')} at commit {made.get('commit')}{python}, "
              f"{made.get('kernel')} kernel)") if made else ""
    return [report.Block("p", f"`{doc['command']}`:"), table,
            *(report.Block("p", line) for line in doc["summary"]), *([report.Block("p", source)] if source else [])]


def markdown(doc: dict[str, Any]) -> str:
    """:func:`blocks` as Markdown."""
    return report.markdown(blocks(doc))
