"""The ``dnnevo`` command's one-dimensional navigation parts: the first lines of ``evaluate``
and ``plot`` for ``nav1d`` runs, and the ``nav1d-system`` command (the integrated system of paper
§4.2)."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dnnevo.tasks import nav1d
from dnnevo.evaluation.assessment import Assessment
from dnnevo.config import EvolutionConfig
from dnnevo.runs.rundir import RunDir, save_figure, write_atomic

SYSTEM_EXAMPLE = (
    "example: dnnevo nav1d-system --classifier runs/nav1d-classifier-seed0 "
    "--far runs/nav1d-far-seed0 --near runs/nav1d-near-seed0 --out runs/nav1d-system"
)


def _rate_table(episodes: Sequence[dict[str, Any]], first_scored: int) -> list[str]:
    """Goal rate by environment type and trial index, one line per environment type."""
    return _by_trial(nav1d.goal_rates(episodes), episodes, first_scored)


def _by_trial(rates: dict[str, Any], episodes: Sequence[dict[str, Any]], first_scored: int) -> list[str]:
    """A table of ``rates`` by environment type and trial index, one line per environment type."""
    k = len(rates["all"])
    lines = [f"{'environment':>12} {'chains':>6}  " + " ".join(f"{'trial ' + str(t + 1):>8}" for t in range(k))]
    for env in ("far", "near", "all"):
        count = sum(1 for e in episodes if env in ("all", e["environment"]))
        if count:
            cells = " ".join(f"{r:>8.1%}" for r in rates[env])
            lines.append(f"{env:>12} {count:>6}  {cells}")
    if first_scored:
        lines.append(f"(trial 1 is for learning; trials {first_scored + 1}.. are scored)")
    return lines


def preface(where: Path, a: Assessment) -> list[str]:
    """What ``evaluate`` ran on a ``nav1d`` run, and the rates by case (``classify``) or by
    environment type and trial index."""
    objective = a.details["objective"]
    episodes = a.report["episodes"]
    lines = [f"{where}: champion ({objective}) on {a.trials} fresh chains (seed {a.seed})."]
    if objective == "classify":
        lines.append("A trial is right when f(v_C) >= 0.5 exactly in landmark-near environments.")
        lines.append(f"{'environment':>12} {'goal':>6} {'trials':>6} {'right':>7} {'mean f(v_C)':>12}")
        for env, goal in nav1d.CASES:
            picked = [e for e in episodes if e["environment"] == env
                      and e["conditions"][0]["goal"] == goal]
            if picked:
                f = np.array([np.nan if e["classification"][0] is None else e["classification"][0]
                              for e in picked])
                right = (f >= 0.5) if env == "near" else (f < 0.5)
                lines.append(f"{env:>12} {goal:>6} {len(picked):>6} {right.mean():>7.1%} {f.mean():>12.3f}")
    else:
        lines += _rate_table(episodes, 1 if objective == "single" else 0)
    if objective == "single" and a.details.get("classify_weight", 0.0) > 0:
        lines.append("The classifier (shaped by classify_weight): trials after which it names the "
                     "environment right (f(v_C) >= 0.5 exactly in landmark-near chains).")
        lines += _by_trial(nav1d.classifier_rates(episodes), episodes, 0)
    return lines


def plot(run: RunDir, config: EvolutionConfig, seed: int) -> list[str]:
    """``dnnevo plot`` for a ``nav1d`` run: Fig. 2 (x(t) in the four cases) and, for a network with
    a classifier, Fig. 3 (its traces in a landmark-near and a landmark-far trial)."""
    import matplotlib.pyplot as plt

    from dnnevo.plot import plot_nav1d_traces

    champion = run.read_best(config, run.read_config()[1])
    params = config.task_json()
    k = params.get("trials_per_environment", 5) if params.get("objective") == "single" else 1
    records = [nav1d.record(config, champion, [c] * k) for c in nav1d.cases(config)]
    _fig2(records, params, f"{run.path.name}: the champion in environments A-D", run.path / "fig2-paths.png")
    written = ["fig2-paths.png"]
    if params.get("objective") in ("classify", "single"):
        classifier = int(params.get("classifier", 2))
        motors = (int(params.get("left_motor", 0)), int(params.get("right_motor", 1)))
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), layout="constrained")
        for ax, (env, goal) in zip(axes, [("near", "left"), ("far", "right")], strict=True):
            cond = next(c for c in nav1d.cases(config) if (c.environment, c.goal) == (env, goal))
            rec = nav1d.record(config, champion, [cond])
            plot_nav1d_traces(rec, ax, classifier=classifier, motors=motors, title=(
                f"landmark-{env}, goal {goal}: "
                f"{'reached' if rec.reached[0] else 'missed'}, f(v_C) = {rec.classification[0]:.2f}"))
        save_figure(fig, run.path / "fig3-classifier.png")
        plt.close(fig)
        written.append("fig3-classifier.png")
    return written


def _fig2(records: Sequence[nav1d.Record], params: dict[str, Any], title: str, path: Path) -> None:
    import matplotlib.pyplot as plt

    from dnnevo.plot import plot_nav1d_path

    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), layout="constrained", sharey=True)
    for ax, rec, letter in zip(axes.T.flat, records, "ABCD", strict=True):
        c = rec.conditions[0]
        plot_nav1d_path(rec, ax, half_length=float(params.get("half_length", 20.0)),
                        landmark_width=float(params.get("landmark_width", 4.0)),
                        title=f"{letter}: landmark-{c.environment}, goal {c.goal}")
    fig.suptitle(title)
    save_figure(fig, path)
    plt.close(fig)


def add_system_parser(sub: Any) -> None:
    """Adds the ``nav1d-system`` command."""
    p = sub.add_parser("nav1d-system", help="assemble and test the integrated navigation system",
                       description="The paper's §4.2 system: the classifier drives the first trial "
                                   "in an environment; its output picks the far or the near network "
                                   "for the later trials.",
                       epilog=SYSTEM_EXAMPLE)
    p.add_argument("--classifier", type=Path, required=True, metavar="RUN", help="a nav1d-classifier run")
    p.add_argument("--far", type=Path, required=True, metavar="RUN", help="a nav1d-far run")
    p.add_argument("--near", type=Path, required=True, metavar="RUN", help="a nav1d-near run")
    p.add_argument("--environments", type=int, default=100, help="fresh random environments (default 100)")
    p.add_argument("--trials", type=int, default=5, help="trials per environment (default 5)")
    p.add_argument("--seed", type=int, default=0, help="seed of the environments (default 0)")
    p.add_argument("--reset-each-trial", action="store_true",
                   help="reset the picked network's state at each trial (the paper keeps it)")
    p.add_argument("--out", type=Path, help="folder for report.json and fig2-system.png")


def system(args: argparse.Namespace) -> int:
    """``dnnevo nav1d-system``."""
    from dnnevo.errors import ConfigError
    from dnnevo.evaluation.stats import wilson

    if args.environments < 1 or args.trials < 1 or args.seed < 0:
        raise ConfigError("--environments and --trials must be >= 1 and --seed >= 0")
    parts = [nav1d.load_part(p, role) for p, role in
             [(args.classifier, "--classifier"), (args.far, "--far"), (args.near, "--near")]]
    persist = not args.reset_each_trial
    report = nav1d.system_assess(parts[0], parts[1], parts[2], environments=args.environments, trials=args.trials,
                                 seed=args.seed, persist_state=persist)
    state = "persisting" if persist else "reset each trial"
    print(f"integrated system on {args.environments} fresh environments x {args.trials} trials "
          f"(seed {args.seed}; state {state}): goal rate by trial")
    for line in _rate_table(report["episodes"], 0):
        print(line)
    envs, trials = args.environments, args.environments * args.trials
    right = report["classification_rate"] * envs
    lo, hi = wilson(right, envs)
    print(f"classifier right in {report['classification_rate']:.1%} of environments "
          f"(95% interval {lo:.1%}-{hi:.1%})")
    # The trials of one environment share the system's state, so count environments, not trials.
    lo, hi = wilson(report["goal_rate"] * envs, envs)
    print(f"goal reached in {report['goal_rate']:.1%} of {trials} trials (95% interval "
          f"{lo:.1%}-{hi:.1%}, clustered by environment: n = {envs})")
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        write_atomic(args.out / "report.json", json.dumps(report, indent=1))
        draw_system(parts, args.trials, args.out / "fig2-system.png", persist_state=persist)
        print(f"wrote {args.out / 'report.json'}, {args.out / 'fig2-system.png'}")
    return 0


def draw_system(parts: Sequence[nav1d.Part], trials: int, path: Path, *, persist_state: bool = True) -> None:
    """Fig. 2 of the integrated system of ``parts`` (classifier, far, near): one environment per
    case, ``trials`` trials each, the goal on the same side, written to ``path``."""
    records = []
    for c in nav1d.cases(parts[0].config):
        first, rest, _ = nav1d.system_record(parts[0], parts[1], parts[2], [c] * trials,
                                             persist_state=persist_state)
        records.append(_join(first, rest))
    _fig2(records, parts[0].config.task_json(), "integrated system, one environment per case "
          f"({trials} trials, goal on the same side)", path)


def _join(first: nav1d.Record, rest: nav1d.Record) -> nav1d.Record:
    """The classifier's trial followed by the picked network's, as one record for plotting
    (outputs are left out: the two networks' neurons differ)."""
    return nav1d.Record(
        conditions=first.conditions + rest.conditions,
        x=np.concatenate([first.x, rest.x]),
        landmark=np.concatenate([first.landmark, rest.landmark]),
        reinforcement=np.concatenate([first.reinforcement, rest.reinforcement]),
        outputs=np.zeros((len(first.x) + len(rest.x), 0)),
        trial=np.concatenate([first.trial, rest.trial + 1]),
        moving=np.concatenate([first.moving, rest.moving]),
        reached=first.reached + rest.reached,
        classification=first.classification + rest.classification,
        final_state=rest.final_state,
    )
