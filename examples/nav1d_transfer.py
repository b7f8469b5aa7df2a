"""A navigation champion on conditions its training never saw.

For each nav1d run folder given, judges the champion (``best.json``) on fresh chains of trials as
trained, and with one setting of the world changed at a time: longer chains, the paper's
1000-step time limit, a landmark and a start that move from trial to trial. Each cell is the rate
of scored trials done right, with "(fail)" where the rule of 95% (on the interval, as ``dnnevo
evaluate`` judges) is not met::

    python examples/nav1d_transfer.py runs/single-incremental/seed-0 runs/single-incremental/seed-1 \\
        --chains 1000 --seed 7000001

The champions of the README's single-network rows were judged with exactly this command.
"""

from __future__ import annotations

import argparse
import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from dnnevo.tasks import nav1d

VARIANTS: dict[str, dict[str, Any]] = {
    "as trained": {},
    "10 trials per chain": {"trials_per_environment": 10},
    "time limit 1000": {"max_steps": 1000},
    "landmark jitter 1": {"landmark_jitter": 1.0},
    "start jitter 2": {"start_jitter": 2.0},
}
"""Each variant's changes to the run's ``task_params``; the first is the run's own world."""


def judge(run: Path, chains: int, seed: int) -> list[tuple[float, bool]]:
    """``(rate, success)`` of the champion of ``run`` under each of :data:`VARIANTS`."""
    part = nav1d.load_part(run)
    config, net = part.config, part.network
    out = []
    for changes in VARIANTS.values():
        changed = dataclasses.replace(config, task_params={**config.task_params, **changes})
        a = nav1d.assess(changed, net, chains, seed)
        out.append((a["rate"], a["success"]))
    return out


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("runs", nargs="+", type=Path, help="nav1d run folders")
    p.add_argument("--chains", type=int, default=1000, help="fresh chains per variant (default 1000)")
    p.add_argument("--seed", type=int, default=7000001, help="seed of the fresh chains (default 7000001)")
    a = p.parse_args(argv)
    print("| run | " + " | ".join(VARIANTS) + " |")
    print("|---" * (len(VARIANTS) + 1) + "|")
    for run in a.runs:
        cells = [f"{100 * rate:.1f}%" + ("" if ok else " (fail)") for rate, ok in judge(run, a.chains, a.seed)]
        print(f"| {run} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
