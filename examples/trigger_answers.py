"""What a sequence-learning network answers at each trigger, trial by trial.

    python examples/trigger_answers.py runs/sequence-2bit-seed0 --trials 3 --seed 999001

For each target of the preset (``sequence-2bit-paper``'s four unless ``--targets`` is given) and each
trial, one line: the wanted bits, the network's answers (its mean output over each response window,
thresholded at 0.5) and ``+`` where the answer is judged correct. The timings are fresh ones drawn
from ``--seed``, as ``dnnevo assess`` draws them, so they are not the ones the network was
trained on. A network file is judged under ``--preset``'s settings, a run folder under its own.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import dnnevo
from dnnevo import presets
from dnnevo.tasks import sequence
from dnnevo.runs import RunDir


def load(run: str, preset: str) -> tuple[dnnevo.EvolutionConfig, dnnevo.Network]:
    """The config and champion of a run folder, or a network file under ``preset``."""
    path = Path(run)
    if path.is_dir():
        return RunDir(path).read_config()[0], dnnevo.Network.load(path / "best.json")
    return presets.get(preset), dnnevo.Network.load(path)


def answers(config: dnnevo.EvolutionConfig, net: dnnevo.Network, targets: list[str], trials: int,
            seed: int) -> list[str]:
    """One line per (target, trial)."""
    lines = []
    for target in targets:
        for trial in range(trials):
            timing = sequence.timings(config, seed, 0, trial)
            r = sequence.run_trial(config, net, target, timing)
            wanted = "".join(str(int(b)) for b in r.targets)
            given = "".join("1" if m > 0.5 else "0" for m in r.mean_output)
            marks = "".join("+" if c else "-" for c in r.trigger_correct)
            lines.append(f"{target + '*':>4} trial {trial}: wanted {wanted}  answered {given}  "
                         f"correct {marks}")
    return lines


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("run", help="a run folder, or a network file (judged under --preset)")
    p.add_argument("--preset", default="sequence-2bit-paper", help="settings for a network file")
    p.add_argument("--targets", help="comma-separated targets (default: the config's)")
    p.add_argument("--trials", type=int, default=3, help="trials per target")
    p.add_argument("--seed", type=int, default=999001, help="seed of the fresh timings")
    args = p.parse_args(argv)
    config, net = load(args.run, args.preset)
    targets = args.targets.split(",") if args.targets else list(config.task_params["targets"])
    config = dataclasses.replace(config, task_params={**config.task_params, "targets": targets})
    print("\n".join(answers(config, net, targets, args.trials, args.seed)))


if __name__ == "__main__":
    main()
