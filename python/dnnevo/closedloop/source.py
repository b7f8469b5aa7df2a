"""What a task written in Python is made of, as text for its digest (``fitness_sha256``).

A run records the SHA-256 of its task's text so that ``resume``, ``assess``, ``plot`` and
``analyze`` refuse a task edited since. The text of a function or class is its own source and
what it reads from its module: the source of the functions and classes defined there that it
names (and what those name, in turn), and the values of the module's data that it names
(numbers, strings, arrays, containers; see :func:`fingerprint`); a class's base classes from
its module count as named. So an edited constant at the top
of the task's file is an edited task.

A class's ``analysis = ...`` attribute (:class:`dnnevo.tasks.protocol.Analysis`) is left out: it
says how to analyse a champion, not what the task asks, so adding one to a task class keeps the
runs evolved with it.

>>> from dnnevo.closedloop.source import task_source
>>> from dnnevo.closedloop import FarSeeker
>>> text = task_source(FarSeeker)
>>> text.startswith("class FarSeeker")
True
"""

from __future__ import annotations

import ast
import hashlib
import inspect
import sys
import textwrap
import types
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

__all__ = ["fingerprint", "plain_source", "task_source"]

#: Class attributes left out of a class's text (see the module docs).
IGNORED_ATTRIBUTES = ("analysis",)


def fingerprint(value: Any) -> str:
    """An exact text of ``value`` for the digest: numbers by ``repr`` (exact for floats), arrays
    by dtype, shape and a hash of their bytes, containers item by item, and any other object by
    its type alone (an address or a random generator's state would change from run to run)."""
    if value is None or isinstance(value, bool | int | float | complex | str | bytes):
        return repr(value)
    if isinstance(value, np.generic):
        return f"{value.dtype}:{value.item()!r}"
    if isinstance(value, np.ndarray):
        data = np.ascontiguousarray(value)
        if data.dtype.hasobject:
            return f"ndarray[{data.dtype}, {data.shape}]"
        return f"ndarray[{data.dtype}, {data.shape}, {hashlib.sha256(data.tobytes()).hexdigest()}]"
    if isinstance(value, list | tuple):
        return f"{type(value).__name__}[{', '.join(fingerprint(v) for v in value)}]"
    if isinstance(value, set | frozenset):
        return f"{type(value).__name__}{{{', '.join(sorted(fingerprint(v) for v in value))}}}"
    if isinstance(value, Mapping):
        items = sorted((repr(k), fingerprint(v)) for k, v in value.items())
        return "{" + ", ".join(f"{k}: {v}" for k, v in items) + "}"
    return f"<{type(value).__module__}.{type(value).__qualname__}>"


def plain_source(target: Any) -> str | None:
    """The source of a function or class alone, as digests were made before they took in what
    the task reads from its module; None when Python cannot find it (typed at a prompt)."""
    try:
        return inspect.getsource(target)
    except (OSError, TypeError):
        return None


def task_source(target: Any) -> str | None:
    """The text of a function or class for its digest (see the module docs); None when Python
    cannot find its source."""
    own = plain_source(target)
    if own is None:
        return None
    if inspect.isclass(target):
        own = _without_ignored(own)
    parts = [own]
    seen = {id(target)}
    for name, value in _dependencies(target, seen):
        text = plain_source(value) if _defined_alongside(value, target) else fingerprint(value)
        parts.append(f"# {name}\n{text}")
    return "\n".join(parts)


def _dependencies(target: Any, seen: set[int]) -> Iterator[tuple[str, Any]]:
    """The module-level names that ``target``'s code reads, with their values, depth first and
    each once: data, and functions and classes of ``target``'s own module (whose own names
    follow them); for a class, first its base classes of that module. Modules, builtins and code
    from other modules are left out."""
    namespace = _module_namespace(target)
    if inspect.isclass(target):  # what a subclass inherits from its module is its too
        for base in target.__mro__[1:]:
            if _defined_alongside(base, target) and id(base) not in seen:
                seen.add(id(base))
                yield base.__qualname__, base
                yield from _dependencies(base, seen)
    for name in sorted(_names_read(target)):
        if name not in namespace:
            continue
        value = namespace[name]
        if id(value) in seen or isinstance(value, types.ModuleType):
            continue
        if inspect.isfunction(value) or inspect.isclass(value):
            if not _defined_alongside(value, target):
                continue
            seen.add(id(value))
            yield name, value
            yield from _dependencies(value, seen)
        elif not callable(value):
            seen.add(id(value))
            yield name, value


def _module_namespace(target: Any) -> Mapping[str, Any]:
    if inspect.isfunction(target):
        return target.__globals__
    module = sys.modules.get(getattr(target, "__module__", ""), None)
    return vars(module) if module is not None else {}


def _defined_alongside(value: Any, target: Any) -> bool:
    """Whether ``value`` is a function or class defined in ``target``'s module."""
    return (inspect.isfunction(value) or inspect.isclass(value)) and \
        getattr(value, "__module__", None) == getattr(target, "__module__", None)


def _names_read(target: Any) -> set[str]:
    """Every global (and attribute) name in the code of a function, or of a class's functions,
    nested functions and comprehensions included."""
    codes = []
    if inspect.isfunction(target):
        codes.append(target.__code__)
    elif inspect.isclass(target):
        for attribute in vars(target).values():
            function = attribute.fget if isinstance(attribute, property) else \
                getattr(attribute, "__func__", attribute)
            if inspect.isfunction(function):
                codes.append(function.__code__)
    names: set[str] = set()
    while codes:
        code = codes.pop()
        names.update(code.co_names)
        codes.extend(c for c in code.co_consts if isinstance(c, types.CodeType))
    return names


def _without_ignored(source: str) -> str:
    """A class's source without its class-level assignments to :data:`IGNORED_ATTRIBUTES`."""
    dedented = textwrap.dedent(source)
    try:
        tree = ast.parse(dedented)
    except SyntaxError:
        return source
    if not tree.body or not isinstance(tree.body[0], ast.ClassDef):
        return source
    drop: set[int] = set()
    for statement in tree.body[0].body:
        targets = statement.targets if isinstance(statement, ast.Assign) else \
            [statement.target] if isinstance(statement, ast.AnnAssign) else []
        if any(isinstance(t, ast.Name) and t.id in IGNORED_ATTRIBUTES for t in targets):
            drop.update(range(statement.lineno, (statement.end_lineno or statement.lineno) + 1))
    if not drop:
        return source
    lines = source.splitlines(keepends=True)
    return "".join(line for number, line in enumerate(lines, 1) if number not in drop)
