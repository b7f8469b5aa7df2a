"""The modules of a Rust crate and the paths between them: which top-level module (a file or a
folder under ``src/``) names which through ``crate::``, and the loops among them.
``docs/architecture.md`` says what it holds the crates to.

    python tests/rust_structure.py crates/ctrnn

A path reaches a module by name (``crate::math::exp``), through an item the crate's root
re-exports (``crate::Network``, which ``lib.rs`` takes from ``network``), or up through
``super::`` to the root and down again. Comments are left out, doc comments too: a link in the
docs is no dependency. Paths that a macro writes are not seen.
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


def _group_after(text: str, start: int) -> str:
    """The text of the ``{...}`` group that opens just before ``start``, without its braces."""
    depth, end = 1, start
    while depth and end < len(text):
        depth += {"{": 1, "}": -1}.get(text[end], 0)
        end += 1
    return text[start:end - 1]


def _reexports(src: Path) -> dict[str, str]:
    """The items the crate's root re-exports (``pub use network::{compose, Network};``), each
    mapped to the top-level module it comes from."""
    root = next((src / name for name in ("lib.rs", "main.rs") if (src / name).is_file()), None)
    if root is None:
        return {}
    text = _COMMENT.sub("", root.read_text(encoding="utf-8"))
    out = {}
    for m in re.finditer(r"\bpub(?:\([^)]*\))?\s+use\s+(?:crate::)?(\w+)::(\{|[\w:]+)", text):
        group = _group_after(text, m.end()) if m.group(2) == "{" else m.group(2)
        # The names a use brings in: each last segment (at any depth of braces), or its alias.
        for name, alias in re.findall(r"(\w+)\s*(?:as\s+(\w+))?\s*(?=[,}]|$)", group):
            if (alias or name) != "self":
                out[alias or name] = m.group(1)
    return out


def arrows(crate: Path) -> set[tuple[str, str]]:
    """``(a, b)`` for each top-level module ``a`` of the crate in the folder ``crate`` whose code
    names a path under the top-level module ``b``."""
    src = crate / "src"
    modules = {p.stem if p.is_file() else p.name for p in src.iterdir()
               if (p.suffix == ".rs" and p.stem not in ("lib", "main")) or p.is_dir()}
    reexports = _reexports(src)

    def module(name: str) -> str | None:
        found = name if name in modules else reexports.get(name)
        return found if found in modules else None  # another crate's item is no arrow here

    found = set()
    for path in sorted(src.rglob("*.rs")):
        parts = path.relative_to(src).with_suffix("").parts
        here = parts[0]
        depth = len(parts) - (parts[-1] == "mod")  # how many super:: reach the root
        text = _COMMENT.sub("", path.read_text(encoding="utf-8"))
        targets: set[str | None] = set()
        for m in _PATH.finditer(text):
            named = {m.group(1)} if m.group(1) != "{" else _first_segments(_group_after(text, m.end()))
            targets |= {module(t) for t in named}
        if depth:
            for m in re.finditer(r"\b((?:super::)+)(\w+)", text):
                if m.group(1).count("super::") == depth:
                    targets.add(module(m.group(2)))
        found |= {(here, t) for t in targets if t is not None and t != here}
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
