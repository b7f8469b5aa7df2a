"""The ``dnnevo nav1d-system`` command: the paper's integrated navigation system of §4.2 (the
classifier drives the first trial; its answer picks the far or the near network), assembled from
three runs and judged on fresh environments."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from dnnevo.errors import ConfigError
from dnnevo.evaluation.stats import wilson
from dnnevo.runs import write_atomic
from dnnevo.tasks import nav1d

SYSTEM_EXAMPLE = (
    "example: dnnevo nav1d-system --classifier runs/nav1d-classifier-seed0 "
    "--far runs/nav1d-far-seed0 --near runs/nav1d-near-seed0 --out runs/nav1d-system"
)


def add_parser(sub: Any) -> None:
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
    for flag, value, least in (("--environments", args.environments, 1), ("--trials", args.trials, 1),
                               ("--seed", args.seed, 0)):
        if value < least:
            raise ConfigError(f"{flag} is {value}; it must be >= {least}")
    if args.out is not None and args.out.exists() and not args.out.is_dir():
        raise ConfigError(f"--out {args.out} is a file; it must be a folder for report.json and "
                          "fig2-system.png")
    if args.out is not None and (args.out / "config.toml").exists():
        raise ConfigError(f"--out {args.out} is a run folder; choose a folder of its own for "
                          "report.json and fig2-system.png")
    parts = [nav1d.load_part(p, role) for p, role in
             [(args.classifier, "--classifier"), (args.far, "--far"), (args.near, "--near")]]
    persist = not args.reset_each_trial
    report = nav1d.system_assess(parts[0], parts[1], parts[2], environments=args.environments, trials=args.trials,
                                 seed=args.seed, persist_state=persist)
    state = "persisting" if persist else "reset each trial"
    print(f"integrated system on {args.environments} fresh environments x {args.trials} trials "
          f"(seed {args.seed}; state {state}): goal rate by trial")
    for line in nav1d.goal_rate_table(report["episodes"], 0):
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
        nav1d.draw_system(parts, args.trials, args.out / "fig2-system.png", persist_state=persist)
        print(f"wrote {args.out / 'report.json'}, {args.out / 'fig2-system.png'}")
    return 0
