"""Landmark recognition in held-out worlds (issue 47): how well do saved champions tell the two
landmarks apart in worlds that no run trained or selected on, and where do they sit between a
trivial classifier and an observer fitted on each world?

Every champion (the ``best.json`` of each run folder given) is judged on ``--trials`` fresh
trials per landmark, drawn from ``TEST_SEED``, in five worlds: the training world (the paper's
ideal world, unvaried), the robot-like test (``dnnevo assess --robot-like``), and the three
held-out worlds of a set of :mod:`dnnevo.tasks.landmark_worlds` (``--worlds first``, the default:
another wall follower, another sonar, a bigger room with the landmark off-centre; ``--worlds
second``: a weaving wall follower, a lobed sonar that loses readings, other boxes). In each world,
on the same test trials:

- **constant**: always one answer: 50% by construction (as many trials of each landmark);
- **threshold**: the best single-threshold rule on the sonar input's mean or the fraction of
  steps it reads near (input above ``NEAR``, a range under 2 m), fitted on ``--fit-trials``
  trials per landmark of that world drawn from ``FIT_SEED``;
- **observer**: logistic regression (:mod:`dnnevo.evaluation.observer`) on seven features of the
  input stream (mean, sd, max, fraction near, near episodes, longest and mean near run), fitted
  on the same ``FIT_SEED`` trials; for a held-out world also fitted on the other two held-out
  worlds of its set only (leave one world out), which says whether the features themselves
  transfer.

The judging is :mod:`dnnevo.tasks.landmark_transfer`'s, which the reproduction's held-out-worlds
jobs also run (``landmark-worlds``, ``landmark-robust-worlds`` and ``landmark-wide-first-worlds`` in
the first set; ``landmark-robust-second-worlds`` and ``landmark-wide-worlds`` in the second). A champion meets the issue's
goal in a world when it is right in more than 85% of the trials and
the 95% Wilson interval's lower end is above 80%::

    python examples/landmark_transfer.py /root/dnnevo-reference/landmark \\
        /root/dnnevo-reference/landmark-robust --record docs/results/examples/landmark-transfer.json

With ``--factors`` the held-out worlds are taken apart (:func:`landmark_worlds.single_factors`):
each champion is judged in one world per factor of each held-out world of the set, with only that
factor changed (a world that changes one thing is judged as it is), beside each such world's
threshold rule and observer. That says which factor a champion fails on::

    python examples/landmark_transfer.py /root/dnnevo-reference/landmark \\
        /root/dnnevo-reference/landmark-robust --factors --record docs/results/examples/landmark-factors.json

Each FOLDER is a run folder (``config.toml`` and ``best.json``) or a folder of them
(``seed-0``, ``seed-1``, ...); its name labels its champions. Without any, the reference
reproduction's two landmark folders are used if they exist. Nothing is written into them.
"""

from __future__ import annotations

import argparse
import re
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from dnnevo import _core
from dnnevo.config import EvolutionConfig
from dnnevo.errors import DnnevoError
from dnnevo.evaluation.stats import wilson
from dnnevo.experiments import examples
from dnnevo.runs import RunDir
from dnnevo.tasks import landmark_transfer as transfer
from dnnevo.tasks import landmark_worlds
from dnnevo.tasks.landmark_transfer import FIT_SEED, TEST_SEED, Place, held_out, meets, place

REFERENCE = [Path("/root/dnnevo-reference/landmark"), Path("/root/dnnevo-reference/landmark-robust")]
"""The champions judged by default: the reference reproduction's ``landmark`` and
``landmark-robust`` runs, seeds 0-9."""


def champions(folder: Path) -> list[tuple[str, Path]]:
    """The run folders in ``folder`` (itself, or its ``seed-N`` subfolders in seed order)."""
    if (folder / "config.toml").is_file():
        return [(folder.name, folder)]
    runs = [p for p in folder.glob("seed-*") if p.is_dir() and re.fullmatch(r"seed-\d+", p.name)]
    if not runs:
        raise SystemExit(f"{folder}: neither a run folder (config.toml) nor a folder of seed-N run folders")
    return [(p.name, p) for p in sorted(runs, key=lambda p: int(p.name[5:]))]


def load(run: Path) -> tuple[EvolutionConfig, _core.Network]:
    """A run's config and champion, read without writing anything."""
    rd = RunDir(run)
    config, table = rd.read_run_config()
    return config, rd.read_best(config, table)


def places(world_set: str) -> list[Place]:
    """The five places champions are judged in with ``--worlds world_set``."""
    return [place(name) for name in ("training", "robot-like", *held_out(world_set))]


