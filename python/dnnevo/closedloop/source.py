"""What a task written in Python is made of, as text for its digest (``fitness_sha256``).

A run records the SHA-256 of its task's text so that ``resume``, ``assess``, ``plot`` and
``analyze`` refuse a task edited since. The text of a function or class is its own source and
what it reads from its module:

- the source of the functions and classes defined there that it names as globals (in its
  code, its default arguments, its decorators or a class body's ``horizon = STEPS``), and of
  what those name in turn, a class's base classes from its module among them;
- for the module's other names that it reads, the source of the module's top-level statements
  that make them (``SPEED = 0.1``, ``TABLE["x"] = 2``): what the data is made of, not what it
  holds at run time, so a cache the task fills or a counter it keeps changes nothing; a name no
  statement makes (``globals()[...] = ...``) by its value (see :func:`fingerprint`).

Decorated functions are read layer by layer, properties through their getter, setter and
deleter. So an edited constant at the top of the task's file is an edited task. What the task
reads from other modules, files or objects' hidden state is not covered.

Each piece of source counts by the code it holds (:func:`normalised`): comments, blank lines,
line continuations, the width of spaces and indentation, docstrings and how a string is
written (``'a'`` or ``"a"``) do not count, so documenting or reformatting a task keeps the runs
evolved with it. Every other token does: a name, an operator, a number as written (``0.10`` is
not ``0.1``), a string's value, and the split into lines and blocks (``if x: y`` on one line or
two, a ``;`` for a new line, a bracket or a trailing comma added). The text is the same on
Python 3.11 to 3.13, so a run evolved on one opens on another.

A class's ``analysis = ...`` attribute (:class:`dnnevo.tasks.protocol.Analysis`) is left out: it
says how to analyse a champion, not what the task asks, so adding one to a task class keeps the
runs evolved with it. So is its ``preset = {...}``, the settings a new run starts from (a run's
own are in its ``config.toml``, whose digest parts cover them), unless the class's own code reads
it (``self.preset``), which makes it part of what the task does.

>>> from dnnevo.closedloop.source import task_source
>>> from dnnevo.closedloop import FarSeeker
>>> text = task_source(FarSeeker)
>>> text.startswith("class FarSeeker")
True
>>> from dnnevo.closedloop.source import normalised
>>> print(normalised("def f(x) :  # a comment\\n\\n  'Adds one.'\\n  return (x +\\n          1)"))
def f ( x ) :
    return ( x + 1 )
"""

from __future__ import annotations

import ast
import dataclasses
import dis
import functools
import hashlib
import inspect
import io
import sys
import textwrap
import tokenize
import types
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["fingerprint", "legacy_fingerprint", "normalised", "plain_source", "task_source"]

#: Class attributes left out of a class's text (see the module docs).
IGNORED_ATTRIBUTES = ("analysis", "preset")

#: Of :data:`IGNORED_ATTRIBUTES`, those kept when the class's own code reads them as attributes.
KEPT_WHEN_READ = ("preset",)


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


def legacy_fingerprint(value: Any, _walking: frozenset[int] = frozenset()) -> str:
    """:func:`fingerprint` as digests were made before it read dataclasses and the keys of
    mappings item by item, so that runs recorded then are still recognised (a container that
    holds itself, which then recursed without end, gets a marker)."""
    if value is None or isinstance(value, bool | int | float | complex | str | bytes | np.generic | np.ndarray):
        return fingerprint(value)
    if id(value) in _walking:
        return "<itself>"
    inner = _walking | {id(value)}
    if isinstance(value, list | tuple):
        return f"{type(value).__name__}[{', '.join(legacy_fingerprint(v, inner) for v in value)}]"
    if isinstance(value, Mapping):
        items = sorted((repr(k), legacy_fingerprint(v, inner)) for k, v in value.items())
        return "{" + ", ".join(f"{k}: {v}" for k, v in items) + "}"
    return f"<{type(value).__module__}.{type(value).__qualname__}>"


#: Tokens that are layout, not code, left out of :func:`normalised`'s text.
_LAYOUT = frozenset({tokenize.COMMENT, tokenize.NL, tokenize.ENCODING, tokenize.ENDMARKER})
#: Python 3.12 on splits an f-string into tokens between these two (3.11 has neither).
_FSTRING_START = getattr(tokenize, "FSTRING_START", None)
_FSTRING_END = getattr(tokenize, "FSTRING_END", None)
#: Tokens that make up a name: 3.11's tokenizer splits one with combining marks (``x\u0301``)
#: into names and error tokens that touch.
_NAME_PIECES = (tokenize.NAME, tokenize.ERRORTOKEN)


