"""The modules of a Rust crate and the paths between them: which top-level module (a file or a
folder under ``src/``) names which through ``crate::``, and the loops among them.
``docs/architecture.md`` says what it holds the crates to.

    python tests/rust_structure.py crates/ctrnn

A module's own submodules (``super::``) stay inside it. Comments are left out, doc comments too:
a link in the docs is no dependency.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

_PATH = re.compile(r"\bcrate::(\w+|\{)")
_COMMENT = re.compile(r"//.*")


def _first_segments(group: str) -> set[str]:
    """The first segment of each item of a ``crate::{...}`` group (its text without the braces)."""
    items, depth, item = [], 0, ""
    for ch in group:
        depth += {"{": 1, "}": -1}.get(ch, 0)
        if ch == "," and depth == 0:
            items.append(item)
            item = ""
        else:
            item += ch
    items.append(item)
    return {m.group(0) for m in (re.match(r"\w+", i.strip()) for i in items) if m}


def arrows(crate: Path) -> set[tuple[str, str]]:
    """``(a, b)`` for each top-level module ``a`` of the crate in the folder ``crate`` whose code
    names a path under the top-level module ``b``."""
    src = crate / "src"
    found = set()
    for path in sorted(src.rglob("*.rs")):
        here = path.relative_to(src).with_suffix("").parts[0]
        text = _COMMENT.sub("", path.read_text(encoding="utf-8"))
        for m in _PATH.finditer(text):
            if m.group(1) != "{":
                targets = {m.group(1)}
            else:
                depth, end = 1, m.end()
                while depth and end < len(text):
                    depth += {"{": 1, "}": -1}.get(text[end], 0)
                    end += 1
                targets = _first_segments(text[m.end():end - 1])
            found |= {(here, t) for t in targets if t not in (here, "self")}
    return found


def loops(crate: Path) -> list[list[str]]:
    """Each loop of :func:`arrows` found by a depth-first walk, as the modules it passes through,
    the first repeated at the end."""
    graph: dict[str, list[str]] = {}
    for a, b in sorted(arrows(crate)):
        graph.setdefault(a, []).append(b)
    state: dict[str, int] = {}
    found: list[list[str]] = []

    def walk(m: str, stack: list[str]) -> None:
        state[m] = 1
        stack.append(m)
        for n in graph.get(m, []):
            if state.get(n) == 1:
                found.append(stack[stack.index(n):] + [n])
            elif n not in state:
                walk(n, stack)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            walk(m, [])
    return found


def main(argv: list[str]) -> int:
    """Prints the module loops of each crate named in ``argv``; exit status 1 if there is one."""
    status = 0
    for crate in map(Path, argv):
        found = loops(crate)
        print(f"{crate}: {len(arrows(crate))} module arrows, {len(found)} loops")
        for loop in found:
            print("  loop:", " -> ".join(loop))
            status = 1
    return status


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
