"""Validated champions: the best candidates of each generation re-scored on a validation set that
is fixed for the run; evolution itself unchanged, runs deterministic and resume-identical."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import dnnevo
from dnnevo import ConfigError, EvolutionConfig

# Fast configs of each built-in task that leave room for several champions.
CONFIGS = {
    "landmark": ("landmark", ["generations=12", "task_params.validation_trials=6",
                              "task_params.trial_seconds=20"]),
    "sequence": ("sequence-1bit", ["generations=6", "task_params.validation_trials=8"]),
    "nav1d": ("nav1d-classifier", ["generations=6", "task_params.validation_chains=12"]),
}
FITNESS_COLUMNS = ("generation", "best", "mean", "std", "min")
RESULT_COLUMNS = (*FITNESS_COLUMNS, "champion_success", "validation_rate", "validation_score")


def config(task: str, *extra: str) -> EvolutionConfig:
    preset, overrides = CONFIGS[task]
    return dnnevo.presets.get(preset, quick=True, overrides=[*overrides, *extra])


def same(a: np.ndarray, b: np.ndarray) -> bool:
    return bool(np.array_equal(a, b, equal_nan=True))


@pytest.mark.parametrize("task", sorted(CONFIGS))
def test_champion_is_validated_and_evolution_is_unchanged(task: str, tmp_path: Path) -> None:
    validated = dnnevo.evolve(task, config(task), seed=3, out=tmp_path / "v", progress=False)
    plain = dnnevo.evolve(task, config(task, "validation_candidates=0"), seed=3, progress=False)
    for key in FITNESS_COLUMNS:
        np.testing.assert_array_equal(validated.history[key], plain.history[key])
    assert validated.best_validation is not None
    rate, score = validated.best_validation
    assert 0.0 <= rate <= 1.0 and 0.0 <= score <= 1.0
    rates = validated.history["validation_rate"]
    assert np.all(np.diff(rates) >= 0), "the champion's validation rate never falls"
    assert rates[-1] == rate and validated.history["validation_score"][-1] == score
    meta = dnnevo.Network.load(tmp_path / "v/best.json").meta
    assert (meta["validation_rate"], meta["validation_score"]) == (rate, score)
    # Without validation the champion is the fittest individual, as in the paper.
    assert plain.best_validation is None
    assert plain.best_fitness == plain.history["best"].max()
    assert np.isnan(plain.history["validation_rate"]).all()


@pytest.mark.parametrize("task", sorted(CONFIGS))
def test_validated_run_resumes_identically(task: str, tmp_path: Path) -> None:
    cfg = config(task)
    full = dnnevo.evolve(task, cfg, seed=5, out=tmp_path / "full", progress=False)
    stop_at_3 = lambda stats, ga: ga.generation >= 3  # noqa: E731
    dnnevo.evolve(task, cfg, seed=5, out=tmp_path / "part", progress=False, callback=stop_at_3)
    resumed = dnnevo.resume(tmp_path / "part", progress=False)
    for key in RESULT_COLUMNS:
        assert same(full.history[key], resumed.history[key]), key
    assert full.best == resumed.best and full.best_validation == resumed.best_validation
    assert (tmp_path / "full/best.json").read_bytes() == (tmp_path / "part/best.json").read_bytes()


@pytest.mark.parametrize("task", sorted(CONFIGS))
def test_the_step_check_changes_champions_only_and_resumes_identically(task: str, tmp_path: Path) -> None:
    cfg = config(task, "champion_step_check=true")
    checked = dnnevo.evolve(task, cfg, seed=3, out=tmp_path / "full", progress=False)
    plain = dnnevo.evolve(task, config(task), seed=3, progress=False)
    for key in FITNESS_COLUMNS:
        np.testing.assert_array_equal(checked.history[key], plain.history[key])
    assert np.all(np.diff(checked.history["validation_rate"]) >= 0)
    stop_at_3 = lambda stats, ga: ga.generation >= 3  # noqa: E731
    dnnevo.evolve(task, cfg, seed=3, out=tmp_path / "part", progress=False, callback=stop_at_3)
    resumed = dnnevo.resume(tmp_path / "part", progress=False)
    for key in RESULT_COLUMNS:
        assert same(checked.history[key], resumed.history[key]), key
    assert (tmp_path / "full/best.json").read_bytes() == (tmp_path / "part/best.json").read_bytes()
    two = dnnevo.evolve(task, cfg, seed=3, threads=2, progress=False)
    assert checked.best == two.best and checked.best_validation == two.best_validation


@pytest.mark.parametrize("value", [1, "yes", None])
def test_bad_champion_step_check_is_a_config_error(value: object) -> None:
    with pytest.raises(ConfigError, match="champion_step_check is .*; expected true or false"):
        EvolutionConfig(champion_step_check=value)  # type: ignore[arg-type]


def test_validated_run_is_identical_with_one_and_two_threads() -> None:
    cfg = config("landmark")
    one = dnnevo.evolve("landmark", cfg, seed=9, threads=1, progress=False)
    two = dnnevo.evolve("landmark", cfg, seed=9, threads=2, progress=False)
    for key in RESULT_COLUMNS:
        assert same(one.history[key], two.history[key]), key
    assert one.best == two.best and one.best_validation == two.best_validation


def test_python_fitness_has_no_validation() -> None:
    cfg = EvolutionConfig(population=20, generations=3, size=2, n_inputs=1)
    result = dnnevo.evolve(lambda nets: np.ones(len(nets)), cfg, seed=0, progress=False)
    assert result.best_validation is None
    assert all(math.isnan(v) for v in result.history["validation_rate"])


@pytest.mark.parametrize("value", [-1, 1.5, "ten", True])
def test_bad_validation_candidates_is_a_config_error(value: object) -> None:
    with pytest.raises(ConfigError, match="validation_candidates"):
        EvolutionConfig(validation_candidates=value)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("task", "param"),
    [("landmark", "validation_trials"), ("sequence", "validation_trials"),
     ("nav1d", "validation_chains")],
)
def test_empty_validation_set_is_a_config_error(task: str, param: str) -> None:
    with pytest.raises(ConfigError, match=f"{param} is 0"):
        dnnevo.evolve(task, config(task, f"task_params.{param}=0"), seed=0, progress=False)


# ---------------------------------------------------------------------------------------------
# Fitness from Python: ask/tell with a validate callable, and a closed-loop task's own validation


def _square_fitness(networks: list[dnnevo.Network]) -> np.ndarray:
    """A noisy fitness: each network's tau[0], plus luck from its own weights."""
    return np.array([n.tau[0] + 5 * (abs(n.weights[0][0]) % 1.0) for n in networks])