def normalised(source: str) -> str:
    r"""``source`` as the code it holds, whatever its layout: a line for each logical line,
    indented four spaces a block, its tokens separated by one space. Comments, blank lines,
    line continuations and the width of spaces and indentation are left out, and so are
    docstrings and any other statement that is a string alone (it does nothing but set a
    ``__doc__``); a string is written by its value (``'a'``, ``"a"`` and ``u"\x61"`` alike),
    every other token as it is written (a number's digits: ``0.10`` is not ``0.1``; an
    f-string whole). So two sources share the text only when Python reads the same code in
    them, docstrings aside, in the same lines and blocks.

    It is made with :mod:`tokenize`, not from the syntax tree, whose text (``ast.dump``,
    ``ast.unparse``) changes from one Python version to another, and it is the same on 3.11 to
    3.13: an f-string, which 3.12 on splits into tokens, is taken whole from the source, as
    3.11 reads it, and a name that 3.11 reads in pieces is joined again. Source that Python
    cannot parse alone (a lambda cut out of its line) is returned as it is.
    """
    with warnings.catch_warnings():  # an invalid escape: said when the module was imported
        warnings.simplefilter("ignore")
        try:
            try:
                ast.parse(source)
            except SyntaxError:  # an indented piece (a nested class) parses in a block
                ast.parse(f"if 1:\n{source}")
            tokens = list(tokenize.generate_tokens(io.StringIO(source).readline))
        except (SyntaxError, tokenize.TokenError, ValueError):
            return source
        lines = io.StringIO(source).readlines()  # as tokenize numbers them
        rendered: list[str] = []
        words: list[str] = []
        strings_only = True  # whether the logical line so far is strings alone
        depth, nested, start = 0, 0, (0, 0)
        previous: tokenize.TokenInfo | None = None
        for token in tokens:
            kind = token.type
            if nested or kind == _FSTRING_START:
                if kind == _FSTRING_START:
                    start = start if nested else token.start
                    nested += 1
                elif kind == _FSTRING_END:
                    nested -= 1
                    if not nested:
                        words.append(_span(lines, start, token.end))
                        strings_only = False
                previous = token
                continue
            if kind == tokenize.INDENT:
                depth += 1
            elif kind == tokenize.DEDENT:
                depth -= 1
            elif kind == tokenize.NEWLINE:
                if words and not strings_only:
                    rendered.append("    " * depth + " ".join(words))
                words, strings_only = [], True
            elif kind in _LAYOUT or (kind == tokenize.ERRORTOKEN and token.string.isspace()):
                continue
            elif kind in _NAME_PIECES and previous is not None and previous.type in _NAME_PIECES \
                    and previous.end == token.start and words:
                words[-1] += token.string
            else:
                value = _string(token.string) if kind == tokenize.STRING else None
                words.append(token.string if value is None else value)
                strings_only = strings_only and value is not None
            previous = token
    if words and not strings_only:
        rendered.append("    " * depth + " ".join(words))
    return "\n".join(rendered)


def _string(token: str) -> str | None:
    """A string literal by its value, however it is written: a str in double quotes, with
    every character but printable ASCII escaped (``unicode_escape``, which needs no Unicode
    tables that change with Python's version), bytes by their ``repr``; None for an f-string."""
    if "f" in token[:len(token) - len(token.lstrip("rRbBuUfF"))].lower():
        return None
    try:
        value = ast.literal_eval(token)
    except (SyntaxError, ValueError):
        return None
    if isinstance(value, bytes):
        return repr(value)
    if isinstance(value, str):
        return '"' + value.encode("unicode_escape").decode("ascii").replace('"', '\\"') + '"'
    return None


def _span(lines: list[str], start: tuple[int, int], end: tuple[int, int]) -> str:
    """The text of ``lines`` from ``start`` to ``end``, tokenize's (line from 1, column)."""
    (row, column), (end_row, end_column) = start, end
    if row == end_row:
        return lines[row - 1][column:end_column]
    return lines[row - 1][column:] + "".join(lines[row:end_row - 1]) + lines[end_row - 1][:end_column]


def plain_source(target: Any, *, ignored: bool = False, keep: tuple[str, ...] = ()) -> str | None:
    """The source of a function or class alone (with ``ignored``, a class's without its
    :data:`IGNORED_ATTRIBUTES` but those in ``keep``), as digests were made before they took in
    what the task reads from its module; None when Python cannot find it (typed at a prompt)."""
    try:
        source = inspect.getsource(target)
    except (OSError, TypeError):
        return None
    if not (ignored and inspect.isclass(target)):
        return source
    return _without_ignored(source, keep, _module_reads(target))


