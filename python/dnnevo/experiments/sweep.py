"""Independent runs of one config over several seeds (``dnnevo sweep``), and what they say with
their uncertainty:

- **success rate**: the fraction of seeds whose run found a champion meeting the task's rule
  (:attr:`~dnnevo.EvolutionResult.first_success` is not None), with its Wilson interval;
- **median first-success generation**, with a 95% percentile bootstrap interval (fixed seed
  :data:`~dnnevo.evaluation.stats.BOOTSTRAP_SEED`, 10,000 resamples). A seed that never succeeded is
  censored at its run's last generation and counts as +infinity, so the median is "not
  reached" when more than half the seeds are censored;
- **final champions passing**: each seed's final champion (``best.json``) judged by
  :func:`dnnevo.tasks.assess` on fresh conditions from seed :data:`EVAL_SEED_BASE` + the run's
  seed, which no run uses; the fraction that pass, with its Wilson interval;
- **step artefacts**: final champions that the time-step check (:mod:`dnnevo.evaluation.stepcheck`: the same
  conditions at a 10x finer step and with RK4) finds failing where the run's step did not.

>>> from dnnevo.experiments import sweep
>>> sweep.eval_seed(3)
1000006
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from dnnevo import tasks
from dnnevo.evaluation import stats
from dnnevo.evaluation.assessment import Assessment
from dnnevo.config import EvolutionConfig
from dnnevo.errors import InvalidArgumentError
from dnnevo.runs import RunDir, RunFileError, first_difference, short, write_atomic
from dnnevo.evolution.evolve import evolve
from dnnevo.evolution.evolve import resume as resume_run
from dnnevo.evolution.seeding import Seeding
from dnnevo.evaluation.stats import Verdict
from dnnevo.evaluation.stepcheck import StepCheck, step_check

__all__ = ["EVAL_SEED_BASE", "CSV_COLUMNS", "SUMMARY_FILES", "SeedResult", "Summary", "eval_seed", "run_seed", "summarize"]

EVAL_SEED_BASE = 1_000_003
"""The fresh conditions of seed s's final champion come from seed ``EVAL_SEED_BASE + s``."""

CSV_COLUMNS = (
    "seed", "best_fitness", "best_generation", "first_success", "first_success_lo",
    "first_success_hi", "last_generation", "succeeded", "succeeded_lo", "succeeded_hi", "wall_s",
    "eval_seed", "final_rate", "final_k", "final_n", "final_lo", "final_hi", "final_verdict",
    "step_change", "step_artefact",
)
"""The columns of ``summary.csv``: one row per seed, then a row ``all`` whose cells aggregate
their column (see :meth:`Summary.csv_text`)."""


SUMMARY_FILES = ("summary.csv", "summary.json")
"""The files a sweep writes into its folder, beside a run folder per seed."""


def eval_seed(seed: int, base: int = EVAL_SEED_BASE) -> int:
    """The seed of the fresh conditions that judge run ``seed``'s final champion."""
    return base + seed


