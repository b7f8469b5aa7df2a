"""The ``dnnevo`` command's landmark-recognition parts: ``evaluate`` (with ``--robot-like``) and
``plot`` for ``landmark`` runs."""

from __future__ import annotations

import argparse
from typing import Any

from dnnevo import landmark
from dnnevo.config import EvolutionConfig
from dnnevo.rundir import RunDir


def evaluate(args: argparse.Namespace, config: EvolutionConfig, champion: Any, seed: int) -> int:
    """``dnnevo evaluate`` for a ``landmark`` run: a confusion matrix on fresh trials."""
    report = landmark.assess(config, champion, args.trials, seed, robot_like=args.robot_like)
    kind = ("robot-like (sonar noise, specular misses, jittered room)" if args.robot_like
            else "ideal")
    print(f"{args.dir}: champion on {args.trials} fresh {kind} trials per landmark (seed {seed}).")
    (a, b), (c, d) = report["confusion"]
    print(f"{'':>12} {'said 1':>7} {'said 2':>7} {'right':>7}")
    print(f"{'landmark 1':>12} {a:>7} {b:>7} {a / max(a + b, 1):>7.1%}")
    print(f"{'landmark 2':>12} {c:>7} {d:>7} {d / max(c + d, 1):>7.1%}")
    verdict = "SUCCESS" if report["success"] else "failure"
    print(f"overall: {report['rate']:.1%} right (success needs >= 95%): {verdict}")
    return 0 if report["success"] else 1


def plot(run: RunDir, config: EvolutionConfig, seed: int) -> list[str]:
    """``dnnevo plot`` for a ``landmark`` run: Fig. 1 (sonar input and every neuron over a
    landmark-1 and a landmark-2 trial) and a top-down view of both trials."""
    import matplotlib.pyplot as plt

    from dnnevo import _core
    from dnnevo.plot import plot_landmark_world, plot_traces

    champion = _core.Network.load(run.best)
    classifier = int(config.task_json().get("classifier", 0))
    records = [landmark.record(config, champion, n, seed=seed, trial=n) for n in (1, 2)]
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.5), layout="constrained")
    for ax, rec in zip(axes, records, strict=True):
        labels = [f"neuron {i}" for i in range(rec.outputs.shape[1])]
        labels[classifier] = f"classifier ({classifier})"
        plot_traces({"sonar": rec.input}, rec.outputs, ax, labels=labels, highlight=classifier,
                    title=f"landmark {rec.landmark}: said {1 if rec.classification < 0.5 else 2} "
                          f"(f = {rec.classification:.2f})")
    fig.savefig(run.path / "fig1-traces.png", dpi=120)
    plt.close(fig)
    fig, axes = plt.subplots(1, 2, figsize=(12, 5), layout="constrained")
    for ax, rec in zip(axes, records, strict=True):
        plot_landmark_world(rec, ax, title=f"landmark {rec.landmark}: path and sonar echoes")
    fig.savefig(run.path / "world.png", dpi=120)
    plt.close(fig)
    return ["fig1-traces.png", "world.png"]