def task_source(target: Any, *, raw: bool = False, keep: tuple[str, ...] = ()) -> str | None:
    """The text of a function or class for its digest (see the module docs), each piece of
    source :func:`normalised`; with ``raw``, each piece as written, as digests were made before
    comments and layout were left out; with ``keep``, those of :data:`IGNORED_ATTRIBUTES` kept,
    as digests were made before they were left out. None when Python cannot find its source."""
    own = plain_source(target, ignored=True, keep=keep)
    if own is None:
        return None
    statements = _module_statements(target)
    namespace = _module_namespace(target)
    parts = [own if raw else normalised(own)]
    seen: set[str] = set()
    pending = sorted(_names_used(target, own))
    while pending:
        name = pending.pop(0)
        if name in seen or name not in namespace or isinstance(namespace[name], types.ModuleType):
            continue
        seen.add(name)
        value = namespace[name]
        function = _function_of(value)
        if name in statements:  # made by a statement (even a function: AMPLIFY = make(2.0))
            written = statements[name]
            # Statements the same but for their layout count once.
            text = "\n".join(written if raw else dict.fromkeys(normalised(t) for t in written))
            used = _loaded_names("\n".join(written))
        elif (function is not None or inspect.isclass(value)) and _defined_alongside(function or value, target):
            source = plain_source(function or value, ignored=True, keep=keep) or ""
            text = source if raw else normalised(source)
            used = _names_used(function or value, source)
        elif not callable(value):
            text, used = fingerprint(value), set()
        else:
            continue  # code from another module
        parts.append(f"# {name}\n{text}")
        pending.extend(sorted(used - seen))
    return "\n".join(parts)


def _names_used(target: Any, source: str) -> set[str]:
    """The global names that ``target`` reads: those its code (every layer of a decorated
    function, a class's methods and properties) loads as globals, and those its source loads
    outside function bodies (a class body's ``horizon = STEPS``, default arguments, decorators,
    base classes)."""
    names: set[str] = set()
    codes = [f.__code__ for f in _functions(target)]
    while codes:
        code = codes.pop()
        names.update(str(i.argval) for i in dis.get_instructions(code)
                     if i.opname in ("LOAD_GLOBAL", "LOAD_NAME"))
        codes.extend(c for c in code.co_consts if isinstance(c, types.CodeType))
    return names | _loaded_names(source, outside_bodies=True)


def _loaded_names(source: str, *, outside_bodies: bool = False) -> set[str]:
    """The names ``source`` loads; with ``outside_bodies``, not those inside the bodies of the
    functions it defines (their code says which of them are globals)."""
    try:
        tree = ast.parse(textwrap.dedent(source))
    except SyntaxError:
        return set()
    names: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load):
            names.add(node.id)
        for field, child in ast.iter_fields(node):
            if outside_bodies and field == "body" and isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda):
                continue
            for item in child if isinstance(child, list) else [child]:
                if isinstance(item, ast.AST):
                    visit(item)
    visit(tree)
    return names


def _module_statements(target: Any) -> dict[str, list[str]]:
    """The source of each top-level statement of ``target``'s module that stores a name (an
    assignment, also to an item or attribute of it, an augmented assignment, a ``for`` or a
    ``with``), by name: what the module's data is made of, whatever it holds at run time (a
    cache filled by the task, a counter)."""
    module = sys.modules.get(getattr(target, "__module__", ""), None)
    try:
        source = inspect.getsource(module) if module is not None else ""
        tree = ast.parse(source)
    except (OSError, TypeError, SyntaxError):
        return {}
    found: dict[str, list[str]] = {}
    for statement in tree.body:
        if isinstance(statement, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef | ast.Import
                      | ast.ImportFrom):
            continue
        for node in ast.walk(statement):
            if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
                stored = node.id
            elif isinstance(node, ast.Subscript | ast.Attribute) and isinstance(node.ctx, ast.Store) \
                    and isinstance(base := _base_name(node), str):
                stored = base
            else:
                continue
            text = ast.get_source_segment(source, statement) or ""
            if text not in found.setdefault(stored, []):
                found[stored].append(text)
    return found


