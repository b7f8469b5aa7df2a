"""The ``dnnevo`` command's landmark-recognition parts: the first lines of ``evaluate`` (with
``--robot-like``) and ``plot`` for ``landmark`` runs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from dnnevo.tasks import landmark
from dnnevo.evaluation.assessment import Assessment
from dnnevo.config import EvolutionConfig
from dnnevo.runs.rundir import RunDir, save_figure, write_atomic_with


def preface(where: Path, a: Assessment) -> list[str]:
    """What ``evaluate`` ran on a ``landmark`` run, and the confusion matrix."""
    kind = ("robot-like (sonar noise, specular misses, jittered room)" if a.details["robot_like"]
            else "ideal")
    (p, q), (r, s) = a.details["confusion"]
    return [
        f"{where}: champion on {a.trials} fresh {kind} trials per landmark (seed {a.seed}).",
        f"{'':>12} {'said 1':>7} {'said 2':>7}",
        f"{'landmark 1':>12} {p:>7} {q:>7}",
        f"{'landmark 2':>12} {r:>7} {s:>7}",
    ]


def plot(run: RunDir, config: EvolutionConfig, seed: int, *, animate: bool = False) -> list[str]:
    """``dnnevo plot`` for a ``landmark`` run: Fig. 1 (sonar input and every neuron over a
    landmark-1 and a landmark-2 trial), a top-down view of both trials and, with ``animate``, a
    GIF of the landmark-2 trial."""
    import matplotlib.pyplot as plt

    from dnnevo.plot import plot_landmark_world, plot_traces

    champion = run.read_best(config, run.read_config()[1])
    classifier = int(config.task_json().get("classifier", 0))
    records = [landmark.record(config, champion, n, seed=seed, trial=n) for n in (1, 2)]
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.5), layout="constrained")
    for ax, rec in zip(axes, records, strict=True):
        labels = [f"neuron {i}" for i in range(rec.outputs.shape[1])]
        labels[classifier] = f"classifier ({classifier})"
        plot_traces({"sonar": rec.input}, rec.outputs, ax, labels=labels, highlight=classifier,
                    title=f"landmark {rec.landmark}: said {1 if rec.classification < 0.5 else 2} "
                          f"(f = {rec.classification:.2f})")
    save_figure(fig, run.path / "fig1-traces.png")
    plt.close(fig)
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), layout="constrained")
    for ax, rec in zip(axes, records, strict=True):
        plot_landmark_world(rec, ax, title=f"landmark {rec.landmark}: path and sonar echoes")
    save_figure(fig, run.path / "world.png")
    plt.close(fig)
    written = ["fig1-traces.png", "world.png"]
    if animate:
        _animate(records[1], classifier, run.path / "trial-landmark2.gif")
        written.append("trial-landmark2.gif")
    return written


FRAME_STEPS = 10
"""Robot steps per GIF frame (1 s of simulated time at the default 0.1 s step)."""


def _animate(rec: landmark.Record, classifier: int, path: Any) -> None:
    """A GIF of one trial: the robot, its sonar echo and the classifier's output so far.

    The figure is drawn once; each frame redraws only the three moving artists over a copy of
    it, as matplotlib's blitting does, which is many times quicker than drawing every frame whole.
    """
    import matplotlib.pyplot as plt
    import numpy as np
    from PIL import Image

    from dnnevo.plot import plot_landmark_world

    fig, (top, trace) = plt.subplots(2, 1, figsize=(6, 6.5), height_ratios=[3, 1],
                                     layout="constrained")
    plot_landmark_world(rec, top, title=f"landmark {rec.landmark}")
    (robot,) = top.plot([], [], "o", ms=12, color="tab:blue", alpha=0.6, animated=True)
    (beam,) = top.plot([], [], "-", color="tab:red", lw=1, animated=True)
    out = rec.outputs[:, classifier]
    (line,) = trace.plot([], [], color="tab:red", animated=True)
    trace.axhline(0.5, color="0.3", lw=0.7, ls=":")
    trace.set_xlim(0, len(out))
    trace.set_ylim(-0.05, 1.05)
    trace.set_xlabel("time step")
    trace.set_ylabel("classifier")

    fig.canvas.draw()  # lays the figure out and draws everything but the moving artists
    fig.set_layout_engine("none")
    background = fig.canvas.copy_from_bbox(fig.bbox)  # type: ignore[attr-defined]
    images = []
    for frame in range(len(out) // FRAME_STEPS):
        k = min(frame * FRAME_STEPS, len(out) - 1)
        x, y = rec.poses[k, :2]
        robot.set_data([x], [y])
        ex, ey = rec.echoes[k]
        beam.set_data([x, ex], [y, ey])
        line.set_data(range(k + 1), out[: k + 1])
        fig.canvas.restore_region(background)  # type: ignore[attr-defined]
        for artist in (robot, beam, line):
            fig.draw_artist(artist)
        rgba = np.asarray(fig.canvas.buffer_rgba())  # type: ignore[attr-defined]
        images.append(Image.fromarray(rgba).convert("RGB"))
    write_atomic_with(path, lambda tmp: images[0].save(
        tmp, format="GIF", save_all=True, append_images=images[1:], duration=100, loop=0), suffix=".gif")
    plt.close(fig)