def _true_quality(networks: list[dnnevo.Network]) -> tuple[np.ndarray, np.ndarray]:
    taus = np.array([n.tau[0] for n in networks])
    return taus / 10.0, np.zeros(len(networks))


def test_tell_with_validate_chooses_the_champion_and_leaves_evolution_unchanged() -> None:
    cfg = EvolutionConfig(population=30, size=2, n_inputs=1, validation_candidates=5, elitism=3)
    a, b = dnnevo.GeneticAlgorithm(cfg, seed=7), dnnevo.GeneticAlgorithm(cfg, seed=7)
    seen: list[int] = []

    def validate(networks: list[dnnevo.Network]) -> tuple[np.ndarray, np.ndarray]:
        seen.append(len(networks))
        return _true_quality(networks)

    for _ in range(6):
        a.tell(_square_fitness(a.ask().networks), validate=validate)
        b.tell(_square_fitness(b.ask().networks))
        np.testing.assert_array_equal(a.ask().genomes, b.ask().genomes)
    assert a.best_validation is not None and b.best_validation is None
    assert a.best_validation[0] == a.best.tau[0] / 10.0
    assert a.best.tau[0] >= b.best.tau[0]  # the lucky one by fitness is no better by tau
    assert seen[0] == 5 and sum(seen) < 6 * 5  # elites carried over are validated once


@pytest.mark.parametrize("returned, message", [
    ((np.zeros(5),), r"validate returned tuple; expected \(rates, scores\), two arrays of shape \(5,\)"),
    ((np.zeros(4), np.zeros(5)), r"validate returned rates of shape \(4,\); expected \(5,\)"),
    ((np.full(5, 2.0), np.zeros(5)), r"a validation gave rate 2 and score 0; a rate lies in \[0, 1\]"),
    ((np.zeros(5), np.full(5, np.nan)), r"a validation gave rate 0 and score NaN"),
])
def test_a_bad_validation_is_a_fitness_error(returned: tuple, message: str) -> None:
    ga = dnnevo.GeneticAlgorithm(EvolutionConfig(population=10, size=2, n_inputs=1,
                                                 validation_candidates=5), seed=0)
    with pytest.raises(dnnevo.FitnessError, match=message):
        ga.tell(np.ones(10), validate=lambda networks: returned)
    assert ga.generation == 0


