"""A run's history: the columns of ``log.csv``, one row per generation, and the checks every
history passes when read (from the log or from a checkpoint)."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

from dnnevo.runs.files import fail, number

__all__ = ['INTEGER_COLUMNS', 'LOG_COLUMNS', 'OPTIONAL_COLUMNS', 'check_history', 'history_rows', 'log_cell']

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
#: Columns a history from before they existed may lack (those generations have no value).
OPTIONAL_COLUMNS = ("champion_success", "validation_rate", "validation_score")
#: Columns log.csv writes as integers (``7``, not ``7.0``; ``nan`` stays ``nan``). Files written
#: before, with ``7.0``, read the same.
INTEGER_COLUMNS = ("generation", "champion_success")


def check_history(path: Path, rows: list[dict[str, float]], *, what: str = "generation") -> None:
    """The rules every history obeys, in checkpoint.json and log.csv alike: rows of generations
    0, 1, 2, ... in order; finite fitness statistics, std >= 0, min <= best; success 0, 1 or NaN;
    a validation rate in [0, 1] and a finite score, or both NaN; evaluations per second finite
    and >= 0; elapsed seconds finite, >= 0 and never decreasing."""
    elapsed = 0.0
    for i, row in enumerate(rows):
        at = f"{what} row {i + 1}"
        if row["generation"] != i:
            raise fail(path, f"{at} has generation {row['generation']:g}; expected {i}")
        for k in ("best", "mean", "std", "min", "evals_per_s", "elapsed_s"):
            if not math.isfinite(row[k]):
                raise fail(path, f"{at}: {k} is {row[k]}; expected a finite number")
        if row["std"] < 0 or row["evals_per_s"] < 0 or row["elapsed_s"] < 0:
            raise fail(path, f"{at}: std, evals_per_s and elapsed_s must be >= 0")
        if row["min"] > row["best"]:
            raise fail(path, f"{at}: min {row['min']} exceeds best {row['best']}")
        success = row["champion_success"]
        if not (math.isnan(success) or success in (0.0, 1.0)):
            raise fail(path, f"{at}: champion_success is {success}; expected 0, 1 or nan")
        rate, score = row["validation_rate"], row["validation_score"]
        if math.isnan(rate) != math.isnan(score) or not (
                math.isnan(rate) or (0.0 <= rate <= 1.0 and math.isfinite(score))):
            raise fail(path, f"{at}: validation_rate {rate} and validation_score {score} "
                              "must be a rate in [0, 1] and a finite score, or both nan")
        if row["elapsed_s"] < elapsed:
            raise fail(path, f"{at}: elapsed_s goes back in time ({row['elapsed_s']} < {elapsed})")
        elapsed = row["elapsed_s"]


def history_rows(path: Path, history: Any) -> list[dict[str, float]]:
    if not isinstance(history, list):
        raise fail(path, f"history is {type(history).__name__}; expected a list")
    rows = []
    for i, raw in enumerate(history):
        if not isinstance(raw, dict):
            raise fail(path, f"history[{i}] is {type(raw).__name__}; expected an object")
        unknown = sorted(set(raw) - set(LOG_COLUMNS))
        if unknown:
            raise fail(path, f"history[{i}] has unknown key {unknown[0]!r}")
        row = {}
        for k in LOG_COLUMNS:
            if k not in raw and k not in OPTIONAL_COLUMNS:
                raise fail(path, f"history[{i}] has no {k!r}")
            row[k] = number(path, f"history[{i}].{k}", raw.get(k, math.nan))
        rows.append(row)
    check_history(path, rows, what="history")
    return rows


NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:nan|inf)")
"""What a cell of log.csv may hold: a decimal number as ``repr`` writes it, ``nan`` or ``inf``
(Python's ``float`` also takes ``1_0``, spaces and ``infinity``, which no log holds)."""


def read_cell(cell: str) -> float:
    """A cell of log.csv as a float; a ``ValueError`` when it is not a number :data:`NUMBER`
    allows."""
    if NUMBER.fullmatch(cell) is None:
        raise ValueError(f"not a number: {cell!r}")
    return float(cell)


def log_cell(column: str, value: float) -> str:
    """One value of log.csv: an integer column's whole numbers as integers, any other number as
    ``repr`` writes it (which reads back to the same bits)."""
    if column in INTEGER_COLUMNS and value.is_integer():
        return str(int(value))
    return repr(value)
