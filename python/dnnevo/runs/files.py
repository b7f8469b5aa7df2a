"""One file of a run folder: written atomically (a temporary file beside it, then a rename), read
with every check of its type, and every failure a :class:`RunFileError` of one line naming the
file.

Every reader of a file dnnevo wrote (a run's, a sweep's, a reproduction's) reads it as a whole
through :func:`read_text` or :func:`read_json`, and checks it inside :func:`checked`, so that no
damage to the file can escape as anything but a :class:`RunFileError` naming it.
"""

from __future__ import annotations

import contextlib
import errno
import json
import re
import os
import tempfile
from collections.abc import Callable, Container, Iterator
from pathlib import Path
from typing import Any

from dnnevo.errors import DnnevoError, WriteError

__all__ = ['FILE_MODE', 'RunFileError', 'checked', 'fail', 'load_json', 'number', 'read_json', 'read_text', 'remove_temporaries', 'save_figure', 'short', 'temporary_of', 'write_atomic', 'write_atomic_with', 'write_error']

def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: Files are created with mode 0666 & ~umask, as ``open()`` and Rust's ``File::create`` do.
FILE_MODE = 0o666 & ~_umask()


class RunFileError(DnnevoError):
    """A file of a run folder (or of a sweep's or a reproduction's folder) is missing, damaged or
    disagrees with the others."""


def fail(path: Path, problem: str) -> RunFileError:
    return RunFileError(f"{path}: {problem}")


#: What a failed write means, by errno; any other is said in the system's words.
_WRITE_FAILURES = {
    errno.ENOSPC: "no space is left on the device",
    errno.EDQUOT: "the disk quota is used up",
    errno.EFBIG: "it would pass the file-size limit (ulimit -f)",
    errno.EROFS: "the file system is read-only",
    errno.EACCES: "permission denied: the folder is read-only to this user",
    errno.EPERM: "permission denied: the folder is read-only to this user",
}


def write_failure(error: OSError) -> str:
    """Why a write failed, in words: "the file system is read-only", "the disk is full", ..."""
    return _WRITE_FAILURES.get(error.errno or 0, error.strerror or str(error))


def write_error(path: Path, error: OSError) -> WriteError:
    """One line naming the file that could not be written, and why."""
    return WriteError(f"{path} could not be written: {write_failure(error)}; what it held before is kept")


#: Temporary files of atomic writes: ``.NAME.RANDOM.tmp`` (Python, Rust), optionally with the
#: final name's extension after it, and ``.NAME.tmpPID`` (Rust before version 0.1.1).
_TEMPORARY = re.compile(r"^\.(?P<name>.+)\.(?:[A-Za-z0-9_]{8,16}\.tmp(?:\.[a-z]+)?|tmp\d+)$")


def temporary_of(path: Path) -> str | None:
    """The name of the file that ``path`` is the temporary file of (an atomic write killed
    before its rename leaves one behind), or None when ``path`` is no such file."""
    m = _TEMPORARY.match(path.name)
    return m["name"] if m and path.is_file() else None


def remove_temporaries(folder: Path, names: Container[str] | None = None) -> None:
    """Removes the temporary files that killed atomic writes left in ``folder``: those of the
    files ``names``, or every one when None. Only the holder of the folder's lock may call it,
    since it alone writes there."""
    if folder.is_dir():
        for p in folder.iterdir():
            name = temporary_of(p)
            if name is not None and (names is None or name in names):
                p.unlink(missing_ok=True)


def write_atomic_with(path: Path, write: Callable[[str], None], *, suffix: str = "") -> None:
    """Calls ``write(tmp)`` on a new, exclusively created temporary file beside ``path`` (named
    ``.NAME.RANDOM.tmp`` + ``suffix``), syncs it and renames it over ``path``. The rename replaces
    a symlink at ``path``; it never writes through one. A full disk, a file-size limit or a
    read-only folder is a :class:`~dnnevo.errors.WriteError` naming ``path``; the file is then as
    it was."""
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=f".tmp{suffix}")
    except OSError as e:
        raise write_error(path, e) from e
    try:
        os.fchmod(fd, FILE_MODE)
        os.close(fd)
        write(tmp)
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as e:
        Path(tmp).unlink(missing_ok=True)
        if isinstance(e, OSError) and not isinstance(e, DnnevoError):
            raise write_error(path, e) from e
        raise


