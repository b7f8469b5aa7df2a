"""A run folder's figures as PNGs in the folder: the fitness curve and the paper's figures of its
task (``dnnevo plot``, and the report of ``dnnevo reproduce``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from dnnevo.runs.rundir import RunDir, save_figure

__all__ = ["draw_run"]


def draw_run(path: str | Path, *, seed: int = 0, animate: bool = False) -> list[str]:
    """Writes the figures of the run in ``path`` and returns their file names: ``fitness.png``,
    then the task's (sequence: Figs. 4-5; nav1d: Figs. 2-3; landmark: top-down views, with
    ``animate`` a GIF too), of trials drawn from ``seed``. Every file of the run is checked before
    any figure is written."""
    import matplotlib.pyplot as plt

    from dnnevo.cli import landmark_parts as _cli_landmark
    from dnnevo.cli import nav1d_parts as _cli_nav1d
    from dnnevo.cli import sequence_parts as _cli_sequence
    from dnnevo.plot import plot_fitness

    run = RunDir(path)
    config, table = run.read_config()
    history = run.read_log(config)
    if config.task in ("sequence", "nav1d", "landmark"):
        run.read_best(config, table)
    arrays = {k: np.array([r[k] for r in history]) for k in history[0]}
    ax = plot_fitness(arrays, title=f"{config.task}: {run.path.name}")
    save_figure(ax.figure, run.path / "fitness.png")
    plt.close(ax.figure)
    written = ["fitness.png"]
    if config.task == "sequence":
        written += _cli_sequence.plot(run, config, seed)
    if config.task == "nav1d":
        written += _cli_nav1d.plot(run, config, seed)
    if config.task == "landmark":
        written += _cli_landmark.plot(run, config, seed, animate=animate)
    return written