def factors(world_set: str) -> list[Place]:
    """The places of ``--factors``: each held-out world's factors, one world each."""
    return [Place(w.name, w) for world in landmark_worlds.SETS[world_set].values()
            for w in landmark_worlds.single_factors(world)]


def judge(run: Path, trials: int, places: Sequence[Place]) -> dict[str, int]:
    """Trials right of ``run``'s champion in each of ``places`` (of ``2 trials``), and under
    ``"<place> one answer"`` the trials given its commoner answer."""
    return transfer.judge(*load(run), trials, places)


def pct(k: int, n: int) -> str:
    return f"{100 * k / n:.1f}"


def rates(ks: list[int], n: int) -> list[str]:
    """A row's cells for champions right in ``ks`` of ``n`` trials each: how many meet the goal,
    each one's % right, and the pooled % with its 95% Wilson interval."""
    lo, hi = wilson(sum(ks), n * len(ks))
    return [f"{sum(meets(k, n) for k in ks)}/{len(ks)}", " ".join(pct(k, n) for k in ks),
            f"{pct(sum(ks), n * len(ks))} ({100 * lo:.1f}-{100 * hi:.1f})"]


def table(families: dict[str, dict[str, dict[str, int]]], base: dict[str, dict[str, Any]],
          trials: int, world_set: str) -> tuple[list[str], list[list[str]], list[str]]:
    """The record's columns, one row per place and family, and the summary lines."""
    n = 2 * trials
    held = held_out(world_set)
    columns = ["world", "champions", "meet the goal", "% right, seed by seed", "pooled % (95% interval)",
               "threshold rule %", "observer %", "observer fitted on the other two worlds %"]
    rows = []
    for where in places(world_set):
        b = base[where.name]
        for family, seeds in families.items():
            lowo = b.get("observer, other worlds")
            rows.append([where.name + (" (held out)" if where.name in held else ""), family,
                         *rates([r[where.name] for r in seeds.values()], n),
                         pct(b["threshold"], b["n"]), pct(b["observer"], b["n"]),
                         "-" if lowo is None else pct(lowo, b["n"])])
    summary = [f"{trials} fresh trials per landmark per champion and world (seed {TEST_SEED}); the bounds are "
               f"judged on the same trials and fitted on others (seed {FIT_SEED}). The constant classifier is "
               "right in 50% of them by construction. The goal (issue 47): more than 85% right with the 95% "
               "Wilson interval's lower end above 80%."]
    for family, seeds in families.items():
        every = [s for s, r in seeds.items() if all(meets(r[w], n) for w in held)]
        worst = [min(r[w] for w in held) for r in seeds.values()]
        summary.append(f"{family}: {len(every)}/{len(seeds)} champions meet the goal in all three held-out worlds"
                       f"{' (' + ', '.join(every) + ')' if every else ''}; worst held-out world per champion, "
                       f"% right: {' '.join(pct(k, n) for k in worst)}.")
    stuck = {f: {w: sum(r[f"{w} one answer"] >= 0.95 * n for r in seeds.values()) for w in held}
             for f, seeds in families.items()}
    summary.append("Champions that give one answer in at least 95% of a held-out world's trials, as the constant "
                   "classifier does: " + "; ".join(f"{f}: " + ", ".join(f"{w} {k}/{len(families[f])}"
                                                                      for w, k in by.items())
                                                   for f, by in stuck.items()) + ".")
    summary.append("Threshold rules: " + "; ".join(f"{p.name}: {base[p.name]['rule']}" for p in places(world_set))
                   + ".")
    return columns, rows, summary


def factor_table(families: dict[str, dict[str, dict[str, int]]], base: dict[str, dict[str, Any]],
                 trials: int, world_set: str) -> tuple[list[str], list[list[str]], list[str]]:
    """``--factors``' columns, one row per single-factor world and family, and the summary."""
    n = 2 * trials
    columns = ["world, one factor changed", "champions", "meet the goal", "% right, seed by seed",
               "pooled % (95% interval)", "one answer in >= 95% of trials", "threshold rule %", "observer %"]
    rows = []
    for where in factors(world_set):
        b = base[where.name]
        for family, seeds in families.items():
            stuck = sum(r[f"{where.name} one answer"] >= 0.95 * n for r in seeds.values())
            rows.append([where.name, family, *rates([r[where.name] for r in seeds.values()], n),
                         f"{stuck}/{len(seeds)}",
                         pct(b["threshold"], b["n"]), pct(b["observer"], b["n"])])
    summary = [f"{trials} fresh trials per landmark per champion and world (seed {TEST_SEED}), as in the "
               f"held-out worlds' table; the bounds are fitted on others (seed {FIT_SEED}). Each row named "
               "WORLD: FACTOR changes one factor of that held-out world and nothing else; a row named by its "
               "world alone is a world that changes one thing. The goal (issue 47): more than 85% right with "
               "the 95% Wilson interval's lower end above 80%."]
    for family, seeds in families.items():
        fails = {p.name: sum(not meets(r[p.name], n) for r in seeds.values()) for p in factors(world_set)}
        worst = max(fails.values())
        most = ", ".join(name for name, k in fails.items() if k == worst) if worst else "none (every champion meets the goal in every one)"
        summary.append(f"{family}: the factor that the most champions fail on: {most} ({worst}/{len(seeds)}); "
                       "champions failing each factor: " + ", ".join(f"{name} {k}" for name, k in fails.items()) + ".")
    return columns, rows, summary