@dataclass(frozen=True)
class SeedResult:
    """One seed's run and its final champion's assessment."""

    seed: int
    best_fitness: float
    best_generation: int
    first_success: int | None
    """The first generation whose champion met the task's rule during the run, if any."""
    last_generation: int
    wall_s: float
    final: Assessment
    interrupted: bool = False
    step: StepCheck | None = None
    """The final champion's time-step check, when the sweep made one."""

    @property
    def artefact(self) -> bool:
        """Whether the time-step check found the final champion to be a step artefact."""
        return self.step is not None and self.step.artefact

    @property
    def censored_at(self) -> float:
        """The first-success generation, or +infinity for a run that never succeeded (censored at
        :attr:`last_generation`)."""
        return math.inf if self.first_success is None else float(self.first_success)

    def to_dict(self) -> dict[str, Any]:
        """The result as plain JSON types."""
        return {
            "seed": self.seed, "best_fitness": self.best_fitness, "best_generation": self.best_generation,
            "first_success": self.first_success, "last_generation": self.last_generation,
            "succeeded": self.first_success is not None, "wall_s": self.wall_s,
            "interrupted": self.interrupted, "final": self.final.to_dict(),
            "step_check": None if self.step is None else self.step.to_dict(),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> SeedResult:
        """The result of :meth:`to_dict`, checked; a malformed one raises :class:`ValueError`,
        :class:`KeyError` or :class:`TypeError`."""
        final = Assessment.from_dict(d["final"])
        step = None if d["step_check"] is None else StepCheck.from_dict(d["step_check"], final)
        first = d["first_success"]
        ints = [d["seed"], d["best_generation"], d["last_generation"]] + ([] if first is None else [first])
        if not all(isinstance(x, int) and not isinstance(x, bool) and x >= 0 for x in ints):
            raise ValueError("seed and generations must be integers >= 0")
        if d["succeeded"] != (first is not None):
            raise ValueError("'succeeded' does not follow from 'first_success'")
        return cls(seed=d["seed"], best_fitness=float(d["best_fitness"]), best_generation=d["best_generation"],
                   first_success=first, last_generation=d["last_generation"], wall_s=float(d["wall_s"]),
                   final=final, interrupted=bool(d["interrupted"]), step=step)


def run_seed(
    config: EvolutionConfig, seed: int, out: Path, *, threads: int | None = None, force: bool = False,
    eval_seed_base: int = EVAL_SEED_BASE, eval_trials: int | None = None, dt_check: bool = True,
    seeding: Seeding | None = None, resume: bool = False, progress: bool = True,
) -> SeedResult:
    """Runs ``config`` with ``seed`` into ``out``, then judges the final champion (``out /
    best.json``) on fresh conditions from :func:`eval_seed` with ``eval_trials`` (default: the
    task's :data:`~dnnevo.tasks.DEFAULT_TRIALS`), and, with ``dt_check``, checks it at finer
    steps on the same conditions (:func:`~dnnevo.evaluation.stepcheck.step_check`). With ``seeding`` the
    first population starts from earlier runs' networks (:mod:`dnnevo.evolution.seeding`). With ``resume``
    the run in ``out`` (same config and seed, else a :class:`RunFileError`) is continued from its
    checkpoint, or only judged if it has finished; its wall time then counts every session. A
    run made with fewer generations than ``config`` and otherwise the same config is extended to
    ``config.generations`` (as ``dnnevo resume --generations``). ``progress`` shows the run's
    progress bar."""
    t0 = time.perf_counter()
    if resume:
        found, table = RunDir(out).read_config()
        # A run of fewer generations, otherwise the same, is one this sweep extends.
        extend = found.generations < config.generations
        if extend:
            found = dataclasses.replace(found, generations=config.generations)
        diff = first_difference(config.to_dict(), found.to_dict())
        if diff is None and table.get("seed") != seed:
            diff = ("run.seed", seed, table.get("seed", "(missing)"))
        if diff is not None:
            raise RunFileError(f"{out}: the run's {diff[0]} is {short(diff[2])}; this sweep's is "
                               f"{short(diff[1])}")
        result = resume_run(out, threads=threads, progress=progress,
                            generations=config.generations if extend else None)
        wall = float(result.history["elapsed_s"][-1]) if len(result.history["elapsed_s"]) else 0.0
    else:
        seeds = seeding.networks(config.size, seed) if seeding else None
        info = seeding.info() if seeding else None
        result = evolve(config.task, config, seed=seed, out=out, threads=threads, force=force,
                        founders=seeds, run_info=info, progress=progress)
        wall = time.perf_counter() - t0
    champion = RunDir(out).read_best(config, {"seed": seed})
    fresh = eval_seed(seed, eval_seed_base)
    final = tasks.assess(config, champion, eval_trials, seed=fresh)
    step = (step_check(lambda c: tasks.assess(c, champion, final.trials, seed=fresh), config, base=final)
            if dt_check else None)
    generations = result.history["generation"]
    return SeedResult(
        seed=seed, best_fitness=float(result.best_fitness), best_generation=int(result.best_generation),
        first_success=result.first_success, last_generation=int(generations[-1]) if len(generations) else 0,
        wall_s=round(wall, 2), final=final, interrupted=result.interrupted, step=step,
    )


@dataclass(frozen=True)
class Summary:
    """What a sweep's seeds say together."""

    runs: list[SeedResult]
    succeeded: int
    """Seeds whose run met the task's rule."""
    success_interval: tuple[float, float]
    first_success: stats.Median
    """The median first-success generation; ``math.inf`` is "not reached"."""
    passed: int
    """Final champions whose verdict is pass."""
    pass_interval: tuple[float, float]
    verdicts: dict[Verdict, int]
    checked: int = 0
    """Final champions given the time-step check."""
    artefacts: int = 0
    """Final champions the time-step check found to be step artefacts."""

    @property
    def seeds(self) -> int:
        """How many seeds ran."""
        return len(self.runs)

    def to_dict(self) -> dict[str, Any]:
        """The summary as plain JSON types; "not reached" is null."""
        m = self.first_success

        def gen(x: float) -> int | None:
            return int(x) if math.isfinite(x) else None

        return {
            "seeds": [r.seed for r in self.runs],
            "success": {"k": self.succeeded, "n": self.seeds, "rate": self.succeeded / self.seeds,
                        "interval": list(self.success_interval)},
            "median_first_success": {
                "median": gen(m.median), "reached": m.reached, "interval": [gen(m.lo), gen(m.hi)],
                "censored": m.censored, "method": "censored median (failures count as +infinity "
                "at their last generation; null is not reached), percentile bootstrap",
                "resamples": m.resamples, "bootstrap_seed": m.seed,
            },
            "final_champions_pass": {"k": self.passed, "n": self.seeds, "rate": self.passed / self.seeds,
                                     "interval": list(self.pass_interval), "verdicts": dict(self.verdicts)},
            "step_artefacts": {"k": self.artefacts, "n": self.checked},
            "runs": [r.to_dict() for r in self.runs],
        }

    def csv_text(self) -> str:
        """``summary.csv``: a row per seed, then a row ``all`` that holds each column's aggregate:
        ``succeeded`` the fraction of seeds (with ``succeeded_lo``/``_hi``, its Wilson interval),
        ``first_success`` the median (``not reached`` when censored, with ``first_success_lo``/
        ``_hi``, its bootstrap interval), ``final_k``/``final_n`` the final champions passing (with
        ``final_lo``/``_hi``, its Wilson interval), ``step_artefact`` the count of step artefacts,
        ``wall_s`` the total. ``step_change`` is the largest change of a judged rate at a finer
        step, as a fraction."""
        buf = io.StringIO()
        writer = csv.DictWriter(buf, fieldnames=CSV_COLUMNS, lineterminator="\n", restval="")
        writer.writeheader()
        for r in self.runs:
            w = r.final.weakest
            writer.writerow({
                "seed": r.seed, "best_fitness": r.best_fitness, "best_generation": r.best_generation,
                "first_success": "" if r.first_success is None else r.first_success,
                "last_generation": r.last_generation, "succeeded": int(r.first_success is not None),
                "wall_s": r.wall_s, "eval_seed": r.final.seed, "final_rate": w.name, "final_k": w.k,
                "final_n": w.n, "final_lo": _round(w.interval[0]), "final_hi": _round(w.interval[1]),
                "final_verdict": r.final.verdict,
                "step_change": "" if r.step is None else _round(r.step.max_change),
                "step_artefact": "" if r.step is None else int(r.step.artefact),
            })
        m = self.first_success
        writer.writerow({
            "seed": "all", "first_success": _generation(m.median), "first_success_lo": _generation(m.lo),
            "first_success_hi": _generation(m.hi), "succeeded": _round(self.succeeded / self.seeds),
            "succeeded_lo": _round(self.success_interval[0]), "succeeded_hi": _round(self.success_interval[1]),
            "wall_s": round(sum(r.wall_s for r in self.runs), 2), "final_rate": "champions passing",
            "final_k": self.passed, "final_n": self.seeds, "final_lo": _round(self.pass_interval[0]),
            "final_hi": _round(self.pass_interval[1]),
            "step_artefact": self.artefacts if self.checked else "",
        })
        return buf.getvalue()

    def write(self, out: Path, info: dict[str, Any] | None = None) -> list[Path]:
        """Writes ``summary.csv`` and ``summary.json`` (with ``info``, e.g. the preset, first)
        into ``out``; returns their paths."""
        paths = [out / name for name in SUMMARY_FILES]
        write_atomic(paths[0], self.csv_text())
        write_atomic(paths[1], json.dumps({**(info or {}), **self.to_dict()}, indent=1) + "\n")
        return paths


def _round(x: float) -> float:
    return round(x, 6)


def _generation(x: float) -> str | int:
    return int(x) if math.isfinite(x) else "not reached"


def summarize(runs: Sequence[SeedResult]) -> Summary:
    """The sweep's statistics over ``runs`` (at least one)."""
    if not runs:
        raise InvalidArgumentError("a sweep summary needs at least one run")
    succeeded = sum(r.first_success is not None for r in runs)
    verdicts: dict[Verdict, int] = {"pass": 0, "fail": 0, "undecided": 0}
    for r in runs:
        verdicts[r.final.verdict] += 1
    n = len(runs)
    return Summary(
        runs=list(runs), succeeded=succeeded, success_interval=stats.wilson(succeeded, n),
        first_success=stats.bootstrap_median([r.censored_at for r in runs]),
        passed=verdicts["pass"], pass_interval=stats.wilson(verdicts["pass"], n), verdicts=verdicts,
        checked=sum(r.step is not None for r in runs), artefacts=sum(r.artefact for r in runs),
    )
