"""Run folders: config, per-generation log, champion and checkpoint, each written atomically.

A run folder holds:

- ``config.toml``: the complete, resolved config, with the seed and the dnnevo version;
- ``log.csv``: one row per generation (rewritten at most every second, and at every
  checkpoint, so it may trail the run by a second): best, mean, std and min fitness; whether the
  champion so far meets the task's success criterion on fresh conditions (1 or 0, ``nan`` when
  the task has none); the champion's validation rate and score (``nan`` when it was chosen by
  training fitness); evaluations per second and elapsed seconds;
- ``best.json``: the champion in the ``dnnevo-network`` format, with meta;
- ``checkpoint.json``: the GA state and the history, enough to continue bit for bit.
"""

from __future__ import annotations

import csv
import json
import os
import tempfile
from pathlib import Path
from typing import Any

from dnnevo.errors import DnnevoError

__all__ = ["LOG_COLUMNS", "RunDir", "write_atomic"]

LOG_COLUMNS = (
    "generation",
    "best",
    "mean",
    "std",
    "min",
    "champion_success",
    "validation_rate",
    "validation_score",
    "evals_per_s",
    "elapsed_s",
)
CHECKPOINT_FORMAT = "dnnevo-checkpoint"
CHECKPOINT_VERSION = 1


def write_atomic(path: Path, text: str) -> None:
    """Writes ``text`` to a temporary file beside ``path``, syncs it, and renames it into place."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


class RunDir:
    """The files of one run."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)

    config = property(lambda self: self.path / "config.toml")
    log = property(lambda self: self.path / "log.csv")
    best = property(lambda self: self.path / "best.json")
    checkpoint = property(lambda self: self.path / "checkpoint.json")

    def create(self, *, force: bool) -> None:
        """Makes the folder; a non-empty one is refused unless ``force``."""
        if self.path.exists() and not self.path.is_dir():
            raise DnnevoError(f"{self.path} exists and is not a folder")
        if self.path.is_dir() and any(self.path.iterdir()) and not force:
            raise DnnevoError(
                f"{self.path} is not empty; choose another --out, resume it with "
                f"'dnnevo resume {self.path}', or pass --force to overwrite"
            )
        self.path.mkdir(parents=True, exist_ok=True)
        if force:
            for name in (self.config, self.log, self.best, self.checkpoint):
                name.unlink(missing_ok=True)

    def write_log(self, history: list[dict[str, float]]) -> None:
        """Rewrites ``log.csv`` from the whole history (atomic, so never torn)."""
        lines = [",".join(LOG_COLUMNS)]
        # Histories from before a column existed lack it: those generations have no value.
        lines += [",".join(repr(float(row.get(k, "nan"))) for k in LOG_COLUMNS) for row in history]
        write_atomic(self.log, "\n".join(lines) + "\n")

    def write_checkpoint(self, state: dict[str, Any], history: list[dict[str, float]]) -> None:
        """Writes the GA state and the history."""
        doc = {
            "format": CHECKPOINT_FORMAT,
            "version": CHECKPOINT_VERSION,
            "state": state,
            "history": history,
        }
        write_atomic(self.checkpoint, json.dumps(doc))

    def read_checkpoint(self) -> tuple[dict[str, Any], list[dict[str, float]]]:
        """The GA state and history saved by :meth:`write_checkpoint`."""
        if not self.checkpoint.is_file():
            raise DnnevoError(f"{self.path} has no checkpoint.json; is it a dnnevo run folder?")
        try:
            doc = json.loads(self.checkpoint.read_text(encoding="utf-8"))
            if doc.get("format") != CHECKPOINT_FORMAT or doc.get("version") != CHECKPOINT_VERSION:
                raise ValueError("wrong format or version")
            return doc["state"], doc["history"]
        except (ValueError, KeyError, TypeError) as e:
            raise DnnevoError(f"{self.checkpoint} is not a valid checkpoint: {e}") from None

    def read_log(self) -> list[dict[str, float]]:
        """The rows of ``log.csv`` as floats."""
        if not self.log.is_file():
            raise DnnevoError(f"{self.path} has no log.csv; is it a dnnevo run folder?")
        with self.log.open(encoding="utf-8") as f:
            return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]