def labels(folders: Sequence[Path]) -> list[str]:
    """Each folder's label in the tables: its name, or its whole path where two share a name (two
    reproductions' ``landmark`` folders, say).

    >>> labels([Path("a/landmark"), Path("b/landmark"), Path("b/landmark-robust")])
    ['a/landmark', 'b/landmark', 'landmark-robust']
    """
    names = [f.name for f in folders]
    return [f.name if names.count(f.name) == 1 else str(f) for f in folders]


def judge_all(folders: Sequence[Path], trials: int, fit_trials: int, judged: Sequence[Place]
              ) -> tuple[dict[str, dict[str, dict[str, int]]], dict[str, dict[str, Any]]]:
    """Every champion of ``folders`` judged in ``judged`` (by family label and seed), and the
    bounds in each place (fitted on the first champion's config: the sonar does not depend on the
    network)."""
    families: dict[str, dict[str, dict[str, int]]] = {}
    start = time.perf_counter()
    for label_of, folder in zip(labels(folders), folders, strict=True):
        family = families.setdefault(label_of, {})
        for label, run in champions(folder):
            family[label] = judge(run, trials, judged)
            print(f"{label_of} {label}: " + "  ".join(f"{p.name} {pct(family[label][p.name], 2 * trials)}%"
                                                      for p in judged), flush=True)
    base_cfg, base_net = load(champions(folders[0])[0][1])
    base = transfer.bounds(base_cfg, base_net, fit_trials, trials, judged)
    print(f"{time.perf_counter() - start:.0f} s", file=sys.stderr)
    return families, base


def checked_folders(p: argparse.ArgumentParser, folders: Sequence[Path], example: str) -> Sequence[Path]:
    """``folders``, or the parser's one-line error naming the first that is not a folder."""
    missing = [f for f in folders if not f.is_dir()]
    if missing:
        p.error(f"{missing[0]} is not a folder; pass the champions' folders (run folders, or folders "
                f"of seed-N run folders), for example: {example}")
    return folders


def show(columns: Sequence[str], rows: Sequence[Sequence[str]], summary: Sequence[str]) -> None:
    """Prints a table and its summary, as the record holds them."""
    print()
    print(" | ".join(columns))
    for row in rows:
        print(" | ".join(row))
    print("\n".join(summary))


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folders", nargs="*", type=Path, metavar="FOLDER",
                   help="run folders, or folders of seed-N run folders (default: "
                        + " and ".join(map(str, REFERENCE)) + ", if they exist)")
    p.add_argument("--trials", type=int, default=100, help="fresh test trials per landmark (default 100)")
    p.add_argument("--fit-trials", type=int, default=100,
                   help="trials per landmark the bounds are fitted on, per world (default 100)")
    p.add_argument("--worlds", choices=sorted(landmark_worlds.SETS), default="first",
                   help="the set of held-out worlds (default first)")
    p.add_argument("--factors", action="store_true",
                   help="judge in each held-out world's factors, one at a time, instead of the five places")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="also write the table here, for the docs (docs/results/examples/landmark-transfer.json, "
                        "or landmark-factors.json with --factors; landmark-transfer-second.json with --worlds "
                        "second)")
    args = p.parse_args(argv)
    if args.trials < 1 or args.fit_trials < 1:
        p.error("--trials and --fit-trials must be at least 1")
    folders = checked_folders(p, args.folders or REFERENCE, "examples/landmark_transfer.py runs/sweep-landmark")
    judged = factors(args.worlds) if args.factors else places(args.worlds)
    try:
        families, base = judge_all(folders, args.trials, args.fit_trials, judged)
    except DnnevoError as e:  # a run folder that cannot be read, or not a landmark run
        sys.exit(f"error: {e}")
    columns, rows, summary = (factor_table if args.factors else table)(families, base, args.trials, args.worlds)
    show(columns, rows, summary)
    if args.record:
        examples.write(args.record, command=examples.command("examples/landmark_transfer.py", argv),
                       columns=columns, rows=rows, summary=summary)


if __name__ == "__main__":
    main()
