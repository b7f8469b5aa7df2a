"""Landmark recognition (paper §3): recorded robot trials and the assessment, robot-like or not,
for networks evolved on the ``landmark`` task.

A trial (see ``crates/tasks/src/landmark/mod.rs``): a Nomad-200-like robot starts at a random
pose in a 6 m x 5 m room, finds a wall and follows it counter-clockwise; its left sonar's range
``d`` feeds the network as ``min(1, 0.5 / d)`` every 0.1 s. After 45 s the classifier neuron's
output ``f`` is read: ``f < 0.5`` means landmark 1 (two crates pushed together), else landmark 2
(the crates 0.6 m apart).

Success rule: at least 95% of fresh trials classified right. ``robot_like=True`` adds sonar
noise, specular misses and a jittered room: our stand-in for the paper's real-robot test.

>>> from dnnevo.tasks import landmark
>>> world = landmark.default_world(2)
>>> world["room"], len(world["boxes"])
([6.0, 5.0], 2)
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from dnnevo import _core, plot
from dnnevo._checks import bounded_count, builtin, nonnegative
from dnnevo.config import EvolutionConfig
from dnnevo.errors import InvalidArgumentError
from dnnevo.evaluation.assessment import INDEPENDENT, Assessment, combine, rate
from dnnevo.runs import RunDir, save_figure, write_atomic_with
from dnnevo.tasks.defaults import assess_extra, extra_lines, overall, rate_column


if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["ANALYSIS_CONDITIONS", "DEFAULT_TRIALS", "INPUT_NAMES", "MAIN_INPUT", "OUTPUT_NEURON", "FRAME_STEPS", "NAME", "ROBOT_LIKE", "THRESHOLD", "UNIT", "Record", "params",
           "assess", "cast_rays", "default_world", "draw", "assess_extra", "extra_lines", "judge",
           "overall", "preface", "rate_column", "record", "recorded_trials"]

NAME = "landmark"
"""The task's name in a config."""

THRESHOLD: float = _core.LANDMARK_SUCCESS_RATE
"""The fraction of fresh trials, over both landmarks, that must be classified right:
the core's own number
(``LANDMARK_SUCCESS_RATE`` of the binding)."""

DEFAULT_TRIALS = 500
"""``dnnevo assess``'s default: trials per landmark (1000 robot trials take 1.2-1.7 s on one
core)."""

UNIT = "trials per landmark"
"""What a trial count counts."""

ROBOT_LIKE = True
"""Landmark recognition has a robot-like test: sonar noise, specular misses, a jittered room."""

INPUT_NAMES = ["sonar input"]
"""The network's inputs, in order, as the analysis names them."""

ANALYSIS_CONDITIONS: dict[str, list[float]] = {"off": [0.0], "sonar 1": [1.0]}
"""The constant input conditions ``dnnevo analyze`` finds the attractors of, by default."""

MAIN_INPUT = 0
"""The input a bifurcation sweep varies by default: the one the task's behaviour turns on."""

OUTPUT_NEURON = 0
"""The neuron whose firing rate is the task's answer (``task_params.classifier`` overrides it)."""


Record = _core.LandmarkRecord
"""One trial, step by step, as the core records it (arrays of length T; ``outputs`` is (T, N),
``poses`` (T, 3) as x, y, heading, ``echoes`` (T, 2) with NaN where nothing echoed; the trial's
``world`` and the classifier's final output ``classification``)."""


def _task(config: EvolutionConfig) -> _core.LandmarkTask:
    return builtin(config, NAME, _core.LandmarkTask)


def params(config: EvolutionConfig) -> dict[str, Any]:
    """The config's task settings with every default filled in, as the core reads them."""
    return _task(config).params()


def _landmark(n: int) -> int:
    if n not in (1, 2) or isinstance(n, bool):
        raise InvalidArgumentError(f"landmark is {n!r}; it must be 1 or 2")
    return n


