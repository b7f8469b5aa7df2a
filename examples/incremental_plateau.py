"""Why the paper's incremental 2-bit route starts on a plateau: the composite of a 1-bit and an
alternating network, probed by hand.

    python examples/incremental_plateau.py runs/sequence-1bit-seed0 runs/sequence-2bit-alternating-seed0

1. With zero cross weights the composite's output is the 1-bit part's, step for step: the script
   counts the trials (timings x targets) on which the two outputs are identical.
2. A single mutation of the cross weight from the alternating part's output (its neuron 0,
   composite neuron n1) to the composite's output (neuron 0), set to +-8 and +-16.
3. The output neuron rewired as a relay of the alternating part: its weights from the 1-bit part
   and its sensor weights set to 0, the cross weight to +-16 and its threshold to half of it.

Each network is judged as ``dnnevo assess`` judges (``sequence.assess``) on fresh timings of
the ``sequence-2bit-paper`` preset; the table gives, per target, the fraction of trials right after the
warm-up.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

import dnnevo
from dnnevo import presets
from dnnevo.tasks import sequence

TARGETS = ("0", "1", "01", "10")


def champion(run: str) -> dnnevo.Network:
    """A run folder's champion, or a network file."""
    path = Path(run)
    return dnnevo.Network.load(path / "best.json" if path.is_dir() else path)


def identical_outputs(one_bit: dnnevo.Network, composite: dnnevo.Network, timings: int,
                      seed: int) -> tuple[int, int]:
    """On how many (timing, target) trials the composite's output equals the 1-bit part's."""
    two_bit = presets.get("sequence-2bit-paper")
    same = total = 0
    for t in range(timings):
        timing = sequence.timings(two_bit, seed, 0, t)
        for target in TARGETS:
            alone_cfg = dataclasses.replace(
                two_bit, size=one_bit.size, task_params={**two_bit.task_params, "targets": [target]})
            alone = sequence.run_trial(alone_cfg, one_bit, target, timing).output
            both = sequence.run_trial(two_bit, composite, target, timing).output
            same += int(np.array_equal(np.asarray(alone), np.asarray(both)))
            total += 1
    return same, total


def variants(composite: dnnevo.Network, alternating_output: int) -> dict[str, dnnevo.Network]:
    """The composite, one-gene mutants of its output's cross weight, and relays."""
    tau, theta = np.array(composite.tau), np.array(composite.theta)
    weights, sensors = np.array(composite.weights), np.array(composite.sensor_weights)
    out: dict[str, dnnevo.Network] = {"composite, cross weights 0": composite}
    for w in (16.0, 8.0, -8.0, -16.0):
        mutant = weights.copy()
        mutant[0, alternating_output] = w
        out[f"one mutation: w[0][{alternating_output}] = {w:g}"] = dnnevo.Network(
            tau=tau, theta=theta, weights=mutant, sensor_weights=sensors)
    for w in (16.0, -16.0):
        relay_w, relay_s, relay_t = weights.copy(), sensors.copy(), theta.copy()
        relay_w[0, :alternating_output] = 0.0
        relay_w[0, alternating_output] = w
        relay_s[0] = 0.0
        relay_t[0] = w / 2
        out[f"relay: w[0][{alternating_output}] = {w:g}, theta[0] = {w / 2:g}"] = dnnevo.Network(
            tau=tau, theta=relay_t, weights=relay_w, sensor_weights=relay_s)
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("one_bit", help="the 1-bit run folder (or network file)")
    ap.add_argument("alternating", help="the alternating run folder (or network file)")
    ap.add_argument("--trials", type=int, default=200, help="fresh trials per target (200)")
    ap.add_argument("--seed", type=int, default=777, help="seed of the fresh timings (777)")
    ap.add_argument("--timings", type=int, default=40,
                    help="timings compared in step 1, each on the 4 targets (40)")
    args = ap.parse_args(argv)
    one_bit, alternating = champion(args.one_bit), champion(args.alternating)
    composite = dnnevo.compose(one_bit, alternating)
    same, total = identical_outputs(one_bit, composite, args.timings, args.seed)
    print(f"composite output identical to the 1-bit part's on {same} of {total} trials")
    config = presets.get("sequence-2bit-paper")
    print(f"{'network':44} " + " ".join(f"{t + '*':>6}" for t in TARGETS))
    for name, net in variants(composite, one_bit.size).items():
        report = sequence.assess(config, net, args.trials, args.seed)
        right = {t["target"]: t["success_fraction"] for t in report["targets"]}
        print(f"{name:44} " + " ".join(f"{right[t]:6.3f}" for t in TARGETS))


if __name__ == "__main__":
    main()
