"""What a task written in Python is made of, as text for its digest (``fitness_sha256``).

A run records the SHA-256 of its task's text so that ``resume``, ``assess``, ``plot`` and
``analyze`` refuse a task edited since. The text of a function or class is its own source and
what it reads from its module:

- the source of the functions and classes defined there that its code names as globals (and
  what those name, in turn), a class's base classes from its module among them;
- the values of the module's data that its code names as globals (numbers, strings, arrays,
  containers, dataclasses; see :func:`fingerprint`);
- the values of its default arguments, and of a class's data attributes (``horizon = STEPS``).

Decorated functions are read through their ``__wrapped__``, properties through their getter,
setter and deleter. So an edited constant at the top of the task's file is an edited task. What
the task reads from other modules, files or objects' hidden state is not covered.

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
import dataclasses
import dis
import functools
import hashlib
import inspect
import sys
import textwrap
import types
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

__all__ = ["fingerprint", "legacy_fingerprint", "plain_source", "task_source"]

#: Class attributes left out of a class's text (see the module docs).
IGNORED_ATTRIBUTES = ("analysis",)


def fingerprint(value: Any, _walking: frozenset[int] = frozenset()) -> str:
    """An exact text of ``value`` for the digest: numbers by ``repr`` (exact for floats), arrays
    by dtype, shape and a hash of their bytes, containers and dataclasses item by item (a
    container that holds itself by a marker), and any other object by its type alone (an
    address or a random generator's state would change from run to run)."""
    if value is None or isinstance(value, bool | int | float | complex | str | bytes):
        return repr(value)
    if isinstance(value, np.generic):
        return f"{value.dtype}:{value.item()!r}"
    if isinstance(value, np.ndarray):
        data = np.ascontiguousarray(value)
        if data.dtype.hasobject:
            return f"ndarray[{data.dtype}, {data.shape}]"
        return f"ndarray[{data.dtype}, {data.shape}, {hashlib.sha256(data.tobytes()).hexdigest()}]"
    if id(value) in _walking:
        return "<itself>"
    inner = _walking | {id(value)}
    if isinstance(value, list | tuple):
        return f"{type(value).__name__}[{', '.join(fingerprint(v, inner) for v in value)}]"
    if isinstance(value, set | frozenset):
        return f"{type(value).__name__}{{{', '.join(sorted(fingerprint(v, inner) for v in value))}}}"
    if isinstance(value, Mapping):
        items = sorted((fingerprint(k, inner), fingerprint(v, inner)) for k, v in value.items())
        return "{" + ", ".join(f"{k}: {v}" for k, v in items) + "}"
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = ", ".join(f"{f.name}={fingerprint(getattr(value, f.name), inner)}"
                           for f in dataclasses.fields(value))
        return f"{type(value).__qualname__}({fields})"
    return f"<{type(value).__module__}.{type(value).__qualname__}>"


def legacy_fingerprint(value: Any) -> str:
    """:func:`fingerprint` as digests were made before it read dataclasses and the keys of
    mappings item by item, so that runs recorded then are still recognised."""
    if value is None or isinstance(value, bool | int | float | complex | str | bytes | np.generic | np.ndarray):
        return fingerprint(value)
    if isinstance(value, list | tuple):
        return f"{type(value).__name__}[{', '.join(legacy_fingerprint(v) for v in value)}]"
    if isinstance(value, Mapping):
        items = sorted((repr(k), legacy_fingerprint(v)) for k, v in value.items())
        return "{" + ", ".join(f"{k}: {v}" for k, v in items) + "}"
    return f"<{type(value).__module__}.{type(value).__qualname__}>"


def plain_source(target: Any, *, ignored: bool = False) -> str | None:
    """The source of a function or class alone (with ``ignored``, a class's without its
    :data:`IGNORED_ATTRIBUTES`), as digests were made before they took in what the task reads
    from its module; None when Python cannot find it (typed at a prompt)."""
    try:
        source = inspect.getsource(target)
    except (OSError, TypeError):
        return None
    return _without_ignored(source) if ignored and inspect.isclass(target) else source


def task_source(target: Any) -> str | None:
    """The text of a function or class for its digest (see the module docs); None when Python
    cannot find its source."""
    target = inspect.unwrap(target) if callable(target) and not inspect.isclass(target) else target
    own = plain_source(target, ignored=True)
    if own is None:
        return None
    parts = [own, *(f"# {label}\n{text}" for label, text in _own_values(target))]
    seen = {id(target)}
    for name, value in _dependencies(target, seen):
        text = (plain_source(value, ignored=True) if _defined_alongside(value, target)
                else fingerprint(value))
        parts.append(f"# {name}\n{text}")
        parts.extend(f"# {name}: {label}\n{extra}" for label, extra in _own_values(value)
                     if _defined_alongside(value, target))
    return "\n".join(parts)


def _own_values(target: Any) -> Iterator[tuple[str, str]]:
    """The values a function or class holds besides its code: default arguments, and a class's
    data attributes (not its methods, nor :data:`IGNORED_ATTRIBUTES`)."""
    for function in _functions(target):
        if function.__defaults__:
            yield f"{function.__qualname__} defaults", fingerprint(function.__defaults__)
        if function.__kwdefaults__:
            yield f"{function.__qualname__} keyword defaults", fingerprint(function.__kwdefaults__)
    if inspect.isclass(target):
        for name, value in sorted(vars(target).items()):
            if name.startswith("__") or name in IGNORED_ATTRIBUTES or _function_of(value) is not None \
                    or isinstance(value, property | staticmethod | classmethod | functools.cached_property):
                continue
            yield f"{target.__qualname__}.{name}", fingerprint(value)


def _dependencies(target: Any, seen: set[int]) -> Iterator[tuple[str, Any]]:
    """The module-level names that ``target``'s code reads as globals, with their values, depth
    first and each once: data, and functions and classes of ``target``'s own module (whose own
    names follow them); for a class, first its base classes of that module. Modules, builtins and
    code from other modules are left out."""
    namespace = _module_namespace(target)
    if inspect.isclass(target):  # what a subclass inherits from its module is its too
        for base in target.__mro__[1:]:
            if _defined_alongside(base, target) and id(base) not in seen:
                seen.add(id(base))
                yield base.__qualname__, base
                yield from _dependencies(base, seen)
    for name in sorted(_globals_read(target)):
        if name not in namespace:
            continue
        value = namespace[name]
        unwrapped = _function_of(value) or value
        if id(value) in seen or isinstance(value, types.ModuleType):
            continue
        if inspect.isfunction(unwrapped) or inspect.isclass(unwrapped):
            if not _defined_alongside(unwrapped, target):
                continue
            seen.add(id(value))
            yield name, unwrapped
            yield from _dependencies(unwrapped, seen)
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


def _function_of(value: Any) -> types.FunctionType | None:
    """The plain function behind ``value`` (a function, a method, a decorated function, a
    static or class method, a cached property), or None."""
    value = getattr(value, "__func__", value)  # staticmethod, classmethod, bound method
    value = getattr(value, "func", value) if isinstance(value, functools.cached_property) else value
    if callable(value) and hasattr(value, "__wrapped__"):
        value = inspect.unwrap(value)
    return value if inspect.isfunction(value) else None


def _functions(target: Any) -> list[types.FunctionType]:
    """The functions whose code is ``target``'s: itself, or a class's methods and its
    properties' getters, setters and deleters."""
    if not inspect.isclass(target):
        function = _function_of(target)
        return [function] if function is not None else []
    found: list[types.FunctionType] = []
    for attribute in vars(target).values():
        parts = [attribute.fget, attribute.fset, attribute.fdel] if isinstance(attribute, property) \
            else [attribute]
        found.extend(f for f in map(_function_of, parts) if f is not None)
    return found


def _globals_read(target: Any) -> set[str]:
    """Every name that the code of a function, or of a class's functions, loads as a global
    (nested functions and comprehensions included); attribute names are not globals."""
    codes = [f.__code__ for f in _functions(target)]
    names: set[str] = set()
    while codes:
        code = codes.pop()
        names.update(str(i.argval) for i in dis.get_instructions(code)
                     if i.opname in ("LOAD_GLOBAL", "LOAD_NAME"))
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