def record(
    config: EvolutionConfig, net: _core.Network, landmark: int, *, seed: int = 0, trial: int = 0,
    robot_like: bool = False,
) -> Record:
    """Runs ``net`` through fresh trial ``trial`` of ``seed`` with ``landmark`` (1 or 2)."""
    _landmark(landmark)
    return _task(config).record(net, nonnegative("landmark", landmark), nonnegative("seed", seed),
                                nonnegative("trial", trial), robot_like)


def assess(
    config: EvolutionConfig, net: _core.Network, per_landmark: int, seed: int, *,
    robot_like: bool = False,
) -> dict[str, Any]:
    """Judges ``net`` on ``per_landmark`` fresh trials of each landmark: ``{"confusion"
    (rows: true landmark 1, 2; columns: answer 1, 2), "rate", "success", "trials"}``."""
    return _task(config).assess(net, bounded_count("per_landmark", per_landmark), nonnegative("seed", seed),
                                robot_like)


def default_world(n: int) -> dict[str, Any]:
    """The shipped world of landmark ``n`` (1 or 2) as a dict (room, boxes, start region); pass
    a changed copy as ``task_params["landmark1"]`` or ``["landmark2"]``."""
    result: dict[str, Any] = _core.sim2d_landmark_world(_landmark(n))
    return result


def cast_rays(
    world: dict[str, Any], origins: npt.ArrayLike, directions: npt.ArrayLike, max_distance: float = 6.5
) -> npt.NDArray[np.float64]:
    """Distance along each ray (rows of the (K, 2) ``origins`` and ``directions``) to the
    nearest wall or box of ``world``, or ``max_distance`` when nothing is nearer."""
    o = np.ascontiguousarray(origins, dtype=float)
    d = np.ascontiguousarray(directions, dtype=float)
    if o.ndim != 2 or o.shape[1:] != (2,) or o.shape != d.shape:
        raise InvalidArgumentError(
            f"origins has shape {o.shape} and directions {d.shape}; both must be (K, 2)")
    return _core.sim2d_cast_rays(dict(world), o, d, float(max_distance))


def judge(config: EvolutionConfig, net: _core.Network, trials: int, seed: int, *,
          robot_like: bool = False) -> Assessment:
    """``net`` judged on ``trials`` fresh trials per landmark drawn from ``seed`` (robot-like
    ones with ``robot_like``): the overall rate is judged against :data:`THRESHOLD`, each
    landmark's own rate is shown."""
    report = assess(config, net, trials, seed, robot_like=robot_like)
    (a, b), (c, d) = report["confusion"]
    overall = rate("overall", a + d, a + b + c + d, threshold=THRESHOLD, per_trial=2.0)
    rates = [rate("landmark 1", a, a + b), rate("landmark 2", d, c + d), overall]
    return Assessment(
        task="landmark", trials=trials, unit=UNIT, seed=seed, rates=rates,
        verdict=combine([r.verdict for r in rates if r.verdict is not None]),
        method=INDEPENDENT + "; only the overall rate is judged",
        details={"confusion": report["confusion"], "robot_like": robot_like}, report=report,
    )


def preface(where: Path, a: Assessment) -> list[str]:
    """What ``assess`` ran on a ``landmark`` run, and the confusion matrix."""
    kind = ("robot-like (sonar noise, specular misses, jittered room)" if a.details["robot_like"]
            else "ideal")
    (p, q), (r, s) = a.details["confusion"]
    return [
        f"{where}: champion on {a.trials} fresh {kind} trials per landmark (seed {a.seed}).",
        f"{'':>12} {'said 1':>7} {'said 2':>7}",
        f"{'landmark 1':>12} {p:>7} {q:>7}",
        f"{'landmark 2':>12} {r:>7} {s:>7}",
    ]


