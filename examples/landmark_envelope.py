"""Landmark recognition at the ends of the training envelope (issue 47): have the champions of a
varied training learnt the envelope they were trained on?

A run of ``landmark-robust`` or ``landmark-wide`` draws, for every training trial, the wall
follower's speed and distance and the sonar's cone (and for ``landmark-wide`` its axis) uniformly
over a range. Each champion (the ``best.json`` of each run folder given) is judged on ``--trials``
fresh trials per landmark, drawn from ``TEST_SEED``, in one world per end of each such range, with
nothing else varied (:func:`dnnevo.tasks.landmark_worlds.envelope_edges`). These are no held-out
worlds: training saw each of them, if rarely. A champion that fails at the ends of its own
envelope was not made robust by its training, whatever it does beyond it. The goal is the
held-out worlds' (more than 85% right, the 95% Wilson interval's lower end above 80%)::

    python examples/landmark_envelope.py /root/dnnevo-reference/landmark-robust \\
        /root/dnnevo-reference/landmark-wide --record docs/results/examples/landmark-envelope.json

With ``--bounds`` it judges no champion and asks instead whether one rule can tell the landmarks
apart at every end at once, as a champion must: at each end, an observer fitted at that end
alone, one linear observer fitted on every end's trials together, and a nearest-neighbour rule
fitted on them (:func:`dnnevo.tasks.landmark_transfer.pooled_bounds`), each fitted on ``--trials``
trials per landmark from ``FIT_SEED`` and judged on as many from ``TEST_SEED``::

    python examples/landmark_envelope.py /root/dnnevo-reference/landmark-wide --bounds \\
        --record docs/results/examples/landmark-envelope-bounds.json

Each FOLDER is a run folder or a folder of ``seed-N`` run folders, as for
``examples/landmark_transfer.py``, whose runs share one training envelope; its name labels its
champions. Without any, the reference reproduction's ``landmark-robust`` and ``landmark-wide``
folders are used. Nothing is written into them. The summary gives each champion's validation
rate: the share of its run's validation set it was right in, a set of as many ideal trials as
varied ones.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from landmark_transfer import champions, checked_folders, labels, load, rates, show

from dnnevo.errors import DnnevoError
from dnnevo.experiments import examples
from dnnevo.tasks import landmark_worlds
from dnnevo.tasks import landmark_transfer as transfer
from dnnevo.tasks.landmark_transfer import TEST_SEED, Place, meets

REFERENCE = [Path("/root/dnnevo-reference/landmark-robust"), Path("/root/dnnevo-reference/landmark-wide")]
"""The champions judged by default: the reference reproduction's two varied-training presets."""

COLUMNS = ["champions", "end of the training envelope", "meet the goal", "% right, seed by seed",
           "pooled % (95% interval)", "one answer in >= 95% of trials"]


def judge_family(label: str, folder: Path, trials: int) -> tuple[list[str], dict[str, dict[str, int]], list[float]]:
    """The envelope's ends of ``folder``'s runs, each champion's trials right (and given its commoner
    answer) at each, by seed label, and each champion's validation rate."""
    edges: list[str] | None = None
    judged: dict[str, dict[str, int]] = {}
    validation = []
    for seed, run in champions(folder):
        config, net = load(run)
        places = [Place(w.name, w) for w in landmark_worlds.envelope_edges(config)]
        names = [p.name for p in places]
        if edges is None:
            edges = names
        elif names != edges:
            raise DnnevoError(f"{run}'s training envelope differs from the other runs' of {folder}; "
                              "give runs of one envelope per folder")
        judged[seed] = transfer.judge(config, net, trials, places)
        validation.append(float(net.meta.get("validation_rate", float("nan"))))
        print(f"{label} {seed}: " + "  ".join(f"{p} {100 * judged[seed][p] / (2 * trials):.1f}%" for p in names),
              flush=True)
    if not edges:
        raise DnnevoError(f"{folder}'s runs vary none of the follower's speed and distance and the sonar's "
                          "cone and axis in training, so their envelope has no ends to judge")
    return edges, judged, validation


BOUNDS_COLUMNS = ["envelope", "end", "observer fitted at that end %", "one linear observer for every end %",
                  "the same on the stream's profile %", "one nearest-neighbour rule for every end %"]
BOUNDS_KEYS = ("own", "one linear", "one linear, profile", "one nearest")
"""The columns' keys in :func:`dnnevo.tasks.landmark_transfer.pooled_bounds`."""