def _base_name(node: ast.AST) -> str | None:
    """The name at the root of ``x[...]`` or ``x.y``."""
    while isinstance(node, ast.Subscript | ast.Attribute):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def _module_namespace(target: Any) -> Mapping[str, Any]:
    function = _function_of(target)
    if function is not None:
        return function.__globals__
    module = sys.modules.get(getattr(target, "__module__", ""), None)
    return vars(module) if module is not None else {}


def _defined_alongside(value: Any, target: Any) -> bool:
    """Whether ``value`` is a function or class defined in ``target``'s module."""
    return (inspect.isfunction(value) or inspect.isclass(value)) and \
        getattr(value, "__module__", None) == getattr(target, "__module__", None)


def _function_of(value: Any) -> types.FunctionType | None:
    """The plain function behind ``value`` (a function, a method, a static or class method, a
    cached property, the outermost layer of a decorated function), or None, also for an object
    whose attributes cannot be read."""
    try:
        value = inspect.getattr_static(value, "__func__", value)  # staticmethod, classmethod
        if isinstance(value, types.MethodType):
            value = value.__func__
        if isinstance(value, functools.cached_property):
            value = value.func
        if not inspect.isfunction(value):  # a callable wrapper (functools.lru_cache)
            value = inspect.getattr_static(value, "__wrapped__", None)
    except Exception:  # an object whose lookups raise is no function
        return None
    return value if inspect.isfunction(value) else None


def _functions(target: Any) -> list[types.FunctionType]:
    """The functions whose code is ``target``'s: every layer of a decorated function (the
    decorator's wrapper and what it wraps), or a class's methods and its properties' getters,
    setters and deleters (each with its layers)."""
    parts = [target]
    if inspect.isclass(target):
        parts = []
        for attribute in vars(target).values():
            parts.extend([attribute.fget, attribute.fset, attribute.fdel] if isinstance(attribute, property)
                         else [attribute])
    found: list[types.FunctionType] = []
    for part in parts:
        function = _function_of(part)
        while function is not None and function not in found:
            found.append(function)
            try:
                inner = inspect.getattr_static(function, "__wrapped__", None)
            except Exception:
                inner = None
            function = _function_of(inner)
    return found


def _without_ignored(source: str, keep: tuple[str, ...] = (), reads: frozenset[str] = frozenset()) -> str:
    """A class's source without its class-level assignments to :data:`IGNORED_ATTRIBUTES` (but
    those in ``keep``). One of :data:`KEPT_WHEN_READ` stays when the class, or its module
    (``reads``: the attribute names and strings its module's code holds), reads it, or when its
    assignment shares a line with other code."""
    dedented = textwrap.dedent(source)
    try:
        tree = ast.parse(dedented)
    except SyntaxError:
        return source
    if not tree.body or not isinstance(tree.body[0], ast.ClassDef):
        return source
    cls = tree.body[0]
    read = reads | {node.attr for node in ast.walk(cls)
                    if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Load)}
    ignored = [a for a in IGNORED_ATTRIBUTES if a not in keep and not (a in KEPT_WHEN_READ and a in read)]

    def alone(statement: ast.stmt) -> bool:
        """Whether no other code shares the statement's lines (the class's header included)."""
        lines = set(range(statement.lineno, (statement.end_lineno or statement.lineno) + 1))
        return cls.lineno not in lines and not any(
            lines & set(range(other.lineno, (other.end_lineno or other.lineno) + 1))
            for other in cls.body if other is not statement)

    drop: set[int] = set()
    for statement in cls.body:
        targets = statement.targets if isinstance(statement, ast.Assign) else \
            [statement.target] if isinstance(statement, ast.AnnAssign) else []
        names = {t.id for t in targets if isinstance(t, ast.Name)} & set(ignored)
        if names and (alone(statement) or not names & set(KEPT_WHEN_READ)):
            drop.update(range(statement.lineno, (statement.end_lineno or statement.lineno) + 1))
    if not drop:
        return source
    lines = source.splitlines(keepends=True)
    return "".join(line for number, line in enumerate(lines, 1) if number not in drop)


def _module_reads(target: Any) -> frozenset[str]:
    """The attribute names that the code of ``target``'s module loads, and the strings it holds
    (``getattr(self, "preset")``): what may read a class attribute from outside the class."""
    module = sys.modules.get(getattr(target, "__module__", ""), None)
    try:
        tree = ast.parse(inspect.getsource(module)) if module is not None else None
    except (OSError, TypeError, SyntaxError):
        return frozenset()
    if tree is None:
        return frozenset()
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Load):
            found.add(node.attr)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            found.add(node.value)
    return frozenset(found)
