"""The shape of a Python package from its own imports: files, import arrows between them, the
longest import chain, import loops, deferred (in-function) imports, and places outside
``tasks/`` that compare a task's name. ``docs/architecture.md`` quotes its figures.

    python tests/structure.py python/dnnevo
"""

from __future__ import annotations

import ast
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

TASK_NAME = re.compile(r"""task\s*(==|!=|in)\s*\(?["'](sequence|nav1d|landmark)""")


@dataclass
class Shape:
    """What :func:`measure` finds."""

    files: int = 0
    arrows: set[tuple[str, str]] = field(default_factory=set)
    levels: int = 0
    loops: list[list[str]] = field(default_factory=list)
    deferred: list[str] = field(default_factory=list)
    """``path:line: import`` of each import inside a function (not under TYPE_CHECKING)."""
    task_name_branches: list[str] = field(default_factory=list)


def _modules(root: Path) -> dict[str, Path]:
    mods = {f"{root.name}._core": root / "_core.pyi"}  # the native module, imported by name
    for p in sorted(root.rglob("*.py")):
        name = ".".join(p.relative_to(root.parent).with_suffix("").parts)
        mods[name.removesuffix(".__init__")] = p
    return mods


def measure(root: Path) -> Shape:
    """The shape of the package in the folder ``root``."""
    mods, shape = _modules(root), Shape()
    shape.files = sum(1 for p in mods.values() if p.suffix == ".py")

    def resolve(target: str) -> str | None:
        while target and target not in mods:
            target = target.rpartition(".")[0]
        return target or None

    for name, path in mods.items():
        if path.suffix != ".py":
            continue
        text = path.read_text(encoding="utf-8")

        def visit(node: ast.AST, in_function: bool, type_only: bool) -> None:
            for child in ast.iter_child_nodes(node):
                only = type_only or (isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test))
                inside = in_function or isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef)
                if isinstance(child, ast.Import | ast.ImportFrom) and not type_only:
                    if in_function:
                        shape.deferred.append(f"{path.relative_to(root)}:{child.lineno}: {ast.unparse(child)}")
                    if isinstance(child, ast.Import):
                        targets = [a.name for a in child.names]
                    else:
                        targets = [f"{child.module}.{a.name}" for a in child.names] if child.module else []
                    for t in targets:
                        found = resolve(t) if t.split(".")[0] == root.name else None
                        if found and found != name:
                            shape.arrows.add((name, found))
                visit(child, inside, only)

        visit(ast.parse(text), False, False)
        if ".tasks" not in name:
            shape.task_name_branches += [f"{path.relative_to(root)}: {m.group(0)}" for m in TASK_NAME.finditer(text)]

    graph = {m: sorted(b for a, b in shape.arrows if a == m) for m in mods}
    state: dict[str, int] = {}
    depth: dict[str, int] = {}

    def walk(m: str, stack: list[str]) -> int:
        state[m] = 1
        stack.append(m)
        deepest = 0
        for n in graph[m]:
            if state.get(n) == 1:
                shape.loops.append(stack[stack.index(n):] + [n])
            elif n not in state:
                deepest = max(deepest, walk(n, stack))
            else:
                deepest = max(deepest, depth.get(n, 0))
        stack.pop()
        state[m], depth[m] = 2, deepest + 1
        return depth[m]

    shape.levels = max(walk(m, []) if m not in state else depth[m] for m in mods)
    return shape


def main(argv: list[str]) -> int:
    """Prints the shape of the package in ``argv[0]``."""
    s = measure(Path(argv[0]))
    print(f"files {s.files}, import arrows {len(s.arrows)}, levels {s.levels}, import loops {len(s.loops)}, "
          f"deferred imports {len(s.deferred)}, task-name comparisons outside tasks/ {len(s.task_name_branches)}")
    for line in s.deferred:
        print("  deferred:", line)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
