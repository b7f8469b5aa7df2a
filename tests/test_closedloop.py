"""dnnevo.Batch (a population stepped one row at a time) and dnnevo.closedloop (a task written in
NumPy, run by rollout): exact against Network.run, the NumPy reference and the built-in task, and
every misuse a one-line error that names it."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import reference as ref

import dnnevo
from dnnevo import Batch, ConfigError, InvalidArgumentError, TaskError
from dnnevo.closedloop import ClosedLoop, FarSeeker, rollout


def networks(count: int, n: int = 4, m: int = 2, seed: int = 0) -> list[dnnevo.Network]:
    return [dnnevo.Network.random(n, m, seed=seed + k) for k in range(count)]


def params(nets: list[dnnevo.Network]) -> tuple[np.ndarray, ...]:
    return tuple(np.stack([getattr(net, k) for net in nets])
                 for k in ("tau", "theta", "weights", "sensor_weights"))


# ---------------------------------------------------------------------------------------------
# Batch


@pytest.mark.parametrize("method", ["euler", "rk4"])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_each_row_gives_the_bits_of_network_run(method: str, dtype: type) -> None:
    nets = networks(7, seed=3)
    batch = Batch(nets, replicas=3, dt=0.05, substeps=4, method=method)
    rng = np.random.default_rng(1)
    inputs = rng.uniform(-2, 2, size=(10, batch.rows, 2)).astype(dtype)
    out = np.empty((batch.rows, batch.size))
    for row in inputs:
        assert batch.step(row, out=out) is out
    for r in range(batch.rows):
        net = nets[r // 3].copy()
        trace = net.run(inputs[:, r].astype(np.float64), dt=0.05, substeps=4, method=method)
        assert np.array_equal(batch.states[r], trace.states[-1])
        assert np.array_equal(out[r], trace.outputs[-1])


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 6), m=st.integers(0, 3), p=st.integers(1, 20), replicas=st.integers(1, 3),
       steps=st.integers(1, 6), seed=st.integers(0, 10_000), method=st.sampled_from(["euler", "rk4"]))
def test_a_batch_agrees_with_the_numpy_reference(n: int, m: int, p: int, replicas: int, steps: int,
                                                 seed: int, method: str) -> None:
    """Rows stepped only while active, against tests/reference.py integrating the same inputs."""
    nets = networks(p, n, m, seed=seed)
    for net in nets:
        net.reset()
    batch = Batch(nets, replicas=replicas, dt=0.1, substeps=2, method=method)
    rows = batch.rows
    rng = np.random.default_rng(seed)
    inputs = rng.uniform(-1, 1, size=(steps, rows, m))
    active = rng.random((steps, rows)) < 0.7
    for t in range(steps):
        batch.step(inputs[t], active=active[t])
    tau, theta, w, s = (np.repeat(x, replicas, axis=0) for x in params(nets))
    v = np.zeros((rows, n))
    do_step = ref.step(method)
    for t in range(steps):
        for _ in range(2):
            moved = do_step(v, 0.1, (tau, theta, w, s), inputs[t])
            v = np.where(active[t][:, None], moved, v)
    np.testing.assert_allclose(batch.states, v, rtol=1e-12, atol=1e-12)


def test_rows_left_out_keep_their_state_and_may_hold_anything() -> None:
    batch = Batch(networks(5), replicas=2)
    out = np.full((10, 4), -1.0)
    inputs = np.ones((10, 2))
    inputs[3] = np.nan
    active = np.ones(10, dtype=bool)
    active[3] = False
    batch.step(inputs, active=active, out=out)
    assert np.all(batch.states[3] == 0) and np.all(out[3] == -1.0)
    assert np.all(out[active] != -1.0)


def test_reset_set_states_and_rates() -> None:
    nets = networks(3)
    batch = Batch(nets, replicas=2)
    batch.step(np.ones((6, 2)))
    before = batch.states
    batch.reset([1, -1])
    after = batch.states
    assert np.all(after[[1, 5]] == 0) and np.array_equal(after[[0, 2, 3, 4]], before[[0, 2, 3, 4]])
    batch.set_states(np.full((6, 4), 0.5), rows=np.array([False, False, True, False, False, False]))
    assert np.all(batch.states[2] == 0.5)
    theta = nets[1].theta
    np.testing.assert_array_equal(batch.rates[2], 1 / (1 + np.exp(-(0.5 - theta))))
    batch.reset()
    assert not batch.states.any()
    assert (batch.rows, batch.networks, batch.replicas, batch.size, batch.n_inputs) == (6, 3, 2, 4, 2)
    assert len(batch) == 6 and "replicas=2" in repr(batch)
    assert batch.integrator == {"method": "euler", "dt": 0.1, "substeps": 1}


@pytest.mark.parametrize("call, message", [
    (lambda b: b.step(np.ones((5, 2))), r"inputs has shape \(5, 2\); expected \(B, M\) = \(4, 2\)"),
    (lambda b: b.step(np.full((4, 2), np.nan)), r"inputs\[0, 0\] is NaN"),
    (lambda b: b.step(np.ones((4, 2)), active=[1, 0, 1, 1]), "active is an array of dtype int64"),
    (lambda b: b.step(np.ones((4, 2)), active=np.ones(3, bool)), r"expected booleans of shape \(4,\)"),
    (lambda b: b.step(np.ones((4, 2)), out=np.empty((4, 4), np.float32)), "out is an array of dtype float32 and shape \\(4, 4\\); expected a float64"),
    (lambda b: b.step(np.ones((4, 2)), out=np.empty((4, 3))), r"out has shape \(4, 3\)"),
    (lambda b: b.step(np.ones((4, 2)), out=np.empty((4, 8))[:, ::2]), "not C-contiguous"),
    (lambda b: b.reset([4]), "rows holds index 4; this batch has 4 rows"),
    (lambda b: b.reset(np.array([0.5])), "expected a boolean mask"),
    (lambda b: b.set_states(np.full((4, 4), np.inf)), r"states\[0, 0\] is inf"),
    (lambda b: b.set_states(np.zeros((4, 3))), r"states has shape \(4, 3\)"),
])
def test_misuse_is_an_invalid_argument_error_that_names_it(call, message: str) -> None:
    batch = Batch(networks(2), replicas=2)
    with pytest.raises(InvalidArgumentError, match=message):
        call(batch)
    assert not batch.states.any()


def test_a_read_only_out_is_refused() -> None:
    batch = Batch(networks(1))
    out = np.empty((1, 4))
    out.flags.writeable = False
    with pytest.raises(InvalidArgumentError, match="out cannot be written"):
        batch.step(np.ones((1, 2)), out=out)


@pytest.mark.parametrize("kwargs, message", [
    ({"replicas": 0}, "replicas is 0"),
    ({"replicas": -1}, "replicas is -1"),
    ({"dt": float("nan")}, "dt"),
    ({"substeps": 0}, "substeps"),
    ({"method": "heun"}, "method"),
])
def test_bad_settings_are_refused(kwargs: dict, message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        Batch(networks(1), **kwargs)


def test_networks_of_different_shapes_are_refused() -> None:
    with pytest.raises(InvalidArgumentError, match="network 1 has N = 3"):
        Batch([dnnevo.Network.random(4, 2, seed=0), dnnevo.Network.random(3, 2, seed=0)])


# ---------------------------------------------------------------------------------------------
# rollout


def test_the_numpy_far_seeker_gives_the_built_in_fitness_bit_for_bit() -> None:
    """The protocol loses nothing: the paper's far seeker in NumPy against nav1d's Rust world."""
    config = dnnevo.presets.get("nav1d-far")
    config = dnnevo.EvolutionConfig(**{**config.to_dict(), "population": 96})
    nets = dnnevo.GeneticAlgorithm(config, seed=5).ask().networks
    built_in = dnnevo.evaluate("nav1d-far", nets, generation=0, seed=5, config=config)
    result = rollout(nets, FarSeeker(), episodes=2, max_steps=10_000, dt=0.1, substeps=1)
    assert np.array_equal(result.fitness, built_in)
    assert 0 < built_in.mean() < 1  # the population is neither all right nor all wrong
    assert result.returns.shape == result.lengths.shape == (96, 2)
    assert result.lengths.max() <= 10_000 and result.lengths.min() >= 1


class Drift:
    """A 1-D world: the agent drifts at the rate of neuron 0 towards a target drawn per episode."""

    observation_size = 1

    def __init__(self, length: int = 5) -> None:
        self.length = length
        self.drawn: list[np.ndarray] = []

    def reset(self, episodes, rng):
        targets = rng.uniform(-1, 1, size=episodes.max() + 1)
        self.drawn.append(targets)
        self.target = targets[episodes]
        self.x = np.zeros(len(episodes))
        self.t = 0
        return (self.target - self.x)[:, None]

    def step(self, rates, active):
        self.x = self.x + 0.1 * rates[:, 0]
        self.t += 1
        done = np.full(len(self.x), self.t >= self.length)
        return (self.target - self.x)[:, None], -np.abs(self.target - self.x), done


def test_rollout_with_its_defaults_scores_as_closed_loop_with_its_defaults() -> None:
    """A champion evolved by ClosedLoop with its defaults and judged by rollout with its
    defaults meets the same time step (both are the run config's [integrator])."""
    from dnnevo.closedloop import ClosedLoop

    nets = networks(6, m=1)
    by_rollout = rollout(nets, Drift(length=40), episodes=3, max_steps=40, seed=2, generation=1).fitness
    by_loop = ClosedLoop(Drift(length=40), episodes=3, max_steps=40)(nets, generation=1, seed=2)
    assert np.array_equal(by_rollout, by_loop)
    coarse = rollout(nets, Drift(length=40), episodes=3, max_steps=40, seed=2, generation=1, substeps=1)
    assert not np.array_equal(coarse.fitness, by_loop)  # the step matters for this world


def test_conditions_are_common_to_every_network_and_follow_seed_and_generation() -> None:
    nets = networks(4, m=1)
    env = Drift()
    a = rollout(nets, env, episodes=3, max_steps=50, seed=1, generation=2)
    b = rollout(nets, env, episodes=3, max_steps=50, seed=1, generation=2)
    rollout(nets, env, episodes=3, max_steps=50, seed=1, generation=3)
    assert np.array_equal(env.drawn[0], env.drawn[1]) and not np.array_equal(env.drawn[0], env.drawn[2])
    assert np.array_equal(a.returns, b.returns)
    assert np.all(a.lengths == 5)
    # One network copied four times scores the same in every row: the episodes are common.
    same = rollout([nets[0]] * 4, Drift(), episodes=3, max_steps=50, seed=1, generation=2)
    assert np.all(same.returns == same.returns[0])


def test_ended_episodes_stop_counting_and_the_step_limit_holds() -> None:
    result = rollout(networks(2, m=1), Drift(length=1000), episodes=2, max_steps=7)
    assert np.all(result.lengths == 7)


class Broken(Drift):
    def __init__(self, fault: str) -> None:
        super().__init__()
        self.fault = fault

    def reset(self, episodes, rng):
        obs = super().reset(episodes, rng)
        return obs[:, 0] if self.fault == "reset shape" else obs

    def step(self, rates, active):
        obs, reward, done = super().step(rates, active)
        fault = self.fault
        if fault == "raises":
            raise KeyError("velocity")
        if fault == "nan obs":
            obs[0] = np.nan
        if fault == "nan reward":
            reward[1] = np.nan
        if fault == "nan once" and self.t == 2:
            reward[3] = np.nan
        if fault == "overflow":
            reward[:] = 1e308
        if fault == "large once" and self.t == 1:
            reward[:] = 1e308  # every return finite, though their sum is not
        if fault == "text obs":
            obs = np.array([["a"]] * len(obs))
        if fault == "float done":
            done = done.astype(float)
        if fault == "two done":
            done = done.astype(int) * 2
        if fault == "bool done":
            done = bool(done[0])
        if fault == "pair":
            return obs, reward
        if fault == "none":
            return None
        return obs, reward, done


@pytest.mark.parametrize("fault, message", [
    ("raises", r"Broken.step raised KeyError: 'velocity'"),
    ("nan obs", r"Broken.step returned observations that are not finite \(inputs\[0, 0\] is NaN"),
    ("nan reward", r"Broken.step returned rewards\[1\] = nan"),
    # Returns are checked when an episode ends: an earlier reward is named by its row.
    ("nan once", r"Broken.step returned rewards that made row 3's return nan; every reward"),
    pytest.param("overflow", r"made row 0's return inf; .* below 1.8e308 \(scale the rewards down",
                 marks=pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")),
    ("text obs", r"observations from step of dtype <U1; expected numbers"),
    ("float done", r"Broken.step returned done as an array of dtype float64 and shape \(8,\); expected "
                   r"booleans \(or integers 0 and 1\) of shape \(B,\) = \(8,\)"),
    # 2 is not a flag: guessing that it means True would hide a mistake
    ("two done", r"Broken.step returned done as an array of dtype int64 and shape \(8,\); expected booleans"),
    ("bool done", r"Broken.step returned done as a bool \(bool, shape \(\)\); expected booleans \(or integers "
                  r"0 and 1\) of shape \(B,\)"),
    ("pair", r"Broken.step returned a tuple of 2; expected three values \(observations, rewards, done\)"),
    ("none", r"Broken.step returned None \(does it end with a return\?\); expected three values"),
    ("reset shape", r"Broken.reset returned observations of shape \(8,\); expected \(B, M\) = \(8, 1\)"),
])
def test_a_broken_task_gets_a_task_error_naming_the_method(fault: str, message: str) -> None:
    with pytest.raises(TaskError, match=message):
        rollout(networks(4, m=1), Broken(fault), episodes=2, max_steps=10)


class IntegerFlags(Drift):
    """Drift with done, and a success rule, given as integers 0 and 1."""
    success_rate = 0.3

    def step(self, rates, active):
        obs, reward, done = super().step(rates, active)
        return obs, reward, done.astype(np.int8)

    def success(self, returns, lengths):
        return (returns > -2).astype(int)


def test_integers_0_and_1_are_flags_as_booleans_are() -> None:
    from dnnevo.closedloop import ClosedLoop

    class BoolFlags(IntegerFlags):
        def step(self, rates, active):
            return Drift.step(self, rates, active)

        def success(self, returns, lengths):
            return returns > -2

    nets = networks(6, m=1)
    ints, bools = (rollout(nets, env, episodes=3, max_steps=20, seed=1) for env in (IntegerFlags(), BoolFlags()))
    assert np.array_equal(ints.returns, bools.returns) and np.array_equal(ints.lengths, bools.lengths)
    judged = [[ClosedLoop(env, episodes=3, max_steps=20).succeeds(n, seed=3) for n in nets]
              for env in (IntegerFlags(), BoolFlags())]
    assert judged[0] == judged[1] and set(judged[0]) == {0.0, 1.0}


def test_a_success_rule_that_returns_no_flags_is_named() -> None:
    from dnnevo.closedloop import ClosedLoop

    class Scores(IntegerFlags):
        def success(self, returns, lengths):
            return returns  # floats: no flags

    with pytest.raises(TaskError, match=r"Scores.success returned float64 of shape \(40,\); expected booleans "
                                        r"\(or integers 0 and 1\) of shape \(40,\), one per episode"):
        ClosedLoop(Scores(), episodes=3, max_steps=20).succeeds(networks(1, m=1)[0], seed=3)


def test_observation_size_must_match_the_networks() -> None:
    with pytest.raises(TaskError, match="Drift.observation_size is 1; the networks have 2 inputs"):
        rollout(networks(2, m=2), Drift(), max_steps=3)


class _Sized(Drift):
    def __init__(self, size: object) -> None:
        self.observation_size = size


class _Unsized(Drift):
    observation_size = property(lambda self: self.missing)  # an attribute it does not have


@pytest.mark.parametrize("env, message", [
    (_Sized("1"), "_Sized.observation_size is '1'; expected the number of observations the task gives "
                  "at each step, a whole number >= 0"),
    (_Sized(1.0), "_Sized.observation_size is 1.0; expected"),
    (_Sized(True), "_Sized.observation_size is True; expected"),
    (_Sized(-1), "_Sized.observation_size is -1; expected"),
    (_Unsized(), "_Unsized has no observation_size; give it the number of observations"),
])
def test_an_observation_size_that_is_no_count_is_refused_alike_everywhere(env, message: str) -> None:
    """rollout and ClosedLoop check it as the command line does: they took a string, a float or
    none at all before."""
    with pytest.raises(TaskError) as rolled:
        rollout(networks(2, m=1), env, max_steps=3)
    with pytest.raises(TaskError) as made:
        ClosedLoop(env, max_steps=3)
    assert message in str(rolled.value) and message in str(made.value)


def test_closed_loop_takes_an_environment_not_its_class() -> None:
    with pytest.raises(dnnevo.ConfigError, match=r"env is the class Drift; ClosedLoop takes an "
                                                 r"environment made from it, Drift\(...\)"):
        ClosedLoop(Drift, max_steps=3)


def test_condition_seed_checks_its_arguments() -> None:
    seed = dnnevo._core.condition_seed
    assert seed(0, 0) != seed(0, 1) != seed(1, 0)
    assert seed(3, 4, "validate") != seed(3, 4)
    with pytest.raises(InvalidArgumentError, match="seed is -1"):
        seed(-1, 0)
    with pytest.raises(InvalidArgumentError, match="purpose is 'test'"):
        seed(0, 0, "test")


# ---------------------------------------------------------------------------------------------
# evolve


def test_a_closed_loop_run_resumes_to_the_end_of_an_unbroken_one(tmp_path) -> None:
    from dnnevo.closedloop import ClosedLoop

    config = dnnevo.EvolutionConfig(population=24, generations=4, size=3, n_inputs=1, selection="rank")
    fitness = ClosedLoop(Drift(), episodes=3, max_steps=20)
    whole = dnnevo.evolve(fitness, config, seed=2, progress=False, out=tmp_path / "whole")
    part = dnnevo.evolve(fitness, config, seed=2, progress=False, out=tmp_path / "part",
                         callback=lambda stats, ga: ga.generation >= 2)
    assert len(part.history["best"]) == 2
    text = (tmp_path / "part" / "config.toml").read_text()
    assert 'task = "python:test_closedloop.Drift"' in text
    with pytest.raises(dnnevo.ConfigError, match=r"was evolved with python:test_closedloop.Drift, not "
                                                 r"python:test_closedloop.Drift as made here \(the rollout's settings"):
        dnnevo.resume(tmp_path / "part", ClosedLoop(Drift(), episodes=4, max_steps=20), progress=False)
    resumed = dnnevo.resume(tmp_path / "part", ClosedLoop(Drift(), episodes=3, max_steps=20),
                            progress=False)
    assert np.array_equal(resumed.history["best"], whole.history["best"])
    assert resumed.best == whole.best


def test_a_fitness_function_that_asks_gets_the_generation_and_the_seed() -> None:
    seen = []

    def fitness(networks, *, generation, seed):
        seen.append((generation, seed))
        return np.zeros(len(networks))

    config = dnnevo.EvolutionConfig(population=8, generations=3, size=2, n_inputs=1)
    dnnevo.evolve(fitness, config, seed=7, progress=False)
    assert seen == [(0, 7), (1, 7), (2, 7)]


def test_a_run_started_as_a_script_resumes_from_a_module_that_imports_the_same_code(tmp_path) -> None:
    """A run of ``python light.py`` names ``__main__.Light``; another script that does ``from
    light import Light`` resumes it, since the source is the same. An edited source is refused."""
    (tmp_path / "light.py").write_text(
        "import numpy as np, dnnevo\n"
        "from dnnevo.closedloop import ClosedLoop\n"
        "class Light:\n"
        "    observation_size = 1\n"
        "    def reset(self, episodes, rng):\n"
        "        self.x = np.zeros(len(episodes))\n"
        "        return np.ones((len(episodes), 1))\n"
        "    def step(self, rates, active):\n"
        "        self.x += rates[:, 0]\n"
        "        return np.ones((len(self.x), 1)), self.x.copy(), self.x > 3\n"
        "if __name__ == '__main__':\n"
        "    config = dnnevo.EvolutionConfig(population=8, generations=3, size=2, n_inputs=1)\n"
        "    dnnevo.evolve(ClosedLoop(Light(), max_steps=10), config, out='run', progress=False,\n"
        "                  callback=lambda stats, ga: ga.generation >= 1)\n"
        "    from dnnevo.figures import draw_run\n"
        "    print(draw_run('run'))  # the script that defined the class can draw its run\n")
    import subprocess
    import sys
    drawn = subprocess.run([sys.executable, "light.py"], cwd=tmp_path, check=True, capture_output=True, text=True)
    assert "episodes.png" in drawn.stdout, drawn.stdout + drawn.stderr
    assert 'task = "python:__main__.Light"' in (tmp_path / "run" / "config.toml").read_text()
    sys.path.insert(0, str(tmp_path))
    try:
        import light
    finally:
        sys.path.remove(str(tmp_path))
    from dnnevo.closedloop import ClosedLoop

    done = dnnevo.resume(tmp_path / "run", ClosedLoop(light.Light(), max_steps=10), progress=False)
    assert len(done.history["best"]) == 3
    # The command line cannot import a script's class, and says so instead of pointing at assess.
    shown = dnnevo_command(tmp_path, "show", "run")
    assert "next: python:__main__.Light was defined in a script" in shown.stdout, shown.stdout
    judged = dnnevo_command(tmp_path, "assess", "run")
    assert judged.returncode == 2 and "is a class defined in a script" in judged.stderr, judged.stderr
    with pytest.raises(dnnevo.ConfigError, match="was evolved with python:__main__.Light"):
        dnnevo.resume(tmp_path / "run", ClosedLoop(light.Light(), max_steps=11), progress=False,
                      generations=4)


# ---------------------------------------------------------------------------------------------
# a task named in config.toml: dnnevo run, resume, show and assess


SEEKER = '''
import json

import numpy as np

from dnnevo.tasks.protocol import Analysis


class Seeker:
    """A 1-D agent seeks a light."""

    observation_size = 1
    success_rate = 0.9

    def __init__(self, speed=0.1):
        self.speed = speed

    def reset(self, episodes, rng):
        lights = rng.uniform(-5, 5, size=episodes.max() + 1)
        self.light, self.x = lights[episodes], np.zeros(len(episodes))
        return np.sign(self.light - self.x)[:, None]

    def step(self, rates, active):
        self.x += self.speed * (rates[:, 1] - rates[:, 0])
        distance = np.abs(self.light - self.x)
        return np.sign(self.light - self.x)[:, None], -distance, distance < 0.05

    def success(self, returns, lengths):
        return lengths < 300


class Ruleless(Seeker):
    success_rate = None


class Sizeless(Seeker):
    observation_size = None


class Blind(Seeker):
    """No sensor: the light is always at 1, and a network must find it from its own dynamics."""

    observation_size = 0
    analysis = Analysis(input_names=[], conditions={"free": []}, main_input=0, output_neuron=0,
                        episodes=1)

    def reset(self, episodes, rng):
        self.light, self.x = np.ones(len(episodes)), np.zeros(len(episodes))
        return np.zeros((len(episodes), 0))

    def step(self, rates, active):
        _, reward, done = super().step(rates, active)
        return np.zeros((len(rates), 0)), reward, done


def not_a_class():
    pass
'''

SETTINGS = ["--set", "n_inputs=1", "--set", "size=3", "--set", "selection=rank", "--set",
            "task_params.max_steps=300", "--set", "task_params.episodes=4", "--set", "population=60",
            "--set", "generations=6"]


def dnnevo_command(folder, *args: str):
    """The installed ``dnnevo`` command (not ``python -m``, which would put the folder on the
    path) run in ``folder``."""
    import subprocess
    import sys
    from pathlib import Path

    command = Path(sys.executable).parent / "dnnevo"
    return subprocess.run([str(command), *args], cwd=folder, capture_output=True, text=True,
                          timeout=300)


def test_a_task_class_named_on_the_command_line_runs_resumes_and_is_judged(tmp_path) -> None:
    (tmp_path / "seeker_cli.py").write_text(SEEKER)
    run = dnnevo_command(tmp_path, "run", "python:seeker_cli.Seeker", *SETTINGS)
    assert run.returncode == 0, run.stderr
    folder = tmp_path / "runs" / "seeker_cli.Seeker-seed0"
    text = (folder / "config.toml").read_text()
    assert 'task = "python:seeker_cli.Seeker"' in text and "max_steps = 300" in text
    assert "next: dnnevo assess runs/seeker_cli.Seeker-seed0" in run.stdout
    more = dnnevo_command(tmp_path, "resume", "runs/seeker_cli.Seeker-seed0", "--generations", "8")
    assert more.returncode == 0, more.stderr
    judged = dnnevo_command(tmp_path, "assess", "runs/seeker_cli.Seeker-seed0", "--seed", "3")
    assert judged.returncode in (0, 1, 3), judged.stderr
    assert "fresh episodes (seed 3)" in judged.stdout and "needs" in judged.stdout
    assert "note: all" not in judged.stdout  # each episode draws its light
    drawn = dnnevo_command(tmp_path, "plot", "runs/seeker_cli.Seeker-seed0", "--seed", "3")
    assert drawn.returncode == 0, drawn.stderr
    assert (folder / "episodes.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # show runs no code of the task: the module's top level is not run, and show works with
    # the module gone.
    (tmp_path / "seeker_cli.py").write_text(SEEKER + "\nopen('imported.marker', 'w').close()\n")
    shown = dnnevo_command(tmp_path, "show", "runs/seeker_cli.Seeker-seed0")
    assert shown.returncode == 0 and "next: dnnevo assess" in shown.stdout, shown.stderr
    assert not (tmp_path / "imported.marker").exists()
    (tmp_path / "seeker_cli.py").unlink()
    shown = dnnevo_command(tmp_path, "show", "runs/seeker_cli.Seeker-seed0")
    assert shown.returncode == 0 and "8/8 generations" in shown.stdout, shown.stderr
    gone = dnnevo_command(tmp_path, "resume", "runs/seeker_cli.Seeker-seed0", "--generations", "9")
    assert gone.returncode == 2 and "cannot import seeker_cli" in gone.stderr
    gone = dnnevo_command(tmp_path, "plot", "runs/seeker_cli.Seeker-seed0")
    assert gone.returncode == 2 and "cannot import seeker_cli" in gone.stderr


@pytest.mark.parametrize("task, settings, message", [
    ("python:seeker_bad.Nope", SETTINGS, "has no Nope"),
    ("python:seeker_bad.Seekr", SETTINGS, "seeker_bad.py) has no Seekr (did you mean 'Seeker'?)"),
    ("python:code.Seeker", SETTINGS, "module code (/"),  # the standard library's, named by its file
    ("python:seeker_bad.not_a_class", SETTINGS, "is a function; a task is a class with observation_size"),
    ("python:seeker_bad.Sizeless", SETTINGS, "Sizeless.observation_size is None; expected the number of observations"),
    ("python:seeker_bad_missing.Seeker", SETTINGS, "cannot import seeker_bad_missing"),
    ("python:seeker_bad.Seeker", ["--set", "n_inputs=1"], "needs task_params.max_steps"),
    ("python:seeker_bad.Seeker", SETTINGS + ["--set", "n_inputs=2"], "n_inputs is 2; Seeker.observation_size is 1"),
    ("python:seeker_bad.Seeker", SETTINGS + ["--set", "task_params.sped=1"], "Seeker(**task_params) failed"),
])
def test_a_bad_task_name_or_setting_is_one_line(tmp_path, task: str, settings: list[str], message: str) -> None:
    (tmp_path / "seeker_bad.py").write_text(SEEKER)
    r = dnnevo_command(tmp_path, "run", task, *settings)
    assert r.returncode == 2 and message in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
    assert not (tmp_path / "runs").exists() or not any((tmp_path / "runs").iterdir())


def test_a_run_whose_task_failed_in_generation_0_is_replaced_by_the_next_run(tmp_path) -> None:
    """Nothing was evolved, and resuming could only fail again or, once the code is fixed, be
    refused by the digest: the fixed command simply runs. A run that scored a generation is
    still refused."""
    broken = SEEKER.replace("        self.x += self.speed", "        raise ValueError('my bug')\n        self.x += self.speed")
    (tmp_path / "seeker_g0.py").write_text(broken)
    failed = dnnevo_command(tmp_path, "run", "python:seeker_g0.Seeker", *SETTINGS)
    assert failed.returncode == 2 and "my bug" in failed.stderr, failed.stderr
    (tmp_path / "seeker_g0.py").write_text(SEEKER)
    fixed = dnnevo_command(tmp_path, "run", "python:seeker_g0.Seeker", *SETTINGS)
    assert fixed.returncode == 0, fixed.stderr
    again = dnnevo_command(tmp_path, "run", "python:seeker_g0.Seeker", *SETTINGS)
    assert again.returncode == 2 and "it holds a run: resume it" in again.stderr, again.stderr


def test_a_class_edited_after_its_run_is_refused_by_every_command_that_runs_the_champion(tmp_path) -> None:
    (tmp_path / "seeker_edit.py").write_text(SEEKER)
    run = dnnevo_command(tmp_path, "run", "python:seeker_edit.Seeker", *SETTINGS)
    assert run.returncode == 0, run.stderr
    (tmp_path / "seeker_edit.py").write_text(SEEKER.replace("speed=0.1", "speed=0.25"))
    for command in ("plot", "assess", "analyze"):
        r = dnnevo_command(tmp_path, command, "runs/seeker_edit.Seeker-seed0")
        assert r.returncode == 2 and "evolved with another version of python:seeker_edit.Seeker" in r.stderr, \
            (command, r.stderr)
        # The new default changed the class's source and the environment's attributes, not the rollout.
        assert "source" in r.stderr and "attributes differ" in r.stderr and "settings" not in r.stderr
    # Each part that differs is named, and only those.
    (tmp_path / "seeker_edit.py").write_text(SEEKER.replace("success_rate = 0.9", "success_rate = 0.95"))
    r = dnnevo_command(tmp_path, "assess", "runs/seeker_edit.Seeker-seed0")
    assert "a success rule added or changed counts" in r.stderr and "attributes" not in r.stderr, r.stderr


def test_a_fitness_that_tells_no_networks_apart_is_warned_about(tmp_path) -> None:
    # 0.1 at every step, no episode ending early: the std of equal returns is not exactly 0
    # (about 1e-16), best = min is.
    flat = SEEKER.replace("return np.sign(self.light - self.x)[:, None], -distance, distance < 0.05",
                          "return np.sign(self.light - self.x)[:, None], 0 * distance + 0.1, distance < -1")
    (tmp_path / "seeker_flat.py").write_text(flat)
    run = dnnevo_command(tmp_path, "run", "python:seeker_flat.Seeker", *SETTINGS)
    assert run.returncode == 0, run.stderr
    warning = "warning: every network scored the same in every one of its 6 generations (best = min in log.csv)"
    assert warning in run.stdout, run.stdout
    assert warning in dnnevo_command(tmp_path, "show", "runs/seeker_flat.Seeker-seed0").stdout
    (tmp_path / "seeker_ok.py").write_text(SEEKER)
    assert "warning" not in dnnevo_command(tmp_path, "run", "python:seeker_ok.Seeker", *SETTINGS).stdout


def test_n_inputs_defaults_to_the_class_s_observation_size_on_the_command_line(tmp_path) -> None:
    (tmp_path / "seeker_size.py").write_text(SEEKER)
    without = [a for a in SETTINGS if a != "n_inputs=1"]
    without.remove("--set")  # the one that went with n_inputs=1
    run = dnnevo_command(tmp_path, "run", "python:seeker_size.Seeker", *without)
    assert run.returncode == 0, run.stderr
    assert "n_inputs = 1" in (tmp_path / "runs" / "seeker_size.Seeker-seed0" / "config.toml").read_text()
    # An explicit setting is kept, and a wrong one is still named.
    wrong = dnnevo_command(tmp_path, "run", "python:seeker_size.Seeker", *without, "--set", "n_inputs=2",
                           "--out", "runs/wrong")
    assert wrong.returncode == 2 and "n_inputs is 2; Seeker.observation_size is 1" in wrong.stderr


def test_a_task_without_sensors_runs_and_is_judged_from_the_command_line(tmp_path) -> None:
    """A pattern generator's task gives its networks no input (observation_size = 0), as
    Python's evolve always allowed; the command line refused it."""
    (tmp_path / "seeker_blind.py").write_text(SEEKER)
    without = [a for a in SETTINGS if a != "n_inputs=1"]
    without.remove("--set")
    run = dnnevo_command(tmp_path, "run", "python:seeker_blind.Blind", *without)
    assert run.returncode == 0, run.stderr
    assert "n_inputs = 0" in (tmp_path / "runs" / "seeker_blind.Blind-seed0" / "config.toml").read_text()
    judged = dnnevo_command(tmp_path, "assess", "runs/seeker_blind.Blind-seed0", "--seed", "1", "--trials", "8")
    assert judged.returncode in (0, 1, 3) and "episodes" in judged.stdout, judged.stderr
    # The light never moves: every episode is the same, and assess says what that does to the count.
    assert "note: all 8 episodes gave the same return and length" in judged.stdout
    analysed = dnnevo_command(tmp_path, "analyze", "runs/seeker_blind.Blind-seed0", "--no-lesions")
    assert analysed.returncode == 0 and "no sweep: the network has no input to vary" in analysed.stdout, \
        analysed.stderr
    doc = json.loads((tmp_path / "runs" / "seeker_blind.Blind-seed0" / "analysis.json").read_text())
    assert doc["bifurcation"] is None and doc["conditions"][0]["input"] == []


def test_a_task_without_a_success_rule_cannot_be_judged(tmp_path) -> None:
    (tmp_path / "seeker_rule.py").write_text(SEEKER)
    run = dnnevo_command(tmp_path, "run", "python:seeker_rule.Ruleless", *SETTINGS)
    assert run.returncode == 0, run.stderr
    # Every network's validation rate is 0 without a rule: the bar gives the score that chose.
    bar = run.stderr.strip().splitlines()[-1]
    assert " (validation score " in bar and "validation rate" not in bar, bar
    # The run's last line points at what works for it: plot, not assess.
    assert run.stdout.splitlines()[-1].startswith(
        "next: dnnevo plot runs/seeker_rule.Ruleless-seed0   (draws the champion on fresh episodes; "
        "dnnevo assess needs a success rule"), run.stdout
    r = dnnevo_command(tmp_path, "assess", "runs/seeker_rule.Ruleless-seed0")
    assert r.returncode == 2 and "has no success rule: give Ruleless a success_rate" in r.stderr
    # show says the same from log.csv alone, with the module gone.
    (tmp_path / "seeker_rule.py").unlink()
    shown = dnnevo_command(tmp_path, "show", "runs/seeker_rule.Ruleless-seed0")
    assert shown.returncode == 0 and "next: dnnevo plot runs/seeker_rule.Ruleless-seed0" in shown.stdout, shown.stdout
    (tmp_path / "seeker_rule.py").write_text(SEEKER)
    # From another folder the class cannot be imported, and the error says where to run from.
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    r = dnnevo_command(elsewhere, "assess", "../runs/seeker_rule.Ruleless-seed0")
    assert r.returncode == 2 and "run the command from the folder that holds seeker_rule.py" in r.stderr, r.stderr


def test_naming_the_task_or_passing_it_evolves_the_same(tmp_path, monkeypatch) -> None:
    from dnnevo.closedloop import ClosedLoop

    (tmp_path / "seeker_py.py").write_text(SEEKER)
    monkeypatch.syspath_prepend(str(tmp_path))
    import seeker_py

    base = dnnevo.EvolutionConfig(population=30, generations=3, size=3, n_inputs=1, selection="rank")
    config = dnnevo.EvolutionConfig(**{**base.to_dict(), "task": "python:seeker_py.Seeker",
                                       "task_params": {"max_steps": 100, "episodes": 2}})
    by_name = dnnevo.evolve("python:seeker_py.Seeker", config, seed=4, progress=False)
    loop = ClosedLoop(seeker_py.Seeker(), episodes=2, max_steps=100, substeps=10)
    by_object = dnnevo.evolve(loop, base, seed=4, progress=False)
    assert by_object.config == by_name.config
    assert np.array_equal(by_name.history["best"], by_object.history["best"])


def test_an_interrupted_run_says_how_to_resume_it_where_it_can_be(tmp_path, monkeypatch, capsys) -> None:
    """After an interrupt the run names ``dnnevo resume`` only when the command builds its task
    again from config.toml; else it names dnnevo.resume from Python with the same task."""
    from dnnevo.closedloop import ClosedLoop

    (tmp_path / "seeker_stop.py").write_text(SEEKER)
    monkeypatch.syspath_prepend(str(tmp_path))
    import seeker_stop

    def ctrl_c(stats, ga):
        raise KeyboardInterrupt

    tagged = seeker_stop.Seeker(speed=0.2)
    tagged.tag = 1  # set after it was made: config.toml cannot record it
    config = dnnevo.EvolutionConfig(population=10, generations=3, size=3, n_inputs=1, selection="rank")
    for task, folder, hint in [
        (ClosedLoop(seeker_stop.Seeker(speed=0.2), episodes=2, max_steps=50), "told", "dnnevo resume "),
        (ClosedLoop(tagged, episodes=2, max_steps=50), "other", "dnnevo.resume("),
        (lambda nets: np.zeros(len(nets)), "function", "dnnevo.resume("),
    ]:
        dnnevo.evolve(task, config, out=tmp_path / folder, progress=False, callback=ctrl_c)
        err = capsys.readouterr().err
        assert f"Resume with: {hint}" in err, (folder, err)
    dnnevo.resume(tmp_path / "told", progress=False, callback=ctrl_c)
    assert f"Resume with: dnnevo resume {tmp_path / 'told'}" in capsys.readouterr().err
    # A class of a script, even named, is the script's alone.
    script = SEEKER + (
        "\nimport dnnevo\n\ndef stop(stats, ga):\n    raise KeyboardInterrupt\n\n"
        "config = dnnevo.EvolutionConfig(population=10, generations=3, size=3, n_inputs=1, selection='rank',\n"
        "                                task_params={'max_steps': 20, 'episodes': 2})\n"
        "dnnevo.evolve('python:__main__.Seeker', config, out='script-run', progress=False, callback=stop)\n")
    (tmp_path / "script.py").write_text(script)
    import subprocess
    import sys

    err = subprocess.run([sys.executable, "script.py"], cwd=tmp_path, capture_output=True, text=True).stderr
    assert "Resume with: dnnevo.resume('script-run', task=...) from Python" in err, err


def test_a_run_begun_from_python_is_judged_only_by_the_task_it_evolved(tmp_path, monkeypatch, capsys) -> None:
    """config.toml records an environment object's arguments only when they can be told from
    it (ClosedLoop.arguments): else a command that builds the task from it builds Seeker() with
    its defaults, and the digest says that is another task."""
    from dnnevo.closedloop import ClosedLoop

    (tmp_path / "seeker_arg.py").write_text(SEEKER)
    monkeypatch.syspath_prepend(str(tmp_path))
    import seeker_arg

    def seeker(speed: float, tagged: bool):
        env = seeker_arg.Seeker(speed=speed)
        if tagged:
            env.tag = 1  # set after it was made: no arguments make it again
        return env

    config = dnnevo.EvolutionConfig(population=10, generations=2, size=3, n_inputs=1, selection="rank")
    for speed, tagged, folder in [(0.1, False, "same"), (0.2, False, "told"), (0.2, True, "other")]:
        loop = ClosedLoop(seeker(speed, tagged), episodes=2, max_steps=50)
        dnnevo.evolve(loop, config, out=tmp_path / folder, progress=False)
        # The run says at its start when the command line will not build its task again, and
        # names the attributes set after __init__.
        err = capsys.readouterr().err
        assert ("the command line will not judge, draw or resume" in err) == tagged, folder
        assert ("attributes speed, tag differ from those of one made from config.toml" in err) == tagged, err
    # An environment that ran episodes before it was wrapped keeps their state as attributes.
    used = seeker_arg.Seeker(speed=0.1)
    rollout(networks(2, n=3, m=1), used, max_steps=5)
    dnnevo.evolve(ClosedLoop(used, episodes=2, max_steps=50), config, out=tmp_path / "used", progress=False)
    assert "attributes light, x differ from those of one made from config.toml" in capsys.readouterr().err
    for folder in ("same", "told"):
        judged = dnnevo_command(tmp_path, "assess", folder, "--trials", "20")
        assert judged.returncode in (0, 1, 3) and "20 fresh episodes" in judged.stdout, judged.stderr
    assert "speed = 0.2" in (tmp_path / "told" / "config.toml").read_text()
    assert "speed" not in (tmp_path / "other" / "config.toml").read_text()
    other = dnnevo_command(tmp_path, "assess", "other")
    assert other.returncode == 2 and "another version of python:seeker_arg.Seeker" in other.stderr
    resumed = dnnevo_command(tmp_path, "resume", "other", "--generations", "3")
    assert resumed.returncode == 2 and "another version" in resumed.stderr
    # From Python, with the environment it began with, and by its name for the others.
    loop = ClosedLoop(seeker(0.2, True), episodes=2, max_steps=50)
    assert len(dnnevo.resume(tmp_path / "other", loop, generations=3, progress=False).history["best"]) == 3
    for folder in ("same", "told"):
        by_name = dnnevo.resume(tmp_path / folder, "python:seeker_arg.Seeker", generations=3, progress=False)
        assert len(by_name.history["best"]) == 3
    # Other arguments without new_fitness: refused, saying the attributes differ, not the source.
    with pytest.raises(ConfigError, match=r"not python:seeker_arg.Seeker as made here \(the environment's attributes"):
        dnnevo.resume(tmp_path / "told", ClosedLoop(seeker(0.3, False), episodes=2, max_steps=50),
                      generations=4, progress=False)
    # Continued with new arguments (a curriculum): config.toml says what the task is from then
    # on, so the command line still builds, judges and resumes it.
    harder = ClosedLoop(seeker(0.3, False), episodes=3, max_steps=40)
    dnnevo.resume(tmp_path / "same", harder, generations=4, new_fitness=True, progress=False)
    import tomllib
    table = tomllib.loads((tmp_path / "same" / "config.toml").read_text())
    assert table["task_params"] == {"speed": 0.3, "episodes": 3, "max_steps": 40}
    assert table["run"]["fitness_changes"] == [{"generation": 3, "task": "python:seeker_arg.Seeker",
                                                "task_params": table["task_params"]}]
    for command in (["assess", "same", "--trials", "20"], ["resume", "same", "--generations", "5"]):
        r = dnnevo_command(tmp_path, *command)
        assert r.returncode in (0, 1, 3), r.stderr


def test_a_fitness_function_run_is_neither_resumed_nor_judged_by_the_command_line(tmp_path) -> None:
    config = dnnevo.EvolutionConfig(population=6, generations=2, size=2, n_inputs=1)
    dnnevo.evolve(lambda nets: np.zeros(len(nets)), config, out=tmp_path / "f", progress=False)
    resumed = dnnevo_command(tmp_path, "resume", "f", "--generations", "3")
    assert resumed.returncode == 2 and "resume it from Python" in resumed.stderr
    judged = dnnevo_command(tmp_path, "assess", "f")
    assert judged.returncode == 2 and "has no success rule" in judged.stderr
    analysed = dnnevo_command(tmp_path, "analyze", "f", "--input", "1", "--no-lesions")
    assert analysed.returncode == 2 and "evolved with a Python fitness function" in analysed.stderr \
        and "dnnevo.analysis.attractors" in analysed.stderr, analysed.stderr


class Echo:
    """Hands the rates back as the next observations (N = M), and reads them later."""

    observation_size = 2

    def reset(self, episodes, rng):
        return np.zeros((len(episodes), 2))

    def step(self, rates, active):
        assert not rates.flags.writeable and not active.flags.writeable
        return rates, np.zeros(len(rates)), [False] * len(rates)


def test_the_environment_sees_read_only_arrays_and_may_return_the_rates() -> None:
    nets = [dnnevo.Network.random(2, 2, seed=s) for s in range(3)]
    result = rollout(nets, Echo(), episodes=2, max_steps=5)
    assert np.all(result.lengths == 5)


def test_a_diverging_integration_is_not_blamed_on_the_task() -> None:
    fast = dnnevo.Network(tau=[0.01], theta=[0.0], weights=[[0.0]], sensor_weights=[[1.0]])
    with pytest.raises(InvalidArgumentError, match=r"dt / tau is 10 for tau\[0\]") as caught:
        rollout([fast], Drift(length=1000), max_steps=1000, dt=0.1, substeps=100)
    assert not isinstance(caught.value, TaskError)
    # Two neurons always firing, each weighing 1e308 on both: the sum is past the largest f64.
    loud = dnnevo.Network(tau=[1.0, 1.0], theta=[-1e3, -1e3], weights=np.full((2, 2), 1e308),
                          sensor_weights=np.zeros((2, 1)))
    with pytest.raises(InvalidArgumentError, match="integration diverged") as caught:
        rollout([loud], Drift(length=1000), max_steps=1000, dt=0.1, substeps=100)
    assert not isinstance(caught.value, TaskError)


def test_the_digest_is_exact_and_ignores_what_changes_from_run_to_run() -> None:
    from dnnevo.closedloop import ClosedLoop

    class Slotted(Drift):
        __slots__ = ("weight",)

    def digest(env):
        return ClosedLoop(env, max_steps=5).digest()

    a, b = Drift(), Drift()
    a.w, b.w = np.array([0.1, 0.2]), np.array([0.1, 0.2 + 1e-15])
    assert digest(a) != digest(b)
    a.rng, b.rng = np.random.default_rng(1), np.random.default_rng(2)
    b.w = a.w.copy()
    assert digest(a) == digest(b)
    assert digest(Slotted()) == digest(Slotted())


def test_a_sweep_over_a_task_class_judges_every_seed_by_its_rule(tmp_path) -> None:
    (tmp_path / "seeker_sweep.py").write_text(SEEKER)
    r = dnnevo_command(tmp_path, "sweep", "python:seeker_sweep.Seeker", "--seeds", "0-1", "--out",
                       "sw", "--eval-trials", "20", *SETTINGS)
    assert r.returncode == 0, r.stderr
    summary = json.loads((tmp_path / "sw" / "summary.json").read_text())
    assert summary["seeds"] == [0, 1] and summary["eval_unit"] == "episodes"
    assert "final champions passing on fresh trials: " in r.stdout
    # The run checked its champions by the class's rule as it went (log.csv's champion_success).
    log = (tmp_path / "sw" / "seed-0" / "log.csv").read_text().splitlines()
    column = log[0].split(",").index("champion_success")
    assert {row.split(",")[column] for row in log[1:]} <= {"0", "1"}
    ruleless = dnnevo_command(tmp_path, "sweep", "python:seeker_sweep.Ruleless", "--seeds", "0",
                              "--out", "sw2", *SETTINGS)
    assert ruleless.returncode == 2 and "has no success rule" in ruleless.stderr
    assert not (tmp_path / "sw2").exists()
    # A task whose episodes are all alike is noted for each seed, as assess notes it.
    blind_settings = [a for a in SETTINGS if a != "n_inputs=1"]
    blind_settings.remove("--set")
    blind = dnnevo_command(tmp_path, "sweep", "python:seeker_sweep.Blind", "--seeds", "0", "--out", "sw3",
                           "--eval-trials", "8", "--no-dt-check", *blind_settings)
    assert blind.returncode == 0, blind.stderr
    assert "note: every fresh episode gave the same return and length" in blind.stdout + blind.stderr


def test_a_sweep_of_a_task_class_on_dask_workers_matches_one_in_process(tmp_path) -> None:
    """The workers build the task from its name, importing the user's module from the folder the
    command runs in, as the command itself does."""
    pytest.importorskip("distributed")
    (tmp_path / "seeker_dask.py").write_text(SEEKER)
    args = ["sweep", "python:seeker_dask.Seeker", "--seeds", "0-1", "--eval-trials", "20", *SETTINGS]
    here = dnnevo_command(tmp_path, *args, "--out", "here")
    there = dnnevo_command(tmp_path, *args, "--out", "there", "--workers", "2")
    assert here.returncode == 0 and there.returncode == 0, here.stderr + there.stderr
    assert "a local Dask cluster of 2 workers" in there.stdout

    def runs(out: str) -> list[dict]:
        summary = json.loads((tmp_path / out / "summary.json").read_text())
        return [{k: v for k, v in r.items() if k != "wall_s"} for r in summary["runs"]]

    assert runs("here") == runs("there")
    for seed in (0, 1):
        best = f"seed-{seed}/best.json"
        assert (tmp_path / "here" / best).read_bytes() == (tmp_path / "there" / best).read_bytes()


def test_large_finite_returns_are_not_an_error() -> None:
    result = rollout(networks(4, m=1), Broken("large once"), episodes=2, max_steps=10)
    assert np.isfinite(result.returns).all() and (result.returns > 1e307).all()


DIAL = '''
import numpy as np


class Dial:
    observation_size = 1
    success_rate = 0.5

    def __init__(self, speed=0.1, label="a", *, hidden=3):
        self.speed = speed
        self.label = label
        self._hidden = hidden

    def reset(self, episodes, rng):
        self.x = np.zeros(len(episodes))
        return np.ones((len(episodes), 1))

    def step(self, rates, active):
        self.x += self.speed * rates[:, 0]
        return np.ones((len(self.x), 1)), self.x.copy(), self.x > 3

    def success(self, returns, lengths):
        return returns > 0
'''


def test_a_run_begun_from_python_records_the_arguments_it_can_tell_and_the_command_line_judges_it(
        tmp_path) -> None:
    import sys

    (tmp_path / "dial.py").write_text(DIAL)
    sys.path.insert(0, str(tmp_path))
    try:
        import dial
    finally:
        sys.path.remove(str(tmp_path))
    assert ClosedLoop(dial.Dial(speed=0.2, label="b"), max_steps=5).arguments() == {"speed": 0.2, "label": "b"}
    assert ClosedLoop(dial.Dial(), max_steps=5).arguments() == {}
    # hidden is kept under another name: an object made from what can be told differs, so nothing
    # is recorded, not a part.
    assert ClosedLoop(dial.Dial(speed=0.2, hidden=4), max_steps=5).arguments() == {}
    config = dnnevo.EvolutionConfig(population=8, generations=2, size=2, n_inputs=1, selection="rank")
    dnnevo.evolve(ClosedLoop(dial.Dial(speed=0.2), max_steps=20), config, out=tmp_path / "run", progress=False)
    assert "speed = 0.2" in (tmp_path / "run" / "config.toml").read_text()
    judged = dnnevo_command(tmp_path, "assess", "run", "--trials", "20")
    assert judged.returncode in (0, 1, 3), judged.stderr
    assert "fresh episodes" in judged.stdout


class _Halfway:
    observation_size = 1

    def reset(self, episodes, rng):
        return np.zeros((len(episodes), 1))

    def step(self, rates, active):
        return np.zeros((len(rates), 1)), np.zeros(len(rates)), np.ones(len(rates), bool)


class _RuleWithoutRate(_Halfway):
    def success(self, returns, lengths):
        return returns > 0


class _RateWithoutRule(_Halfway):
    success_rate = 0.9


class _RateOutOfRange(_RuleWithoutRate):
    success_rate = 1.5


class _RuleTurnedOff(_RuleWithoutRate):
    success_rate = None


class _RateStatistic(_Halfway):
    success_rate = 0.0  # a statistic the environment keeps, not a rule's rate


class _FlagsArray(_Halfway):
    def __init__(self):
        self.success = np.zeros(3, bool)  # flags, not a rule's method


@pytest.mark.parametrize("env, message", [
    (_RuleWithoutRate(), "_RuleWithoutRate has a success method but no success_rate"),
    (_RateWithoutRule(), "_RateWithoutRule has a success_rate but no method success(returns, lengths)"),
    (_RateOutOfRange(), "_RateOutOfRange.success_rate is 1.5; expected a number in (0, 1]"),
])
def test_half_a_success_rule_is_refused_when_the_task_is_made(env, message: str) -> None:
    with pytest.raises(dnnevo.ConfigError, match=re.escape(message)):
        ClosedLoop(env, max_steps=5)
    for env in (_RuleTurnedOff(), _RateStatistic(), _FlagsArray()):  # no rule, as they always were
        ClosedLoop(env, max_steps=5)


THREADS_SCRIPT = '''
import sys
import numpy as np
import dnnevo
from dnnevo import _core
from dnnevo.closedloop import ClosedLoop

class Still:
    observation_size = 1
    def reset(self, episodes, rng):
        return np.zeros((len(episodes), 1))
    def step(self, rates, active):
        return np.zeros((len(rates), 1)), rates[:, 0].copy(), np.zeros(len(rates), bool)

config = dnnevo.EvolutionConfig(population=20, generations=2, size=2, n_inputs=1, selection="rank")
for threads in (-1, 0):
    try:
        dnnevo.evolve(ClosedLoop(Still(), max_steps=5), config, progress=False, threads=threads)
    except dnnevo.InvalidArgumentError as e:
        print("refused:", e)
dnnevo.evolve(ClosedLoop(Still(), max_steps=5), config, progress=False, threads=5)
print("pool:", _core.process_threads())
dnnevo.evolve(ClosedLoop(Still(), max_steps=5), config, progress=False, threads=2)
'''


def test_threads_reach_a_python_task_through_the_process_pool() -> None:
    """A Python task steps its networks on the process's shared pool: evolve(threads=n) sizes it
    when it has not started, says so when it cannot, and refuses a count below 1 as a built-in
    task does."""
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-c", THREADS_SCRIPT], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    # 5, not a usual core count, so that the pool's default would not pass
    assert r.stdout.count("refused: threads is") == 2 and "pool: 5\n" in r.stdout, r.stdout
    assert "threads=2 does not reach this Python task: the process's thread pool started earlier, with 5" \
        in r.stderr, r.stderr


PRESET = SEEKER + '''

class Preset(Seeker):
    preset = {"size": 3, "selection": "rank", "generations": 7,
              "task_params": {"max_steps": 40, "episodes": 2, "speed": 0.2}}


class Misspelt(Seeker):
    preset = {"sise": 3}


class Tasked(Seeker):
    preset = {"task": "sequence"}


class Listed(Seeker):
    preset = [("size", 3)]


class Elite(Seeker):
    preset = {"elitism": 30, "task_params": {"max_steps": 40}}


class Named(Preset):
    analysis = Analysis(input_names=["light side"], conditions={"left": [-1.0]}, main_input=0,
                        output_neuron=0, episodes=1)
'''


def test_a_task_class_declares_its_own_preset(tmp_path, monkeypatch) -> None:
    """A class's ``preset`` is what the command line and evolve start from: a run needs no
    --set to say its episode length, and --set and --quick still go over it."""
    from dnnevo import presets

    (tmp_path / "seeker_preset.py").write_text(PRESET)
    monkeypatch.syspath_prepend(str(tmp_path))
    config = presets.get("python:seeker_preset.Preset")
    assert (config.size, config.selection, config.generations, config.n_inputs) == (3, "rank", 7, 1)
    assert config.task_params == {"max_steps": 40, "episodes": 2, "speed": 0.2}
    quick = presets.get("python:seeker_preset.Preset", quick=True, overrides=["task_params.max_steps=30"])
    assert (quick.population, quick.generations) == (presets.PYTHON_QUICK["population"], presets.PYTHON_QUICK["generations"])
    assert quick.task_params == {"max_steps": 30, "episodes": 2, "speed": 0.2}
    result = dnnevo.evolve("python:seeker_preset.Preset", seed=1, progress=False)
    assert result.config == config and len(result.history["best"]) == 7
    for name, message in [("Misspelt", r"Misspelt.preset: config has unknown key 'sise'"),
                          ("Tasked", r"Tasked.preset sets task; the class is the task"),
                          ("Listed", r"Listed.preset is a list; expected a dict of settings")]:
        with pytest.raises(ConfigError, match=message):
            presets.get(f"python:seeker_preset.{name}")
    # --quick's small population goes over the preset's elites; the message says so, and --set fits it.
    with pytest.raises(ConfigError, match=r"elitism is 30; .*: --quick's population 20, generations 5 go over Elite.preset"):
        presets.get("python:seeker_preset.Elite", quick=True)
    assert presets.get("python:seeker_preset.Elite", quick=True, overrides=["elitism=2"]).elitism == 2
    r = dnnevo_command(tmp_path, "run", "python:seeker_preset.Preset", "--quick", "--threads", "1")
    assert r.returncode == 0, r.stderr
    recorded = (tmp_path / "runs" / "seeker_preset.Preset-quick-seed0" / "config.toml").read_text()
    assert "max_steps = 40" in recorded and "speed = 0.2" in recorded and "size = 3" in recorded
    r = dnnevo_command(tmp_path, "run", "python:seeker_preset.Misspelt", "--quick")
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0 and "Misspelt.preset" in r.stderr, r.stderr


def test_the_episodes_figure_names_the_inputs_as_the_analysis_does_and_draws_the_reward(
        tmp_path, monkeypatch) -> None:
    from dnnevo import plot
    from dnnevo.figures import draw_run

    (tmp_path / "seeker_named.py").write_text(PRESET)
    monkeypatch.syspath_prepend(str(tmp_path))
    drawn: list[list[str]] = []
    real = plot.plot_traces
    monkeypatch.setattr(plot, "plot_traces", lambda shown, *a, **k: drawn.append(list(shown)) or real(shown, *a, **k))
    for name, first in [("Named", "light side ["), ("Preset", "input 0 [")]:
        dnnevo.evolve(f"python:seeker_named.{name}", seed=0, progress=False, out=tmp_path / name)
        drawn.clear()
        assert "episodes.png" in draw_run(tmp_path / name, fitness=False)
        assert drawn and all(len(bands) == 2 and bands[0].startswith(first) and bands[1].startswith("reward [")
                             for bands in drawn), drawn


def test_assess_judges_a_champion_on_a_variant_of_its_task(tmp_path) -> None:
    """``assess --set task_params.KEY=VALUE`` is a transfer test from the command line: the same
    class, in conditions its run never saw, said as such; other settings are refused."""
    import json

    (tmp_path / "seeker_variant.py").write_text(PRESET)
    r = dnnevo_command(tmp_path, "run", "python:seeker_variant.Preset", "--quick", "--threads", "1", "--out", "run")
    assert r.returncode == 0, r.stderr
    runs = {}
    for speed in ("0.2", "0.05"):
        r = dnnevo_command(tmp_path, "assess", "run", "--seed", "2", "--trials", "30", "--json",
                           "--set", f"task_params.speed={speed}")
        assert r.returncode in (0, 1, 3), r.stderr
        runs[speed] = json.loads(r.stdout)
        assert runs[speed]["variant"] == [f"task_params.speed={speed}"]
    plain = json.loads(dnnevo_command(tmp_path, "assess", "run", "--seed", "2", "--trials", "30", "--json").stdout)
    assert "variant" not in plain and plain["rates"] == runs["0.2"]["rates"]  # the run's own speed
    assert runs["0.05"]["mean_length"] != runs["0.2"]["mean_length"]  # a slower agent: other episodes
    text = dnnevo_command(tmp_path, "assess", "run", "--trials", "30", "--set", "task_params.speed=0.05").stdout
    assert "judged on a variant of the run's task: task_params.speed=0.05 (--set)" in text
    bad = dnnevo_command(tmp_path, "assess", "run", "--set", "size=4")
    assert bad.returncode == 2 and "assess changes the task's conditions only" in bad.stderr
    bad = dnnevo_command(tmp_path, "assess", "run", "--set", "task_params.episodes=7")
    assert bad.returncode == 2 and "--trials says how many are judged" in bad.stderr, bad.stderr
