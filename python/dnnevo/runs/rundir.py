"""Run folders: config, per-generation log, champion and checkpoint, each written atomically,
each validated when read.

A run folder holds:

- ``config.toml``: the complete, resolved config, with the seed and the dnnevo version;
- ``log.csv``: one row per generation (rewritten at most every second, and at every
  checkpoint, so it may trail the run by a second): the generation (an integer), the generation's
  best, mean, std and min fitness; whether the champion so far meets the task's success
  criterion on fresh conditions (1 or 0, ``nan`` when the task has none); the champion's
  validation rate and score (``nan`` when it was chosen by training fitness); evaluations per
  second and elapsed seconds;
- ``best.json``: the champion in the ``dnnevo-network`` format, with meta;
- ``checkpoint.json``: the GA state, the history and a digest of the complete run config, enough
  to continue bit for bit (written at generation 0, before anything else, so a folder is
  resumable from the moment it holds a run);
- ``.dnnevo.lock``: the lock of the one process that writes the folder (``run``, ``resume``,
  ``sweep``). It is an ``flock`` lock, so it dies with its process; the file itself stays and
  holds the last writer's PID.

Every file is checked when read: its type, shape, ranges and finiteness, and its agreement with
the other files. Whatever is wrong raises :class:`~dnnevo.errors.DnnevoError` (or a subclass)
with one line naming the file and the problem.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import errno
import fcntl
import io
import json
import math
import os
import time
import tomllib
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

from dnnevo._core import Network
from dnnevo.config import PYTHON_TASK, EvolutionConfig
from dnnevo.errors import ConfigError, DnnevoError, FormatError, WriteError
from dnnevo.runs.checkpoint import CHECKPOINT_FORMAT, CHECKPOINT_VERSION, Checkpoint
from dnnevo.runs.files import (FILE_MODE, RunFileError, checked, fail, load_json, read_json, read_text,
                               remove_temporaries, short, temporary_of, write_atomic, write_failure)
from dnnevo.runs.history import LOG_COLUMNS, OPTIONAL_COLUMNS, check_history, history_rows, log_cell, read_cell
from dnnevo.runs.settings import MAX_CONFIG_DEPTH, config_digest, depth, first_difference

__all__ = ["FIGURES", "LOCK_NAME", "RUN_FILES", "RunDir"]

LOCK_NAME = ".dnnevo.lock"
#: Why a folder's lock file cannot be made that says the folder cannot be written at all.
_UNWRITABLE = frozenset({errno.EROFS, errno.EACCES, errno.EPERM, errno.ENOSPC, errno.EDQUOT})
RUN_FILES = ("config.toml", "log.csv", "best.json", "checkpoint.json")
#: Every file ``show``, ``plot`` and ``analyze`` derive from a run; ``--force`` removes them with
#: the run's files.
FIGURES = (
    "fitness.png",
    "fig1-traces.png",
    "world.png",
    "trial-landmark2.gif",
    "fig2-paths.png",
    "fig3-classifier.png",
    "fig4-trials.png",
    "fig5-switch.png",
    "analysis-phase.png",
    "analysis-bifurcation.png",
    "analysis-basins.png",
    "analysis-lesions.png",
    "analysis.json",
)


LOCK_ATTEMPTS = 10
"""Tries at a run folder's lock before it is reported in use, :data:`LOCK_WAIT` apart: a reader
that asks whether a run is going on (:meth:`RunDir.writer`) holds it for an instant."""
LOCK_WAIT = 0.01
"""Seconds between two tries at the lock."""


class RunDir:
    """The files of one run."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self._lock_fd: int | None = None

    config = property(lambda self: self.path / "config.toml")
    log = property(lambda self: self.path / "log.csv")
    best = property(lambda self: self.path / "best.json")
    checkpoint = property(lambda self: self.path / "checkpoint.json")
    lock_file = property(lambda self: self.path / LOCK_NAME)

    # -- the writer's lock --------------------------------------------------------------------

    @contextlib.contextmanager
    def writing(self, *, create: bool) -> Iterator[RunDir]:
        """Holds the folder's exclusive lock (making the folder first when ``create``); another
        writer gets a :class:`DnnevoError` naming the holder's PID. The lock dies with the
        process, so a killed run never leaves a stale lock."""
        if self.path.exists() and not self.path.is_dir():
            raise DnnevoError(f"{self.path} exists and is not a folder")
        if create:
            try:
                self.path.mkdir(parents=True, exist_ok=True)
            except OSError as e:
                raise WriteError(f"{self.path} cannot be made: {write_failure(e)}") from None
        elif not self.path.exists():
            raise RunFileError(f"{self.path} does not exist")
        flags = os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC
        try:
            fd = os.open(self.lock_file, flags, FILE_MODE)
        except OSError as e:
            if e.errno in _UNWRITABLE:  # the folder itself cannot be written
                raise WriteError(f"{self.path} cannot be written: {write_failure(e)}") from None
            raise DnnevoError(f"cannot open the lock file {self.lock_file}: {e.strerror}") from None
        try:
            for attempt in range(LOCK_ATTEMPTS):
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    # A reader's probe (writer()) holds it for an instant; a writer, for good.
                    if attempt + 1 < LOCK_ATTEMPTS:
                        time.sleep(LOCK_WAIT)
                        continue
                    holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "unknown"
                    raise DnnevoError(
                        f"{self.path} is in use by another dnnevo process (PID {holder}); "
                        "wait for it to finish or stop it first") from None
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            self._lock_fd = fd
            yield self
        finally:
            self._lock_fd = None
            os.close(fd)

    def stale_files(self) -> list[Path]:
        """Temporary files of this folder's own atomic writes (the run's four files); stale when
        the lock is held, as only the lock's holder writes them."""
        return [p for p in self.path.iterdir() if temporary_of(p) in RUN_FILES]

    def remove_stale(self) -> None:
        """Removes temporary files left by a writer that was killed inside a write."""
        remove_temporaries(self.path, RUN_FILES)

    def _leftover(self, p: Path) -> bool:
        """A file that holds no run: the lock file, or a temporary file of a killed write."""
        return p.name == LOCK_NAME or temporary_of(p) is not None

    def _unstarted(self, contents: list[Path]) -> bool:
        """Whether ``contents`` are a run that stopped before its first generation was scored
        (its task raised, or it was stopped): only its config, an empty log and a checkpoint
        whose history is empty. Nothing was evolved, so a new run may take the folder; resuming
        would only run the same generation 0 again, and could not once the task's code is
        fixed (its digest changed)."""
        names = {p.name for p in contents}
        if not names <= {self.config.name, self.log.name, self.checkpoint.name} or self.checkpoint.name not in names:
            return False
        try:
            doc = load_json(self.checkpoint, read_text(self.checkpoint))
        except (OSError, ValueError, DnnevoError):
            return False
        return isinstance(doc, dict) and doc.get("history") == []

    def _contents(self) -> list[Path]:
        """What the folder holds that a new run must not overwrite without ``force``: everything
        but a lock file, temporary files of killed writes, and a run that never scored a
        generation (:meth:`_unstarted`)."""
        contents = [p for p in self.path.iterdir() if not self._leftover(p)]
        return [] if self._unstarted(contents) else contents

    def refuse_unless_new(self, *, force: bool) -> None:
        """Refuses, before anything is written (the lock file included), a folder that holds
        more than a lock file and temporary files, unless ``force``; the message says what the
        folder holds and what to do with it. A run that stopped before its first generation was
        scored does not count: a new run replaces it. :meth:`create` checks again under the
        lock."""
        if not self.path.is_dir():
            return
        if (pid := self.writer()) is not None:
            raise DnnevoError(f"{self.path} is in use by another dnnevo process (PID {pid}); "
                              "wait for it to finish or stop it first")
        if force:
            return
        contents = self._contents()
        if contents:
            raise DnnevoError(self._occupied(contents))

    def writer(self) -> str | None:
        """The PID of the process writing this folder now (the holder of its lock, as it wrote
        it), or None when none is. Takes the lock, shared, for an instant to tell."""
        try:
            fd = os.open(self.lock_file, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC)
        except OSError:
            return None
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
            except BlockingIOError:
                return os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "unknown"
            fcntl.flock(fd, fcntl.LOCK_UN)
            return None
        finally:
            os.close(fd)

    def _resume_command(self) -> str:
        """How to resume the run here: from Python when it was evolved with a fitness function
        or a class defined in a script, which the command line cannot build (``resume`` says
        the same)."""
        try:
            stored = tomllib.loads(self.config.read_text())
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
            stored = {}
        task, params = stored.get("task"), stored.get("task_params")
        if not (isinstance(task, str) and task.startswith(PYTHON_TASK)):
            return f"'dnnevo resume {self.path}'"
        if not (isinstance(params, Mapping) and "max_steps" in params):  # a fitness function
            return f"dnnevo.resume({str(self.path)!r}, task=fitness) from Python"
        if task.startswith(f"{PYTHON_TASK}__main__."):  # a script's class: no other process imports it
            return f"dnnevo.resume({str(self.path)!r}, task=ClosedLoop(...)) from Python"
        return f"'dnnevo resume {self.path}'"

    def _occupied(self, contents: list[Path]) -> str:
        names = sorted(p.name for p in contents)
        if "checkpoint.json" in names or "config.toml" in names:
            what = f"it holds a run: resume it with {self._resume_command()}"
        elif "sweep.json" in names:
            what = "it holds a sweep: continue it with the same 'dnnevo sweep' command"
        elif "reproduce.json" in names:
            what = "it holds a reproduction: continue it with the same 'dnnevo reproduce' command"
        else:
            shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
            what = f"it holds files that are not a dnnevo run ({shown})"
        return (f"{self.path} is not empty; {what}; or choose another folder (--out; out= in Python), "
                "or overwrite it (--force; force=True in Python)")

    def create(self, *, force: bool, extra: tuple[str, ...] = ()) -> None:
        """Readies the locked folder for a new run: one that holds more than a lock file and
        temporary files is refused unless ``force``, which removes the old run's files, figures
        and ``extra`` files (other files are kept)."""
        assert self._lock_fd is not None, "create() needs the lock"
        contents = self._contents()
        if contents and not force:
            raise DnnevoError(self._occupied(contents))
        self.clear(extra)

    def clear(self, extra: tuple[str, ...] = ()) -> None:
        """Removes the run's files, its figures, ``extra`` files and every temporary file of a
        killed write."""
        for name in (*RUN_FILES, *FIGURES, *extra):
            (self.path / name).unlink(missing_ok=True)
        remove_temporaries(self.path)

    # -- writing ------------------------------------------------------------------------------

    def write_config(self, config: EvolutionConfig, run: Mapping[str, Any]) -> None:
        """Writes ``config.toml`` with its ``[run]`` table."""
        write_atomic(self.config, config.to_toml(run=run))

    def write_log(self, history: list[dict[str, float]]) -> None:
        """Rewrites ``log.csv`` from the whole history (atomic, so never torn)."""
        lines = [",".join(LOG_COLUMNS)]
        lines += [",".join(log_cell(k, float(row.get(k, "nan"))) for k in LOG_COLUMNS) for row in history]
        write_atomic(self.log, "\n".join(lines) + "\n")

    def write_checkpoint(self, state: dict[str, Any], history: list[dict[str, float]],
                         run: Mapping[str, Any], seed: int) -> None:
        """Writes the GA state, the history, the run table and the config's digest."""
        config = EvolutionConfig.from_dict(state["config"])
        doc = {
            "format": CHECKPOINT_FORMAT,
            "version": CHECKPOINT_VERSION,
            "config_sha256": config_digest(config, seed),
            "run": dict(run),
            "state": state,
            "history": history,
        }
        write_atomic(self.checkpoint, json.dumps(doc, allow_nan=True))

    # -- reading ------------------------------------------------------------------------------

    def read_config(self) -> tuple[EvolutionConfig, dict[str, Any]]:
        """``config.toml``: the config (which must name its task) and its ``[run]`` table (empty
        in a config written by hand; its seed, if any, checked)."""
        path = self.config
        if not path.exists() and not path.is_symlink():
            if not self.path.exists():
                raise RunFileError(f"{self.path} does not exist; give a run folder (one that holds config.toml)")
            if not self.path.is_dir():
                raise RunFileError(f"{self.path} is a file, not a run folder (a folder that holds config.toml)")
            raise RunFileError(f"{self.path} has no config.toml; {self.not_a_run()}")
        with checked(path):
            text = read_text(path)
            try:
                doc = tomllib.loads(text)
            except tomllib.TOMLDecodeError as e:
                raise fail(path, f"not valid TOML: {e}") from None
            except RecursionError:
                raise fail(path, "TOML nested too deeply") from None
            if depth(doc) > MAX_CONFIG_DEPTH:
                raise fail(path, f"tables and arrays nested deeper than {MAX_CONFIG_DEPTH}")
            run = doc.pop("run", {})
            if not isinstance(run, dict):
                raise fail(path, f"run is {short(run)}; expected a table")
            seed = run.get("seed", 0)
            if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**64:
                raise fail(path, f"run.seed is {short(seed)}; expected an integer in [0, 2**64)")
            if "task" not in doc:
                raise fail(path, "has no task")
            try:
                config = EvolutionConfig.from_dict(doc)
            except ConfigError as e:
                raise fail(path, str(e)) from None
            return config, run

    def read_run_config(self) -> tuple[EvolutionConfig, dict[str, Any]]:
        """``config.toml`` as a command that reads a run must take it: :meth:`read_config`,
        refused when it disagrees with the checkpoint's config (it was edited after the run), as
        ``resume`` refuses it. A folder without a checkpoint has only config.toml to go by."""
        config, table = self.read_config()
        if self.checkpoint.exists() or self.checkpoint.is_symlink():
            cp = self.read_checkpoint()
            saved = EvolutionConfig.from_dict(cp.state["config"])
            diff = first_difference(config.to_dict(), saved.to_dict())
            if diff is not None:
                raise RunFileError(
                    f"{self.config} was edited after the run: {diff[0]} is {short(diff[1])} in "
                    f"config.toml and {short(diff[2])} in checkpoint.json, with which the run was "
                    f"made; put it back (to run longer: 'dnnevo resume {self.path} --generations N')")
            if cp.run is not None and "seed" in cp.run and table.get("seed") != cp.run["seed"]:
                raise RunFileError(
                    f"{self.config} was edited after the run: run.seed is {short(table.get('seed'))} in "
                    f"config.toml and {short(cp.run['seed'])} in checkpoint.json, with which the run was "
                    "made; put it back")
        return config, table

    def read_checkpoint(self) -> Checkpoint:
        """The validated checkpoint: its structure, its history (the same rules as log.csv),
        and its config against the digest it carries."""
        path = self.checkpoint
        if not path.exists() and not path.is_symlink():
            raise RunFileError(f"{self.path} has no checkpoint.json; {self.not_a_run()}")
        with checked(path):
            doc = read_json(path)
            if not isinstance(doc, dict):
                raise fail(path, f"is a JSON {type(doc).__name__}; expected an object")
            if doc.get("format") != CHECKPOINT_FORMAT or doc.get("version") not in (1, CHECKPOINT_VERSION):
                raise fail(path, f"format/version is {short(doc.get('format'))}/"
                                  f"{short(doc.get('version'))}; expected {CHECKPOINT_FORMAT}/1 or 2")
            state = doc.get("state")
            if not isinstance(state, dict) or set(state) != {"config", "evolution"}:
                raise fail(path, "state must be an object with 'config' and 'evolution'")
            if not isinstance(state["evolution"], str):
                raise fail(path, "state.evolution must be the GA state as JSON text")
            if depth(state["config"]) > MAX_CONFIG_DEPTH:
                raise fail(path, f"state.config nests deeper than {MAX_CONFIG_DEPTH}")
            try:
                config = EvolutionConfig.from_dict(state["config"])
            except ConfigError as e:
                raise fail(path, f"state.config: {e}") from None
            history = history_rows(path, doc.get("history"))
            run = None
            if doc["version"] >= 2:
                run = doc.get("run")
                seed = run.get("seed") if isinstance(run, dict) else None
                if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**64:
                    raise fail(path, "run.seed must be an integer in [0, 2**64)")
                if doc.get("config_sha256") != config_digest(config, seed):
                    raise fail(path, "its config does not match the digest it carries (was it edited?)")
            return Checkpoint(state, history, run, config)

    def read_log(self, config: EvolutionConfig | None = None) -> list[dict[str, float]]:
        """The rows of ``log.csv`` as floats, checked by the rules of the checkpoint's history,
        and no more generations than ``config`` has."""
        path = self.log
        if not path.exists() and not path.is_symlink():
            raise RunFileError(f"{self.path} has no log.csv; {self.not_a_run()}")
        with checked(path):
            text = read_text(path)
            try:
                table = list(csv.reader(io.StringIO(text, newline=""), strict=True))
            except csv.Error as e:
                raise fail(path, f"not valid CSV: {e}") from None
            if not table:
                raise fail(path, "is empty")
            header = table[0]
            required = [c for c in LOG_COLUMNS if c not in OPTIONAL_COLUMNS]
            if len(set(header)) != len(header) or not set(required) <= set(header) <= set(LOG_COLUMNS):
                raise fail(path, f"has columns {','.join(header)[:80]}; expected {','.join(LOG_COLUMNS)}")
            rows = []
            for i, cells in enumerate(table[1:]):
                if len(cells) != len(header):
                    raise fail(path, f"row {i + 1} has {len(cells)} values; expected {len(header)}")
                row = dict.fromkeys(LOG_COLUMNS, math.nan)
                for k, cell in zip(header, cells, strict=True):
                    try:
                        row[k] = read_cell(cell)
                    except ValueError:
                        raise fail(path, f"row {i + 1}: {k} is {short(cell)}; expected a number") from None
                rows.append(row)
            check_history(path, rows)
            if not rows:
                raise fail(path, "has no generations yet")
            if config is not None and len(rows) > config.generations:
                raise fail(path, f"has {len(rows)} generations; config.toml has {config.generations}")
            return rows

    def not_a_run(self) -> str:
        """What a folder without a run's files is, for a message: a sweep's (:meth:`sweep_hint`),
        or a question."""
        return self.sweep_hint() or "is it a dnnevo run folder?"

    def sweep_hint(self) -> str | None:
        """When the folder holds ``seed-N`` folders (a sweep's or a reproduction's), where its
        runs are; else None."""
        seeds = sorted(p.name for p in self.path.glob("seed-*") if p.is_dir()) if self.path.is_dir() else []
        if not seeds:
            return None
        return (f"it holds the runs {', '.join(seeds[:3])}{', ...' if len(seeds) > 3 else ''} "
                f"(a sweep's folder): name one of them, as {self.path / seeds[0]}")

    def logged_generations(self) -> int:
        """How many generations ``log.csv`` has a row for (its non-empty lines after the header),
        counted without judging them: a damaged log is a record of work all the same."""
        try:
            lines = self.log.read_text(encoding="utf-8", errors="replace").splitlines()
        except FileNotFoundError:
            return 0
        except OSError as e:
            raise RunFileError(f"{self.log}: cannot be read: {e.strerror}") from None
        return sum(1 for line in lines[1:] if line.strip())

    def read_best(self, config: EvolutionConfig, run: Mapping[str, Any] | None = None) -> Network:
        """``best.json``, which must be a network of the run's size and inputs, and, when it
        says, of the run's task, seed, integrator and precision."""
        path = self.best
        if not path.exists() and not path.is_symlink():
            if (pid := self.writer()) is not None:
                raise RunFileError(f"{self.path} has no best.json yet: its run is going on (PID {pid}); "
                                   "try again when a generation has finished")
            if not self.checkpoint.exists():
                raise RunFileError(f"{self.path} has no best.json; no generation has finished yet")
            if self.read_checkpoint().history:
                raise RunFileError(f"{self.path} has no best.json, though it has a checkpoint; "
                                   f"{self._resume_command()} writes it again")
            # A run that failed in its first generation.
            raise RunFileError(f"{self.path} has no best.json; no generation has finished: its run "
                               "stopped in generation 0, so start it again once what stopped it is changed")
        with checked(path):
            try:
                net = Network.load(path)
            except FormatError as e:
                raise RunFileError(str(e) if str(path) in str(e) else f"{path}: {e}") from None
            if (net.size, net.n_inputs) != (config.size, config.n_inputs):
                raise fail(path, f"is a network of size {net.size} with {net.n_inputs} inputs; the run "
                                  f"has size {config.size} with {config.n_inputs} inputs")
            meta = net.meta
            if "task" in meta and meta["task"] != config.task:
                raise fail(path, f"meta.task is {short(meta['task'])}; the run's task is {config.task!r}")
            if run is not None and "seed" in meta and "seed" in run and meta["seed"] != run["seed"]:
                raise fail(path, f"meta.seed is {short(meta.get('seed'))}; the run's seed is {run.get('seed')}")
            want = dataclasses.asdict(config.integrator)
            if net.integrator is not None and net.integrator != want:
                raise fail(path, f"integrator is {net.integrator}; the run's config.toml has {want}")
            if "precision" in meta and meta["precision"] != config.precision:
                raise fail(path, f"meta.precision is {short(meta['precision'])}; the run's precision is "
                                  f"{config.precision!r}")
            return net