def write_atomic(path: Path, text: str) -> None:
    """Writes ``text`` to a temporary file beside ``path``, syncs it, and renames it into place."""

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)

    write_atomic_with(path, write)


def save_figure(fig: Any, path: Path, *, dpi: int = 120) -> None:
    """Saves a matplotlib figure as ``path`` (PNG) atomically."""
    write_atomic_with(path, lambda tmp: fig.savefig(tmp, dpi=dpi, format="png"))


def read_text(path: Path) -> str:
    if path.is_symlink() or not path.is_file():
        problem = "is a symlink" if path.is_symlink() else "is missing or not a file"
        raise fail(path, problem)
    data = path.read_bytes()
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise fail(path, f"is not UTF-8 text (byte {e.start})") from None


#: A ``\u`` escape of a UTF-16 surrogate: half of a pair, or, alone, no character at all.
_SURROGATE_ESCAPE = re.compile(r"\\u[dD][89a-fA-F][0-9a-fA-F]{2}")


def _distinct_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """An object's keys, each once: ``json.loads`` alone keeps the last of two equal keys."""
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"the key {json.dumps(key, ensure_ascii=False)} appears twice in one object")
        out[key] = value
    return out


def load_json(path: Path, text: str) -> Any:
    try:
        doc = json.loads(text, object_pairs_hook=_distinct_keys)
    except RecursionError:
        raise fail(path, "JSON nested too deeply") from None
    except ValueError as e:
        raise fail(path, f"not valid JSON: {e}") from None
    # json.loads turns an escaped lone surrogate into a str that no UTF-8 consumer (the Rust core,
    # a file) accepts; pairs are fine. Checked only when the text holds such an escape at all.
    if _SURROGATE_ESCAPE.search(text):
        try:
            json.dumps(doc, ensure_ascii=False).encode("utf-8")
        except UnicodeEncodeError:
            raise fail(path, "holds a \\u escape of a lone surrogate, which is no character") from None
    return doc


def read_json(path: Path) -> Any:
    """The JSON document in ``path``, read by :func:`read_text` and :func:`load_json`: a file
    that is missing, a symlink, not UTF-8, not JSON or nested too deeply is a
    :class:`RunFileError` naming it."""
    return load_json(path, read_text(path))


#: What a damaged file can make a reader's own code raise when a check is missing: a value of
#: the wrong type or range (``int("x")``, ``None["a"]``, ``"a" < 1``, ``round(inf)``), a
#: missing key or item, or nesting deeper than Python's recursion limit.
_DAMAGE = (ValueError, TypeError, KeyError, IndexError, AttributeError, OverflowError, RecursionError)


@contextlib.contextmanager
def checked(path: Path) -> Iterator[None]:
    """Reads and checks of ``path`` inside this block fail only with a
    :class:`~dnnevo.errors.DnnevoError`: one is passed on as it is; any exception in
    :data:`_DAMAGE` (a check the reader lacks, which the fuzzers in ``fuzz/`` look for) becomes
    a :class:`RunFileError` naming ``path`` and what went wrong.

    >>> with checked(Path("log.csv")):
    ...     float("x")
    Traceback (most recent call last):
    dnnevo.runs.files.RunFileError: log.csv: damaged (ValueError: could not convert string to float: 'x')
    """
    try:
        yield
    except DnnevoError:
        raise
    except _DAMAGE as e:
        raise fail(path, f"damaged ({type(e).__name__}: {e})") from e


def number(path: Path, where: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise fail(path, f"{where} is {short(value)}; expected a number")
    try:
        return float(value)
    except OverflowError:  # an integer of more than 308 digits
        raise fail(path, f"{where} is {short(value)}; expected a number a float can hold") from None


def short(value: Any) -> str:
    """``repr(value)``, cut to 40 characters."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
