"""Fewer rows than episodes: a rollout that starts a waiting episode in the row of one that
ended (``rollout(..., rows=R)``) gives the returns and lengths of one that runs every episode at
once, bit for bit, when the environment's conditions follow the episode number."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import dnnevo
from dnnevo import InvalidArgumentError, TaskError
from dnnevo.closedloop import ClosedLoop, FarSeeker, rollout


def seekers(count: int, seed: int = 3) -> list[dnnevo.Network]:
    """The far seeker's first generation: episodes of 200 to 10 000 steps."""
    config = dnnevo.presets.get("nav1d-far")
    config = dnnevo.EvolutionConfig(**{**config.to_dict(), "population": max(count, 2)})
    return dnnevo.GeneticAlgorithm(config, seed=seed).ask().networks[:count]


class WaitingSeeker(FarSeeker):
    """The far seeker starting a new episode at its next step, as a vector environment with
    next-step autoreset does: ``restart`` returns None, and the next step's observations for
    those rows are the new episodes' first (their rewards and ends are not read)."""

    def restart(self, rows, episodes):
        self.pending = (rows.copy(), episodes.copy())

    def step(self, rates, active):
        obs, reward, done = super().step(rates, active)
        pending = getattr(self, "pending", None)
        if pending is not None:
            self.pending = None
            obs = self._start(*pending)
            reward, done = reward.copy(), done.copy()
            reward[pending[0]] = True  # garbage that must not count
            done[pending[0]] = True
        return obs, reward, done


@settings(max_examples=12, deadline=None)
@given(p=st.integers(1, 8), episodes=st.integers(1, 3), extra=st.integers(0, 30),
       waiting=st.booleans(), seed=st.integers(0, 50), precision=st.sampled_from(["f64", "f32"]))
def test_fewer_rows_give_the_same_returns_and_lengths(p: int, episodes: int, extra: int,
                                                     waiting: bool, seed: int, precision: str) -> None:
    nets = seekers(p, seed)
    everything = rollout(nets, FarSeeker(), episodes=episodes, max_steps=1000, precision=precision)
    rows = episodes + extra % (p * episodes)
    env = WaitingSeeker() if waiting else FarSeeker()
    queued = rollout(nets, env, episodes=episodes, max_steps=1000, rows=rows, precision=precision)
    assert np.array_equal(queued.returns, everything.returns)
    assert np.array_equal(queued.lengths, everything.lengths)


class RateWatcher(FarSeeker):
    """The far seeker, noting whether every rate it was given is a float32 value."""

    all_f32 = True

    def step(self, rates, active):
        self.all_f32 &= bool(np.array_equal(rates.astype(np.float32).astype(np.float64), rates))
        return super().step(rates, active)


def test_a_rollout_in_f32_steps_in_f32_and_ends_where_f64_does_here() -> None:
    nets = seekers(8)
    runs = {}
    for precision in ("f64", "f32"):
        env = RateWatcher()
        runs[precision] = rollout(nets, env, episodes=2, max_steps=2000, precision=precision)
        assert env.all_f32 == (precision == "f32")  # f64 rates are not all float32 values
    # The goal is reached or not: here rounding changes no outcome.
    assert np.array_equal(runs["f32"].returns, runs["f64"].returns)
    with pytest.raises(InvalidArgumentError, match='precision is "f16"'):
        rollout(nets, FarSeeker(), max_steps=10, precision="f16")


def test_the_step_limit_holds_for_each_episode_from_its_own_start() -> None:
    nets = seekers(40)
    everything = rollout(nets, FarSeeker(), episodes=2, max_steps=700)
    assert (everything.lengths == 700).any() and (everything.lengths < 700).any()
    for rows in (2, 3, 17, 79):
        queued = rollout(nets, FarSeeker(), episodes=2, max_steps=700, rows=rows)
        assert np.array_equal(queued.lengths, everything.lengths)
        assert np.array_equal(queued.returns, everything.returns)


def test_a_closed_loop_fitness_with_rows_evolves_the_same_and_records_them(tmp_path) -> None:
    config = dnnevo.EvolutionConfig(population=24, generations=3, size=5, n_inputs=1,
                                    validation_candidates=3)
    plain = dnnevo.evolve(ClosedLoop(FarSeeker(), episodes=2, max_steps=2000, validation_episodes=4),
                          config, seed=2, progress=False)
    fitness = ClosedLoop(FarSeeker(), episodes=2, max_steps=2000, validation_episodes=4, rows=5)
    queued = dnnevo.evolve(fitness, config, seed=2, out=tmp_path / "run", progress=False)
    assert np.array_equal(plain.history["best"], queued.history["best"])
    assert plain.best.to_json() == queued.best.to_json()
    assert fitness.configured(config).task_params["rows"] == 5
    assert "rows" in (tmp_path / "run" / "config.toml").read_text()
    assert "rows=5" in repr(fitness)
    # Without rows, nothing new is recorded: older runs keep their digest.
    assert "rows" not in ClosedLoop(FarSeeker(), episodes=2, max_steps=9).configured(config).task_params


