"""Every task and every way of choosing a champion, pinned to the bit: a short run of each, its
whole history (wall times aside) and champion hashed. A change here changes published results,
so it must be deliberate and said in CHANGELOG.md; tests/test_simd.py pins one run on every
kernel, and these runs on the machine's own.

Each run takes well under a second. Regenerate a digest only for a change that is meant to alter
results: ``python -c "import test_fingerprints as t; print(t.fingerprint('landmark'))"`` from
``tests/``.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable

import numpy as np
import pytest

import dnnevo
from dnnevo import presets
from dnnevo.closedloop import ClosedLoop

TIMINGS = ("elapsed_s", "evals_per_s")


def _preset(name: str, *overrides: str) -> dnnevo.EvolutionConfig:
    return presets.get(name, quick=True, overrides=list(overrides))


def _founded() -> dnnevo.EvolutionResult:
    config = _preset("sequence-1bit", "population=12", "generations=2", "fill=random")
    founder = dnnevo.Network.random(config.size, config.n_inputs, seed=11)
    return dnnevo.evolve("sequence-1bit", config, seed=5, progress=False, founders=[founder])


class Seek:
    """A task in NumPy with random conditions: reach a target drawn per episode on a line."""

    observation_size = 1

    def reset(self, episodes: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        self.target = rng.uniform(-1.0, 1.0, episodes.max() + 1)[episodes]
        self.x = np.zeros(len(episodes))
        return (self.target - self.x)[:, None]

    def step(self, rates: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        self.x = self.x + 0.1 * (rates[:, 1] - rates[:, 0])
        return ((self.target - self.x)[:, None], -np.abs(self.target - self.x),
                np.zeros(len(self.x), dtype=bool))


def _closed_loop(candidates: int) -> dnnevo.EvolutionResult:
    config = dnnevo.EvolutionConfig(population=16, generations=3, size=3, n_inputs=1,
                                    selection="rank", elitism=2, validation_candidates=candidates)
    fitness = ClosedLoop(Seek(), episodes=2, max_steps=50, dt=0.1, substeps=1)
    return dnnevo.evolve(fitness, config, seed=2, progress=False)


#: What each run covers, how to make it, and its pinned digest.
RUNS: dict[str, tuple[Callable[[], dnnevo.EvolutionResult], str]] = {
    # The sonar world, the wall follower, the robot's scoring; champion by validation.
    "landmark": (lambda: dnnevo.evolve(
        "landmark", _preset("landmark", "population=10", "generations=2",
                            "task_params.validation_trials=4", "task_params.trial_seconds=20"),
        seed=1, progress=False), "a2a887d4b181b1f2"),
    # The continuous navigation world with its classifier chains; champion by validation.
    "nav1d": (lambda: dnnevo.evolve(
        "nav1d-classifier", _preset("nav1d-classifier", "population=10", "generations=2",
                                    "task_params.validation_chains=6"),
        seed=1, progress=False), "e0c30a98bd1bc7a4"),
    # Champion by training fitness alone.
    "sequence, by fitness": (lambda: dnnevo.evolve(
        "sequence-1bit", _preset("sequence-1bit", "population=12", "generations=3",
                                 "validation_candidates=0"),
        seed=4, progress=False), "a016b9396a5f540f"),
    # Champion by validation and the step check, with creep mutation and elites.
    "sequence, step check, creep": (lambda: dnnevo.evolve(
        "sequence-1bit", _preset("sequence-1bit", "population=12", "generations=3",
                                 "champion_step_check=true", "mutation=creep", "elitism=2",
                                 "task_params.validation_trials=6"),
        seed=4, progress=False), "19e226820d26694f"),
    # Founders placed first, the rest random.
    "sequence, founders": (_founded, "fc5c8c10e392e885"),
    # A task written in NumPy through the protocol, champion by its validation set or by fitness.
    "closed loop, validated": (lambda: _closed_loop(4), "2582994234f6eba1"),
    "closed loop, by fitness": (lambda: _closed_loop(0), "1057a9a1ab646d54"),
}


def fingerprint(name: str) -> str:
    result = RUNS[name][0]()
    digest = hashlib.sha256()
    for key in sorted(result.history):
        if key not in TIMINGS:
            column = np.ascontiguousarray(result.history[key], dtype=np.float64)
            digest.update(key.encode() + column.view(np.uint64).tobytes())
    digest.update(numbers_only(result.best).encode())
    return digest.hexdigest()[:16]


def numbers_only(net: dnnevo.Network) -> str:
    """The network's own numbers as JSON, without the run's notes (``meta``, ``integrator``)
    that ``EvolutionResult.best`` carries, as digests were pinned before it carried them."""
    return dnnevo.Network(net.tau, net.theta, net.weights, net.sensor_weights, state=net.state).to_json()


@pytest.mark.parametrize("name", RUNS)
def test_each_run_gives_its_pinned_bits(name: str) -> None:
    assert fingerprint(name) == RUNS[name][1]


def test_a_champion_chosen_otherwise_is_another_champion() -> None:
    """Validation changes the champion, never the populations: the fitness columns agree, the
    champions differ."""
    validated, plain = _closed_loop(4), _closed_loop(0)
    for key in ("best", "mean", "std", "min"):
        np.testing.assert_array_equal(validated.history[key], plain.history[key])
    assert validated.best_validation is not None and plain.best_validation is None
    assert validated.best.to_json() != plain.best.to_json()
