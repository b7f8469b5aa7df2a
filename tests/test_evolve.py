"""The evolution engine: ask/tell, determinism over threads, run folders, resume, signals."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

import dnnevo
from dnnevo import ConfigError, EvolutionConfig, FitnessError

SQUARE = np.repeat([1.0, 0.0, 1.0, 0.0], 10)[:, None]


def follow_square(networks: list[dnnevo.Network]) -> np.ndarray:
    """Fitness: neuron 0's firing rate should follow a slow square wave given as input."""
    out = np.array([n.copy().run(SQUARE, substeps=10).outputs[:, 0] for n in networks])
    return 1.0 - np.abs(out - SQUARE[:, 0]).mean(axis=1)


SMALL = EvolutionConfig(population=40, generations=6, size=2, n_inputs=1)


def test_ask_tell_solves_a_small_problem() -> None:
    ga = dnnevo.GeneticAlgorithm(EvolutionConfig(population=60, size=2, n_inputs=1), seed=1)
    firsts = []
    for _ in range(12):
        genomes, networks = ga.ask()
        assert genomes.shape == (60, 2 * (2 + 1 + 2))
        stats = ga.tell(follow_square(networks))
        firsts.append(stats["mean"])
    assert ga.best is not None and ga.best_fitness is not None
    assert ga.best_fitness > 0.8
    assert firsts[-1] > firsts[0] + 0.1, firsts


def test_state_dict_round_trip_continues_identically() -> None:
    a = dnnevo.GeneticAlgorithm(SMALL, seed=4)
    for _ in range(2):
        a.tell(follow_square(a.ask().networks))
    b = dnnevo.GeneticAlgorithm.from_state_dict(json.loads(json.dumps(a.state_dict())))
    for _ in range(3):
        fa = a.tell(follow_square(a.ask().networks))
        fb = b.tell(follow_square(b.ask().networks))
        assert fa == fb
    np.testing.assert_array_equal(a.ask().genomes, b.ask().genomes)


@pytest.mark.parametrize(
    ("fitness", "error", "fragment"),
    [
        (np.full(40, np.nan), FitnessError, "individual 0 is NaN"),
        (-np.ones(40), FitnessError, "rank"),
        (np.ones(3), FitnessError, "3 fitness values"),
        (np.ones((40, 1)), FitnessError, "expected (P,)"),
    ],
)
def test_bad_fitness_is_refused(fitness: np.ndarray, error: type, fragment: str) -> None:
    ga = dnnevo.GeneticAlgorithm(SMALL, seed=0)
    with pytest.raises(error) as info:
        ga.tell(fitness)
    assert fragment in str(info.value)
    assert ga.generation == 0


@pytest.mark.parametrize("seed", [-1, 2**64, 1.5, "3", True])
def test_bad_seed_is_a_config_error(seed: object) -> None:
    with pytest.raises(ConfigError, match="seed is"):
        dnnevo.GeneticAlgorithm(SMALL, seed=seed)  # type: ignore[arg-type]


def test_seeding_puts_networks_first() -> None:
    seed_net = dnnevo.Network.random(2, 1, seed=9)
    ga = dnnevo.GeneticAlgorithm(SMALL, seed=0, founders=[seed_net])
    assert ga.ask().networks[0] == seed_net
    with pytest.raises(ConfigError, match="seed network 0 has N = 3"):
        dnnevo.GeneticAlgorithm(SMALL, seed=0, founders=[dnnevo.Network.random(3, 1, seed=1)])


def test_builtin_run_is_identical_with_one_and_two_threads(tmp_path: Path) -> None:
    config = dnnevo.presets.get("sequence-1bit", quick=True)
    one = dnnevo.evolve("sequence", config, seed=5, threads=1, out=tmp_path / "1", progress=False)
    two = dnnevo.evolve("sequence", config, seed=5, threads=2, out=tmp_path / "2", progress=False)
    for key in ("best", "mean", "std", "min"):
        np.testing.assert_array_equal(one.history[key], two.history[key])
    assert one.best == two.best
    assert (tmp_path / "1/best.json").read_bytes() == (tmp_path / "2/best.json").read_bytes()