class Restless(FarSeeker):
    def __init__(self, fault: str) -> None:
        super().__init__()
        self.fault = fault

    def restart(self, rows, episodes):
        obs = super().restart(rows, episodes).copy()
        if self.fault == "raises":
            raise ValueError("no more room")
        if self.fault == "nan":
            obs[np.flatnonzero(rows)[0]] = np.nan
        if self.fault == "shape":
            return obs[:, 0]
        return obs


@pytest.mark.parametrize("fault, message", [
    ("raises", r"Restless.restart raised ValueError: no more room"),
    ("nan", r"Restless.restart returned observations that are not finite \(row \d+: \[nan\]\)"),
    ("shape", r"Restless.restart returned observations of shape \(3,\); expected \(B, M\) = \(3, 1\)"),
])
def test_a_broken_restart_gets_a_task_error_naming_it(fault: str, message: str) -> None:
    with pytest.raises(TaskError, match=message):
        rollout(seekers(8), Restless(fault), episodes=1, max_steps=3000, rows=3)


class NoRestart:
    observation_size = 1

    def reset(self, episodes, rng):
        return np.zeros((len(episodes), 1))

    def step(self, rates, active):
        n = len(rates)
        return np.zeros((n, 1)), np.zeros(n), np.ones(n, dtype=bool)


def test_rows_need_a_restart_and_at_least_one_row_per_episode_number() -> None:
    nets = seekers(4)
    with pytest.raises(TaskError, match=r"NoRestart has no restart method; without one, rows "
                                        r"must be None or at least P x episodes = 8"):
        rollout(nets, NoRestart(), episodes=2, max_steps=5, rows=3)
    # Rows enough for every episode need no restart.
    assert rollout(nets, NoRestart(), episodes=2, max_steps=5, rows=8).lengths.sum() == 8
    with pytest.raises(InvalidArgumentError, match=r"rows is 1; it must be at least episodes \(2\)"):
        rollout(nets, FarSeeker(), episodes=2, max_steps=5, rows=1)
    with pytest.raises(InvalidArgumentError, match="rows"):
        rollout(nets, FarSeeker(), episodes=2, max_steps=5, rows=-1)
    with pytest.raises(dnnevo.ConfigError, match=r"rows is 1; expected a whole number of rows, at "
                                                 r"least episodes \(2\)"):
        ClosedLoop(FarSeeker(), episodes=2, max_steps=5, rows=1)
    # A fitness function refuses rows without restart at once, before any run folder is made.
    with pytest.raises(dnnevo.ConfigError, match=r"rows is 4, but NoRestart has no restart method"):
        ClosedLoop(NoRestart(), episodes=2, max_steps=5, rows=4)


def test_a_batch_of_fewer_rows_hands_rows_to_other_networks() -> None:
    nets = [dnnevo.Network.random(3, 1, seed=s) for s in range(4)]
    batch = dnnevo.Batch(nets, replicas=2, rows=3)
    assert batch.rows == 3 and batch.network_of.tolist() == [0, 0, 1]
    x = np.ones((3, 1))
    batch.step(x)
    batch.assign([2, 0], [3, 1])
    assert batch.network_of.tolist() == [1, 0, 3]
    # An assigned row starts from its new network's state and runs it: the bits of Network.run.
    batch.reset([0, 2])
    rates = batch.step(x)
    for row, p in ((0, 1), (2, 3)):
        assert np.array_equal(rates[row], nets[p].copy().run(x[:1]).outputs[-1])
    for args, message in [
        (([3], [0]), "row 3 is out of range; the batch has 3 rows"),
        (([0], [4]), "network 4 is out of range; the batch has 4 networks"),
        (([0, 0], [1, 2]), "row 0 is named twice"),
        (([0], [0, 1]), "1 row and 2 networks"),
        (([-4], [0]), r"rows holds index -4; there are 3 rows, so indices run from -3 to 2"),
        (([0], [-5]), r"networks holds index -5; there are 4 networks, so indices run from -4 to 3"),
        (([0.5], [0]), "rows is an array of dtype float64 and 1 dimensions; expected a 1-D array of indices"),
    ]:
        with pytest.raises(InvalidArgumentError, match=message):
            batch.assign(*args)
    assert batch.network_of.tolist() == [1, 0, 3]
    # Negative indices count from the end, as reset's and set_states' rows do.
    batch.assign([-1], [-4])
    assert batch.network_of.tolist() == [1, 0, 0]
    for rows in (0, 9):
        with pytest.raises(InvalidArgumentError, match=rf"rows is {rows}; expected 1 to networks x "
                                                       "replicas = 8"):
            dnnevo.Batch(nets, replicas=2, rows=rows)