def bounds_table(folders: dict[str, Path], trials: int) -> tuple[list[list[str]], list[str]]:
    """For the envelope of each folder's first run: each end's bounds (the rows) and a summary."""
    rows, summary = [], [
        f"Fitted on {trials} trials per landmark per end (seed {transfer.FIT_SEED}), judged on {trials} "
        f"fresh ones (seed {TEST_SEED}). The observers are logistic regressions on the sonar stream's "
        "summary features or on its profile: those features, its distribution (33 quantiles) and its "
        "time course (24 bins; dnnevo.evaluation.observer.profile), which the nearest-neighbour rule "
        "sees too. The sonar does not depend on the network."]
    for label, folder in folders.items():
        (_, run), *_ = champions(folder)
        config, net = load(run)
        places = [Place(w.name, w) for w in landmark_worlds.envelope_edges(config)]
        if not places:
            raise DnnevoError(f"{run}'s training varies none of the follower's speed and distance and the "
                              "sonar's cone and axis, so its envelope has no ends")
        found = transfer.pooled_bounds(config, net, trials, trials, places)
        for end, b in found.items():
            rows.append([label, end, *(f"{100 * b[k] / b['n']:.1f}" for k in BOUNDS_KEYS)])

        def met(key: str) -> str:
            return f"{sum(meets(b[key], b['n']) for b in found.values())} of {len(found)} ends"
        summary.append(f"{label}: the goal is met by one linear observer at {met('one linear')}, by one "
                       f"on the stream's profile at {met('one linear, profile')}, and by the "
                       f"nearest-neighbour rule at {met('one nearest')}.")
    return rows, summary


def table(families: dict[str, tuple[list[str], dict[str, dict[str, int]], list[float]]],
          trials: int) -> tuple[list[list[str]], list[str]]:
    """The record's rows, one per family and end of its envelope, and the summary lines."""
    n = 2 * trials
    rows = []
    summary = [f"{trials} fresh trials per landmark per champion and end (seed {TEST_SEED}); each row sets one "
               "variation of the family's training to one end of its range and varies nothing else. The goal "
               "(issue 47): more than 85% right with the 95% Wilson interval's lower end above 80%."]
    for family, (edges, judged, validation) in families.items():
        for edge in edges:
            stuck = sum(r[f"{edge} one answer"] >= 0.95 * n for r in judged.values())
            rows.append([family, edge, *rates([r[edge] for r in judged.values()], n), f"{stuck}/{len(judged)}"])
        every = sum(all(meets(r[e], n) for e in edges) for r in judged.values())
        summary.append(f"{family}: {every}/{len(judged)} champions meet the goal at every end of their envelope; "
                       "validation rate (half ideal, half varied trials), per champion: "
                       + " ".join(f"{v:.2f}" for v in validation) + ".")
    return rows, summary


def main(argv: Sequence[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("folders", nargs="*", type=Path, metavar="FOLDER",
                   help="run folders, or folders of seed-N run folders (default: "
                        + " and ".join(map(str, REFERENCE)) + ")")
    p.add_argument("--trials", type=int, default=100, help="fresh test trials per landmark (default 100)")
    p.add_argument("--bounds", action="store_true",
                   help="judge no champion: fit one rule for every end of each folder's envelope, to see "
                        "whether one can tell the landmarks apart at all of them")
    p.add_argument("--record", type=Path, metavar="JSON",
                   help="also write the table here, for the docs (docs/results/examples/landmark-envelope.json)")
    args = p.parse_args(argv)
    if args.trials < 1:
        p.error("--trials must be at least 1")
    folders = checked_folders(p, args.folders or REFERENCE, "examples/landmark_envelope.py runs/sweep-landmark-robust")
    named = dict(zip(labels(folders), folders, strict=True))
    try:
        if args.bounds:
            columns = BOUNDS_COLUMNS
            rows, summary = bounds_table(named, args.trials)
        else:
            columns = COLUMNS
            rows, summary = table({label: judge_family(label, folder, args.trials)
                                   for label, folder in named.items()}, args.trials)
    except DnnevoError as e:  # a run folder that cannot be read, not a landmark run, or no envelope
        sys.exit(f"error: {e}")
    show(columns, rows, summary)
    if args.record:
        examples.write(args.record, command=examples.command("examples/landmark_envelope.py", argv),
                       columns=columns, rows=rows, summary=summary)


if __name__ == "__main__":
    main()