def test_evaluate_matches_in_run_scores() -> None:
    config = dnnevo.presets.get("sequence-1bit", quick=True)
    ga = dnnevo.GeneticAlgorithm(config, seed=11)
    genomes, networks = ga.ask()
    from_genomes = dnnevo.evaluate("sequence", genomes, generation=0, seed=11, config=config)
    from_networks = dnnevo.evaluate("sequence", networks, generation=0, seed=11, config=config)
    stats, fitness = ga.step()
    np.testing.assert_array_equal(from_genomes, fitness)
    np.testing.assert_array_equal(from_networks, fitness)


def test_run_folder_contents(tmp_path: Path) -> None:
    out = tmp_path / "run"
    result = dnnevo.evolve(follow_square, SMALL, seed=2, out=out, progress=False)
    assert sorted(p.name for p in out.iterdir()) == [
        ".dnnevo.lock", "best.json", "checkpoint.json", "config.toml", "log.csv"]
    saved = EvolutionConfig.from_toml((out / "config.toml").read_text())
    assert saved.task == "python:test_evolve.follow_square"
    assert dataclasses.replace(saved, task=SMALL.task) == SMALL
    assert "seed = 2" in (out / "config.toml").read_text()
    header, *rows = (out / "log.csv").read_text().splitlines()
    assert len(rows) == SMALL.generations
    # The generation is written as an integer; a Python fitness has no success rule (nan).
    assert header.startswith("generation,") and [row.split(",")[0] for row in rows] == ["0", "1", "2", "3", "4", "5"]
    assert {row.split(",")[header.split(",").index("champion_success")] for row in rows} == {"nan"}
    best = dnnevo.Network.load(out / "best.json")
    assert best == result.best
    assert best.meta["fitness"] == result.best_fitness
    # The file alone says how the run integrated its networks.
    integ = SMALL.integrator
    assert best.integrator == {"method": integ.method, "dt": integ.dt, "substeps": integ.substeps}
    assert best.meta["precision"] == SMALL.precision == "f64"
    assert result.history["best"].shape == (SMALL.generations,)
    assert result.run_dir == out
    with pytest.raises(dnnevo.DnnevoError, match="not empty"):
        dnnevo.evolve(follow_square, SMALL, seed=2, out=out, progress=False)
    dnnevo.evolve(follow_square, SMALL, seed=3, out=out, progress=False, force=True)


def test_stopped_and_resumed_run_equals_uninterrupted(tmp_path: Path) -> None:
    full = dnnevo.evolve(follow_square, SMALL, seed=7, out=tmp_path / "full", progress=False)
    stop_at_3 = lambda stats, ga: ga.generation >= 3  # noqa: E731
    part = dnnevo.evolve(follow_square, SMALL, seed=7, out=tmp_path / "part", progress=False,
                         callback=stop_at_3)
    assert len(part.history["best"]) == 3
    with pytest.raises(dnnevo.DnnevoError, match="Python fitness function"):
        dnnevo.resume(tmp_path / "part", progress=False)
    resumed = dnnevo.resume(tmp_path / "part", follow_square, progress=False)
    for key in ("generation", "best", "mean", "std", "min"):
        np.testing.assert_array_equal(full.history[key], resumed.history[key])
    assert full.best == resumed.best
    assert (tmp_path / "full/best.json").read_bytes() == (tmp_path / "part/best.json").read_bytes()


