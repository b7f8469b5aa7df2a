"""A run folder's figures as PNGs in the folder: the fitness curve and the paper's figures of its
task (``dnnevo plot``, and the report of ``dnnevo reproduce``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from dnnevo import plot, tasks
from dnnevo.closedloop import named
from dnnevo.tasks.user import UserTask
from dnnevo.runs import RunDir, save_figure

__all__ = ["draw_run"]


def draw_run(path: str | Path, *, seed: int = 0, animate: bool = False, fitness: bool = True) -> list[str]:
    """Writes the figures of the run in ``path`` and returns their file names: ``fitness.png``
    (unless ``fitness`` is False), then the task's (sequence: Figs. 4-5; nav1d: Figs. 2-3;
    landmark: top-down views, with ``animate`` a GIF too; a Python task class: its champion's
    episodes, importing the class's module), of trials drawn from ``seed``. Every file of the run
    is checked before any figure is written."""
    run = RunDir(path)
    config, table = run.read_run_config()
    history = run.read_log(config)
    task = tasks.find(config.task)
    if task is None and named.is_closed_loop(config):  # a Python task class: its episodes
        named.check_own_task(config, table)
        task = UserTask(config.task)
    if task is not None:
        run.read_best(config, table)
    written = []
    if fitness:
        arrays = {k: np.array([r[k] for r in history]) for k in history[0]}
        ax = plot.plot_fitness(arrays, title=f"{config.task}: {run.path.name}")
        save_figure(ax.figure, run.path / "fitness.png")
        plot.close(ax.figure)
        written.append("fitness.png")
    if task is not None:
        written += task.draw(run, config, seed, animate=animate)
    return written
