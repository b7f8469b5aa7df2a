"""The ``dnnevo show`` command, and the outcome of a run that ``run``, ``resume`` and ``show`` all
print, in the same words:

- the **champion**: the run's best network so far, the one ``best.json`` holds, with its training
  fitness and the generation it was scored in, and, when the task has validation trials, its
  validation rate and score (log.csv's ``validation_rate`` and ``validation_score``), by which it
  was chosen;
- the **success rule**: whether, and from which generation, the champion met the task's success
  rule on fresh trials during the run (log.csv's ``champion_success``);
- **gen best** and **gen mean**: the training fitness of one generation (log.csv's ``best`` and
  ``mean``); without elitism the best network is not kept, so gen best may drop while the
  champion stays;
- a **warning** when every network scored the same in every generation;
- the **next** command.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dnnevo import plot
from dnnevo.config import EvolutionConfig
from dnnevo.closedloop import named
from dnnevo.config import PYTHON_TASK
from dnnevo.closedloop.fitness import SUCCESS_EPISODES
from dnnevo.cli.outputs import try_write
from dnnevo.cli.sweep import stored_summary
from dnnevo.runs import RunDir, save_figure

__all__ = ["blind_line", "champion_line", "next_line", "outcome", "show", "success_line"]


def champion_line(fitness: float | None, generation: int | None,
                  validation: tuple[float, float] | None) -> str:
    """``champion (best.json): fitness 0.8621 (generation 0); validation rate 1.000, score 0.8554``."""
    if fitness is None or generation is None:
        return "champion (best.json): no fitness recorded in its meta"
    text = f"champion (best.json): fitness {fitness:.4f} (generation {generation})"
    if validation is not None:
        text += f"; validation rate {validation[0]:.3f}, score {validation[1]:.4f}"
    return text


def success_line(task: str, success: Sequence[float], *, closed_loop: bool = False) -> str:
    """Whether the champion met the task's success rule during the run, from log.csv's
    ``champion_success`` column (one value per generation: 1, 0 or nan). ``closed_loop``: the
    run's task is a Python task class (:mod:`dnnevo.closedloop.named`), checked by its own rule
    when it has one."""
    if task.startswith(PYTHON_TASK) and not closed_loop:
        return "success rule: none (a Python fitness function has no success rule)"
    judged = [s for s in success if not math.isnan(s)]
    if not judged and closed_loop and success:
        # A run checks a task class's champion every generation; NaN means it has no rule.
        return ("success rule: none (the task class has no success_rate and success method; one "
                "added makes another task, so run again with it: docs/closed-loop.md#a-success-rule)")
    if not judged:
        return "success rule: not checked in this run (champion_success is nan in log.csv)"
    # A task class's champion is checked on a few episodes only: say so, as assess will differ.
    fresh = f"{SUCCESS_EPISODES} fresh episodes" if closed_loop else "fresh trials"
    met = [g for g, s in enumerate(success) if s == 1.0]
    if not met:
        n = len(success)
        return (f"success rule: not met in {n} generation{'s' * (n != 1)} (the champion failed it "
                f"on {fresh})")
    if success[-1] == 1.0:
        more = closed_loop and not task.startswith(f"{PYTHON_TASK}__main__.")  # assess can import it
        return (f"success rule: met at generation {met[0]} (the champion passed it on {fresh}"
                f"{'; dnnevo assess judges it on more, with an interval' if more else ''})")
    return (f"success rule: met at generation {met[0]}, but the final champion fails it on {fresh}")


def next_line(path: Path, config: EvolutionConfig, success: Sequence[float], *,
              interrupted: bool = False) -> str | None:
    """The command to run next on the run folder ``path``, from log.csv's ``champion_success``
    column ``success`` (one value per generation done); None for a Python fitness function's
    run, which the command line can neither resume nor judge (a Python task class's run it can).

    Whether a task class has a success rule is read from that column (a run checks its champion
    every generation, and writes NaN when the class has no rule), never by importing the class:
    ``show`` runs no code of the run's task."""
    if config.task.startswith(PYTHON_TASK) and not named.is_closed_loop(config):
        return None
    if config.task.startswith(f"{PYTHON_TASK}__main__."):
        return (f"next: {config.task} was defined in a script, which the command line cannot "
                "import: resume, judge or draw it from Python (dnnevo.resume, rollout with "
                "purpose=\"evaluate\"), or move the class into a module (docs/closed-loop.md)")
    judge, verb = f"dnnevo assess {path}", "judge"
    ruleless = bool(success) and all(math.isnan(s) for s in success)
    if config.task.startswith(PYTHON_TASK) and ruleless:
        judge, verb = f"dnnevo plot {path}", "draw"
    if (pid := RunDir(path).writer()) is not None:
        return (f"next: the run is going on (PID {pid}); show it again later, or {judge} to {verb} "
                "the champion so far")
    if interrupted or len(success) < config.generations:
        return (f"next: dnnevo resume {path} to run the rest of its {config.generations} generations, "
                f"or {judge} to {verb} the champion so far")
    if verb == "draw":
        return (f"next: {judge}   (draws the champion on fresh episodes; dnnevo assess needs a "
                "success rule, written before the run: docs/closed-loop.md#a-success-rule)")
    return f"next: {judge}   (judges the champion on fresh trials, with 95% intervals and a verdict)"


def blind_line(best: Sequence[float], worst: Sequence[float]) -> str | None:
    """A warning when every network scored the same in every generation (log.csv's ``best``
    and ``min`` equal in every row; its ``std`` of equal values need not be exactly 0):
    selection then chose at random, which a task whose fitness cannot tell networks apart (a
    reward that never changes) gives without any error."""
    if not best or any(b != w for b, w in zip(best, worst, strict=True)):
        return None
    n = len(best)
    when = f"every one of its {n} generations" if n > 1 else "its only generation"
    return (f"warning: every network scored the same in {when} (best = min in log.csv): the "
            "fitness does not tell networks apart, so selection was blind")


def outcome(path: Path, config: EvolutionConfig, champion: Mapping[str, Any],
            success: Sequence[float], *, interrupted: bool = False,
            best: Sequence[float] = (), worst: Sequence[float] = ()) -> list[str]:
    """The champion, the success rule, a warning when the fitness told no networks apart
    (:func:`blind_line`, from the generations' ``best`` and ``worst`` fitness) and the next
    command, as ``run``, ``resume`` and ``show`` end. ``champion`` is best.json's meta (``fitness``, ``generation``
    and, when validated, ``validation_rate`` and ``validation_score``)."""
    validation = None
    if "validation_rate" in champion and "validation_score" in champion:
        validation = (float(champion["validation_rate"]), float(champion["validation_score"]))
    fitness, generation = champion.get("fitness"), champion.get("generation")
    lines = [champion_line(None if fitness is None else float(fitness),
                           None if generation is None else int(generation), validation),
             success_line(config.task, success, closed_loop=named.is_closed_loop(config))]
    blind = blind_line(best, worst)
    step = next_line(path, config, success, interrupted=interrupted)
    return [*lines, *(x for x in (blind, step) if x is not None)]


def show(args: argparse.Namespace) -> int:
    """``dnnevo show``: the run's size and time, its champion, the success rule, the last
    generation, and fitness.png; for a sweep's folder, the sweep's statistics over its finished
    seeds."""
    summary = stored_summary(args.dir) if not (args.dir / "config.toml").exists() else None
    if summary is not None:  # a sweep's folder: its statistics, as the sweep printed them
        print("\n".join(summary))
        return 0
    run = RunDir(args.dir)
    config, table = run.read_run_config()
    history = run.read_log(config)
    champion = run.read_best(config, table)
    last = history[-1]
    print(f"{args.dir}: task {config.task}, population {config.population}, "
          f"{len(history)}/{config.generations} generations, {last['elapsed_s']:.1f} s")
    lines = outcome(args.dir, config, champion.meta, [r["champion_success"] for r in history],
                    best=[r["best"] for r in history], worst=[r["min"] for r in history])
    print("\n".join(lines[:2]))
    print(f"last generation ({int(last['generation'])}): gen best {last['best']:.4f}, "
          f"gen mean {last['mean']:.4f}")
    arrays = {k: np.array([r[k] for r in history]) for k in history[0]}
    ax = plot.plot_fitness(arrays, title=f"{config.task}: {args.dir.name}")
    if try_write(lambda: save_figure(ax.figure, run.path / "fitness.png")):
        print(f"wrote {run.path / 'fitness.png'}")
    for line in lines[2:]:
        print(line)
    return 0