def test_an_error_inside_validate_is_raised_as_it_was() -> None:
    ga = dnnevo.GeneticAlgorithm(EvolutionConfig(population=10, size=2, n_inputs=1), seed=0)

    def validate(networks: list[dnnevo.Network]) -> tuple[np.ndarray, np.ndarray]:
        raise KeyError("episode")

    with pytest.raises(KeyError, match="episode"):
        ga.tell(np.ones(10), validate=validate)
    assert ga.generation == 0


class _Reach:
    """A 1-D world: an episode succeeds when neuron 0's rate, integrated, passes a target drawn
    per episode; the return is the distance covered (training rewards speed, success needs
    the target)."""

    observation_size = 1
    success_rate = 0.5

    def reset(self, episodes: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        self.target = rng.uniform(0.5, 2.0, episodes.max() + 1)[episodes]
        self.x = np.zeros(len(episodes))
        return self.target[:, None].copy()

    def step(self, rates: np.ndarray, active: np.ndarray):
        self.x = self.x + 0.1 * rates[:, 0]
        return self.target[:, None].copy(), 0.1 * rates[:, 0], np.zeros(len(self.x), dtype=bool)

    def success(self, returns: np.ndarray, lengths: np.ndarray) -> np.ndarray:
        return self.x >= self.target


def test_a_closed_loop_champion_is_chosen_on_its_validation_set() -> None:
    from dnnevo.closedloop import ClosedLoop
    from dnnevo.closedloop.fitness import VALIDATION_EPISODES

    fitness = ClosedLoop(_Reach(), episodes=2, max_steps=20, substeps=1)
    cfg = EvolutionConfig(population=16, generations=4, size=2, n_inputs=1, selection="rank")
    validated = dnnevo.evolve(fitness, cfg, seed=3, progress=False)
    plain = dnnevo.evolve(fitness, dataclasses.replace(cfg, validation_candidates=0), seed=3,
                          progress=False)
    np.testing.assert_array_equal(validated.history["best"], plain.history["best"])
    assert plain.best_validation is None and np.isnan(plain.history["validation_rate"]).all()
    rates, scores = fitness.validate([validated.best], seed=3)
    assert validated.best_validation == (rates[0], scores[0])
    assert (rates[0] * VALIDATION_EPISODES) % 1 == 0
    np.testing.assert_array_equal(validated.history["validation_rate"][-1:], rates)


def test_the_validation_set_size_is_a_setting_recorded_only_when_changed() -> None:
    from dnnevo.closedloop import ClosedLoop
    from dnnevo.closedloop.named import closed_loop

    default = ClosedLoop(_Reach(), episodes=2, max_steps=20, substeps=1)
    three = ClosedLoop(_Reach(), episodes=2, max_steps=20, substeps=1, validation_episodes=3)
    rates, _ = three.validate([dnnevo.Network.random(2, 1, seed=0)], seed=1)
    assert (rates[0] * 3) % 1 == 0
    assert "validation_episodes" not in default.configured(EvolutionConfig()).task_params
    cfg = three.configured(EvolutionConfig(n_inputs=1))
    assert cfg.task_params["validation_episodes"] == 3
    assert three.digest() != default.digest()
    cfg = dataclasses.replace(cfg, task=f"python:{__name__}._Reach")
    assert closed_loop(cfg).validation_episodes == 3
    for bad in (0, -1, 2.5, True):
        with pytest.raises(dnnevo.ConfigError, match="validation_episodes"):
            ClosedLoop(_Reach(), max_steps=20, validation_episodes=bad)


def test_validate_may_read_the_ga_it_is_called_from() -> None:
    """The GA is not held while validate runs: the callable sees the generation being scored."""
    ga = dnnevo.GeneticAlgorithm(EvolutionConfig(population=10, size=2, n_inputs=1,
                                                 validation_candidates=3), seed=0)
    seen: list[int] = []

    def validate(networks: list[dnnevo.Network]) -> tuple[np.ndarray, np.ndarray]:
        seen.append(ga.generation)
        return _true_quality(networks)

    for _ in range(2):
        ga.tell(_square_fitness(ga.ask().networks), validate=validate)
    assert seen == [0, 1] and ga.generation == 2 and ga.best_validation is not None