def draw(run: RunDir, config: EvolutionConfig, seed: int, *, animate: bool = False) -> list[str]:
    """``dnnevo plot`` for a ``landmark`` run: Fig. 1 (sonar input and every neuron over a
    landmark-1 and a landmark-2 trial), a top-down view of both trials and, with ``animate``, a
    GIF of the landmark-2 trial."""
    champion = run.read_best(config, run.read_config()[1])
    classifier = int(params(config)["classifier"])
    records = [record(config, champion, n, seed=seed, trial=n) for n in (1, 2)]
    fig, axes = plot.subplots(1, 2, figsize=(12, 5.5), layout="constrained")
    for ax, rec in zip(axes, records, strict=True):
        labels = [f"neuron {i}" for i in range(rec.outputs.shape[1])]
        labels[classifier] = f"classifier ({classifier})"
        plot.plot_traces({"sonar": rec.input}, rec.outputs, ax, labels=labels, highlight=classifier,
                    title=f"landmark {rec.landmark}: said {1 if rec.classification < 0.5 else 2} "
                          f"(f = {rec.classification:.2f})")
    save_figure(fig, run.path / "fig1-traces.png")
    plot.close(fig)
    fig, axes = plot.subplots(1, 2, figsize=(12, 5), layout="constrained")
    for ax, rec in zip(axes, records, strict=True):
        plot_world(rec, ax, title=f"landmark {rec.landmark}: path and sonar echoes")
    save_figure(fig, run.path / "world.png")
    plot.close(fig)
    written = ["fig1-traces.png", "world.png"]
    if animate:
        _animate(records[1], classifier, run.path / "trial-landmark2.gif")
        written.append("trial-landmark2.gif")
    return written


FRAME_STEPS = 10
"""Robot steps per GIF frame (1 s of simulated time at the default 0.1 s step)."""


def _animate(rec: Record, classifier: int, path: Any) -> None:
    """A GIF of one trial: the robot, its sonar echo and the classifier's output so far.

    The figure is drawn once; each frame redraws only the three moving artists over a copy of
    it, as matplotlib's blitting does, which is many times quicker than drawing every frame whole.
    """
    from PIL import Image  # here, not at the top: only a GIF needs Pillow (matplotlib's own dependency)


    fig, (top, trace) = plot.subplots(2, 1, figsize=(6, 6.5), height_ratios=[3, 1],
                                     layout="constrained")
    plot_world(rec, top, title=f"landmark {rec.landmark}")
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
    plot.close(fig)


def recorded_trials(config: EvolutionConfig, net: _core.Network, *,
                    seed: int) -> list[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
    """One trial per landmark drawn from ``seed``, each as (firing rates (T, N), sonar input
    (T, 1)), for the dynamical analysis."""
    out = []
    for which in (1, 2):
        r = record(config, net, which, seed=seed)
        out.append((r.outputs, r.input.reshape(-1, 1)))
    return out


def plot_world(
    record: Record, ax: Axes | None = None, *, title: str | None = None
) -> Axes:
    """A top-down view of a landmark trial: the room's walls, the boxes, the robot's path (start
    marked) and where the sonar's echoes landed."""
    ax = plot.axes(ax)
    Rectangle = plot.pyplot().Rectangle
    w, h = record.world["room"]
    ax.add_patch(Rectangle((0, 0), w, h, fill=False, lw=2.5, color="0.2"))
    for box in record.world["boxes"]:
        (cx, cy), (sx, sy) = box["center"], box["size"]
        ax.add_patch(Rectangle((cx - sx / 2, cy - sy / 2), sx, sy, angle=box.get("angle_deg", 0.0),
                               rotation_point="center", color="tab:brown", alpha=0.8))
    ax.plot(record.poses[:, 0], record.poses[:, 1], color="tab:blue", lw=1.2, label="robot path")
    ax.plot(*record.poses[0, :2], marker="o", color="tab:blue", ls="none", label="start")
    hit = ~np.isnan(record.echoes[:, 0])
    ax.scatter(record.echoes[hit, 0], record.echoes[hit, 1], s=4, color="tab:red", alpha=0.5,
               label="sonar echoes")
    ax.set_xlim(-0.3, w + 0.3)
    ax.set_ylim(-0.3, h + 0.3)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(loc="upper right", fontsize=7)
    if title:
        ax.set_title(title, fontsize=10)
    return ax
