"""A run in single precision (``precision = "f32"``): built-in tasks and closed-loop environments
compute in f32 with bits of their own, the same with any number of threads, resumable like any
run; f64 configs and their digests are as before; a setting that cannot apply is refused."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

import numpy as np
import pytest

import dnnevo
from dnnevo import ConfigError, EvolutionConfig
from dnnevo.closedloop import ClosedLoop
from dnnevo.runs.settings import config_digest

from cli_helpers import run_cli

#: Short runs of each built-in task's quick preset.
PRESETS = ["sequence-1bit", "nav1d-far", "landmark"]


def _short(name: str, precision: str) -> EvolutionConfig:
    config = dnnevo.presets.get(name, quick=True)
    return dataclasses.replace(config, generations=min(config.generations, 3), precision=precision)


@pytest.mark.parametrize("name", PRESETS)
def test_an_f32_run_has_its_own_bits_whatever_the_threads(name: str, tmp_path: Path) -> None:
    config = _short(name, "f32")
    one = dnnevo.evolve(config.task, config, seed=3, threads=1, out=tmp_path / "1", progress=False)
    two = dnnevo.evolve(config.task, config, seed=3, threads=2, out=tmp_path / "2", progress=False)
    np.testing.assert_array_equal(one.history["best"], two.history["best"])
    assert (tmp_path / "1/best.json").read_bytes() == (tmp_path / "2/best.json").read_bytes()
    assert tomllib.loads((tmp_path / "1/config.toml").read_text())["precision"] == "f32"
    # The same population scored in f64 and in f32: not the same bits.
    networks = dnnevo.GeneticAlgorithm(config, seed=3).ask().networks
    single = dnnevo.evaluate(config.task, networks, generation=0, seed=3, config=config)
    double = dnnevo.evaluate(config.task, networks, generation=0, seed=3,
                             config=dataclasses.replace(config, precision="f64"))
    np.testing.assert_allclose(single, double, atol=0.05)
    # nav1d-far's fitness counts goals reached, on which the two may agree for every network.
    assert name == "nav1d-far" or not np.array_equal(single, double)


def test_an_f32_run_scores_as_evaluate_does_and_resumes_to_the_unbroken_run(tmp_path: Path) -> None:
    config = _short("sequence-1bit", "f32")
    ga = dnnevo.GeneticAlgorithm(config, seed=11)
    _, networks = ga.ask()
    _, fitness = ga.step()
    np.testing.assert_array_equal(
        dnnevo.evaluate("sequence", networks, generation=0, seed=11, config=config), fitness)
    whole = dnnevo.evolve("sequence", config, seed=4, out=tmp_path / "whole", progress=False)
    dnnevo.evolve("sequence", config, seed=4, out=tmp_path / "part", progress=False,
                  callback=lambda stats, ga: ga.generation >= 1)
    resumed = dnnevo.resume(tmp_path / "part", progress=False)
    np.testing.assert_array_equal(resumed.history["best"], whole.history["best"])
    assert resumed.best == whole.best


def test_f64_is_the_default_and_leaves_the_digest_as_it_was() -> None:
    config = EvolutionConfig(population=10)
    assert config.precision == "f64"
    # A run folder written before the setting existed keeps its digest: f64 is left out of it.
    without = {k: v for k, v in config.to_dict().items() if k != "precision"}
    assert EvolutionConfig.from_dict(without) == config
    assert config_digest(config, 1) != config_digest(dataclasses.replace(config, precision="f32"), 1)
    for name in dnnevo.presets.names():
        assert dnnevo.presets.get(name).precision == "f64", name


@pytest.mark.parametrize("value, message", [
    ("f16", "precision: unknown variant `f16`, expected `f64` or `f32`"),
    (32, "precision is 32; expected a string"),
])
def test_a_bad_precision_is_a_config_error_that_names_it(value: object, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        EvolutionConfig(precision=value)  # type: ignore[arg-type]


def test_the_command_line_sets_it_and_refuses_a_bad_one(tmp_path: Path) -> None:
    out = tmp_path / "run"
    r = run_cli("run", "sequence-1bit", "--quick", "--set", "precision=f32", "--set", "generations=2",
                "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert 'precision = "f32"' in (out / "config.toml").read_text()
    # Judged in the run's precision, or in the other one.
    own = run_cli("assess", str(out), "--seed", "2", "--trials", "20")
    assert "computed in f32; the run was evolved in f32" in own.stdout, own.stdout + own.stderr
    double = run_cli("assess", str(out), "--seed", "2", "--trials", "20", "--precision", "f64")
    assert "computed in f64; the run was evolved in f32" in double.stdout, double.stdout + double.stderr
    r = run_cli("run", "sequence-1bit", "--quick", "--set", "precision=f16", "--out", str(tmp_path / "bad"))
    assert r.returncode != 0
    assert r.stderr.count("\n") == 1 and "precision" in r.stderr, r.stderr


def test_a_fitness_function_cannot_be_told_to_compute_in_f32() -> None:
    config = EvolutionConfig(population=10, generations=1, size=2, n_inputs=1, precision="f32")
    with pytest.raises(ConfigError, match="a fitness function integrates its networks itself"):
        dnnevo.evolve(lambda nets: np.zeros(len(nets)), config, seed=0, progress=False)


class Glide:
    """Rewards neuron 0's rate at each of 5 steps, and notes whether every rate it saw was a
    float32 value (widened to float64)."""

    observation_size = 1

    def __init__(self) -> None:
        self.all_f32 = True

    def reset(self, episodes, rng):
        self.t = 0
        return np.ones((len(episodes), 1))

    def step(self, rates, active):
        self.all_f32 &= bool(np.all(rates.astype(np.float32) == rates))
        self.t += 1
        return np.ones((len(rates), 1)), rates[:, 0].astype(float), np.full(len(rates), self.t >= 5)


def test_a_closed_loop_computes_in_its_precision_and_records_it(tmp_path: Path) -> None:
    config = EvolutionConfig(population=20, generations=2, size=5, n_inputs=1)
    single = ClosedLoop(Glide(), episodes=2, max_steps=10, precision="f32")
    double = ClosedLoop(Glide(), episodes=2, max_steps=10)
    # An f64 loop records what it recorded before the setting existed.
    assert "precision" not in double.fitness_source and "precision" in single.fitness_source
    assert single.configured(config).precision == "f32"
    nets = [dnnevo.Network.random(5, 1, seed=s) for s in range(4)]
    returns = single(nets, seed=1), double(nets, seed=1)
    assert single.env.all_f32 and not double.env.all_f32
    assert not np.array_equal(*returns)
    np.testing.assert_allclose(*returns, rtol=1e-5)
    single = ClosedLoop(Glide(), episodes=2, max_steps=10, precision="f32")
    result = dnnevo.evolve(single, config, seed=1, progress=False, out=tmp_path / "run")
    assert tomllib.loads((tmp_path / "run/config.toml").read_text())["precision"] == "f32"
    resumed = dnnevo.resume(tmp_path / "run", single, progress=False)
    assert resumed.best == result.best
    with pytest.raises(ConfigError, match="computes in f32, not f64"):
        dnnevo.resume(tmp_path / "run", ClosedLoop(Glide(), episodes=2, max_steps=10), progress=False,
                      new_fitness=True)
    with pytest.raises(ConfigError, match="this ClosedLoop computes in 'f64'"):
        double.configured(dataclasses.replace(config, precision="f32"))
    with pytest.raises(ConfigError, match="precision is 'f16'"):
        ClosedLoop(Glide(), max_steps=10, precision="f16")