SCRIPT = """
import sys, time
sys.path.insert(0, {tests!r})
import dnnevo
from test_evolve import SMALL, follow_square
def slow(nets):
    time.sleep(0.15)
    return follow_square(nets)
cfg = dnnevo.EvolutionConfig.from_dict({{**SMALL.to_dict(), "generations": 40}})
dnnevo.evolve(slow, cfg, seed=8, out={out!r}, progress=False)
"""


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_signal_checkpoints_and_resume_is_identical(tmp_path: Path, sig: int) -> None:
    out = tmp_path / "run"
    script = SCRIPT.format(tests=str(Path(__file__).parent), out=str(out))
    proc = subprocess.Popen([sys.executable, "-c", script], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        log = out / "log.csv"
        if log.exists() and len(log.read_text().splitlines()) >= 4:
            break
        time.sleep(0.05)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    # A fitness function's run resumes from Python alone, and the hint says so.
    assert "checkpoint saved" in err and f"Resume with: dnnevo.resume({str(out)!r}, task=...) from Python" in err, err
    assert "Traceback" not in err
    cfg = EvolutionConfig.from_dict({**SMALL.to_dict(), "generations": 40})
    with pytest.raises(ConfigError, match="was evolved with python:__main__.slow"):
        dnnevo.resume(out, follow_square, progress=False)
    # slow is follow_square made slower: the same fitness under another name.
    resumed = dnnevo.resume(out, follow_square, progress=False, new_fitness=True)
    changes = tomllib.loads((out / "config.toml").read_text())["run"]["fitness_changes"]
    assert [c["task"] for c in changes] == ["python:test_evolve.follow_square"]
    full = dnnevo.evolve(follow_square, cfg, seed=8, progress=False)
    for key in ("best", "mean", "std", "min"):
        np.testing.assert_array_equal(full.history[key], resumed.history[key])
    assert full.best == resumed.best


def test_callable_with_wrong_shape() -> None:
    with pytest.raises(FitnessError, match=r"returned shape \(3,\)"):
        dnnevo.evolve(lambda nets: np.ones(3), SMALL, progress=False)


def test_config_validation_messages() -> None:
    for kwargs, fragment in [
        ({"population": 1}, "population is 1"),
        ({"crossover_rate": 1.5}, "crossover_rate is 1.5; it must be in [0, 1]"),
        ({"mutation_rate": -0.1}, "mutation_rate is -0.1"),
        ({"elitism": 100}, "elitism is 100"),
        ({"selection": "tournament"}, "selection: unknown variant `tournament`"),
        ({"mutation": "gauss"}, "mutation: unknown variant `gauss`"),
        ({"fill": "zeros"}, "fill: unknown variant `zeros`"),
        ({"mutation_scale": 0.0}, "mutation_scale is 0; it must be in (0, 1]"),
        ({"mutation_scale": 2}, "mutation_scale is 2"),
        ({"generations": 0}, "generations is 0"),
        ({"size": 0}, "size is 0"),
        ({"task": ""}, "task is empty"),
        # A negative count reads as 0 does, the rule coming from the Rust core's check.
        ({"population": 0}, "population is 0; it must be at least 2"),
        ({"population": -1}, "population is -1; it must be at least 2"),
        ({"population": -5}, "population is -5; it must be at least 2"),
        ({"generations": -2}, "generations is -2; it must be at least 1"),
        ({"size": -1}, "size is -1; it must be at least 1"),
        ({"elitism": -1}, "elitism is -1; it must be at least 0"),
        ({"validation_candidates": -3}, "validation_candidates is -3; it must be at least 0"),
        ({"integrator": {"substeps": -2}}, "integrator.substeps is -2; it must be >= 1"),
        # Beyond 64 bits the core cannot parse a count; the setting is still named.
        ({"population": 10**29}, f"population is {10**29}; it must be at most {2**64 - 1}"),
        ({"integrator": {"substeps": 2**64}}, f"integrator.substeps is {2**64}; it must be at most"),
        ({"population": 2.5}, "population is 2.5; expected an integer"),
        ({"population": True}, "population is True; expected an integer"),
        ({"crossover_rate": "high"}, "crossover_rate is 'high'; expected a number"),
        ({"integrator": {"dt": 0}}, "integrator.dt is 0"),
        ({"integrator": {"dt": float("inf")}}, "integrator.dt is inf; every number must be finite"),
        ({"integrator": {"method": "rk2"}}, "integrator.method: unknown variant `rk2`"),
        ({"integrator": {"substeps": 0}}, "integrator.substeps is 0"),
        ({"ranges": {"tau": (0, 1)}}, "ranges.tau is (0, 1); time constants must be > 0"),
        ({"ranges": {"tau": (2, 1)}}, "ranges.tau is (2, 1); the lower bound must be below"),
        ({"task_params": {"size": 3}}, "task_params.size is set"),
    ]:
        with pytest.raises(ConfigError) as info:
            EvolutionConfig(**kwargs)
        assert fragment in str(info.value)
    with pytest.raises(ConfigError, match="unknown key 'populaton'"):
        EvolutionConfig.from_dict({"populaton": 3})


def test_a_new_run_refuses_a_scale_uniform_mutation_ignores_and_an_old_one_resumes(tmp_path) -> None:
    """A scale with uniform mutation did nothing and was accepted; a new run refuses it, and a
    folder that recorded it still resumes (the scale never acted on it)."""
    idle = dataclasses.replace(SMALL, mutation_scale=0.1)
    with pytest.raises(ConfigError, match='mutation_scale is 0.1, but mutation is "uniform", which redraws'):
        dnnevo.evolve(follow_square, idle, progress=False)
    ga = dnnevo.GeneticAlgorithm(idle, seed=1)  # ask/tell and a stored config are read as they were
    assert ga.ask().genomes.shape[0] == SMALL.population


def test_creep_mutation_runs_deterministically_and_differs_from_uniform() -> None:
    creep = dataclasses.replace(SMALL, mutation="creep", mutation_scale=0.02)

    def genomes_after(config: EvolutionConfig) -> np.ndarray:
        ga = dnnevo.GeneticAlgorithm(config, seed=4)
        for _ in range(3):
            ga.tell(follow_square(ga.ask().networks))
        return ga.ask().genomes

    np.testing.assert_array_equal(genomes_after(creep), genomes_after(creep))
    uniform = genomes_after(dataclasses.replace(creep, mutation="uniform", mutation_scale=SMALL.mutation_scale))
    assert not np.array_equal(genomes_after(creep), uniform)
    assert EvolutionConfig.from_toml(creep.to_toml()) == creep


def test_settings_added_later_leave_old_digests_unchanged() -> None:
    """A folder written before ``mutation`` existed carries a digest of a config without it."""
    from dnnevo.config import LATER_SETTINGS
    from dnnevo.runs import config_digest

    config = EvolutionConfig()
    old = {k: v for k, v in config.to_dict().items() if k not in LATER_SETTINGS}
    text = json.dumps({"config": old, "seed": 5}, sort_keys=True, separators=(",", ":"))
    assert config_digest(config, 5) == __import__("hashlib").sha256(text.encode()).hexdigest()
    assert config_digest(dataclasses.replace(config, mutation="creep"), 5) != config_digest(config, 5)


def test_env_thread_count_does_not_change_results(tmp_path: Path) -> None:
    outs = []
    for threads in ("1", "2"):
        out = tmp_path / threads
        env = {**os.environ, "RAYON_NUM_THREADS": threads}
        subprocess.run(
            [sys.executable, "-m", "dnnevo", "run", "sequence-1bit", "--quick", "--seed", "3",
             "--out", str(out)], env=env, check=True, capture_output=True)
        outs.append((out / "best.json").read_bytes())
        assert (out / "log.csv").exists()
    assert outs[0] == outs[1]


def test_a_preset_name_with_its_config_runs_the_presets_task() -> None:
    config = dnnevo.presets.get("nav1d-far", quick=True, overrides=["generations=2"])
    by_name = dnnevo.evolve("nav1d-far", config, seed=1, progress=False)
    by_task = dnnevo.evolve("nav1d", config, seed=1, progress=False)
    assert by_name.best_fitness == by_task.best_fitness
    assert by_name.history["best"].tolist() == by_task.history["best"].tolist()
    with pytest.raises(ConfigError, match="does not match config.task"):
        dnnevo.evolve("landmark", config, seed=1, progress=False)


def test_founders_start_the_population_and_seeds_is_its_deprecated_name() -> None:
    founder = dnnevo.Network.random(2, 1, seed=9)
    ga = dnnevo.GeneticAlgorithm(SMALL, seed=0, founders=[founder])
    assert np.array_equal(ga.ask()[1][0].tau, founder.tau)
    with pytest.warns(DeprecationWarning, match="founders="):
        old = dnnevo.GeneticAlgorithm(SMALL, seed=0, seeds=[founder])
    assert np.array_equal(old.ask()[0], dnnevo.GeneticAlgorithm(SMALL, seed=0, founders=[founder]).ask()[0])
    with pytest.raises(dnnevo.ConfigError, match="not both"):
        dnnevo.GeneticAlgorithm(SMALL, seed=0, founders=[founder], seeds=[founder])


def test_evaluate_scores_a_python_task_preset_as_its_run_does(tmp_path: Path) -> None:
    """A preset of a task written in Python is scored by its closed-loop fitness, with the
    scores of generation 0 inside a run of that preset."""
    config = dataclasses.replace(dnnevo.presets.get("legged-walker", quick=True), generations=1)
    genomes, networks = dnnevo.GeneticAlgorithm(config, seed=11).ask()
    from_genomes = dnnevo.evaluate("legged-walker", genomes, generation=0, seed=11)
    from_networks = dnnevo.evaluate("legged-walker", networks, generation=0, seed=11, config=config)
    np.testing.assert_array_equal(from_genomes, from_networks)
    run = dnnevo.evolve("legged-walker", config, seed=11, out=tmp_path / "run", progress=False)
    assert run.history["best"][0] == from_genomes.max()
    assert run.history["mean"][0] == from_genomes.mean()
    with pytest.raises(dnnevo.errors.InvalidArgumentError, match="genomes must be"):
        dnnevo.evaluate("legged-walker", genomes[0], generation=0, seed=11)
    with pytest.raises(dnnevo.errors.InvalidArgumentError, match="genomes must be"):
        dnnevo.evaluate("legged-walker", [networks[0], genomes[1]], generation=0, seed=11)


def test_a_failing_task_keeps_what_it_finished_and_a_kill_s_rerun_is_said(tmp_path: Path, monkeypatch,
                                                                          capsys) -> None:
    import shutil

    from dnnevo.evolution import evolve as engine

    # Checkpoints only at the start and the end, the log at every generation: a kill in between
    # leaves log.csv ahead of checkpoint.json.
    monkeypatch.setattr(engine, "CHECKPOINT_SECONDS", 1e9)
    monkeypatch.setattr(engine, "LOG_SECONDS", 0.0)
    calls = []

    def fails_at_4(networks):
        calls.append(1)
        if len(calls) == 3:  # generations 0-1 logged, the checkpoint still at 0: a kill here
            shutil.copytree(tmp_path / "run", tmp_path / "killed")
        if len(calls) == 5:
            raise RuntimeError("the simulator crashed")
        return follow_square(networks)

    with pytest.raises(RuntimeError, match="the simulator crashed"):
        dnnevo.evolve(fails_at_4, SMALL, seed=7, out=tmp_path / "run", progress=False)
    # The four finished generations are kept: checkpoint, log and best agree, and resume
    # continues from the fifth.
    evolution = json.loads(json.loads((tmp_path / "run" / "checkpoint.json").read_text())["state"]["evolution"])
    assert evolution["generation"] == 4
    from dnnevo.runs import RunDir
    assert RunDir(tmp_path / "run").logged_generations() == 4
    full = dnnevo.evolve(follow_square, SMALL, seed=7, out=tmp_path / "full", progress=False)
    resumed = dnnevo.resume(tmp_path / "run", follow_square, progress=False, new_fitness=True)
    np.testing.assert_array_equal(full.history["best"], resumed.history["best"])
    capsys.readouterr()
    # The killed copy: its log is two generations ahead of its checkpoint, and resume says so.
    resumed = dnnevo.resume(tmp_path / "killed", follow_square, progress=False, new_fitness=True)
    assert "continuing from its checkpoint at generation 0; the 2 generations log.csv has after " \
           "it run again" in capsys.readouterr().err
    np.testing.assert_array_equal(full.history["best"], resumed.history["best"])
