"""The classic benchmarks: double-pole balancing's physics against hand-computed cases, its
fitness and success rule, and the generalisation grid."""

from __future__ import annotations

import numpy as np
import pytest

import dnnevo
from dnnevo.classic import DoublePole
from dnnevo.classic import double_pole as dp
from dnnevo.closedloop import rollout
from dnnevo.errors import InvalidArgumentError


def test_at_rest_upright_only_the_push_accelerates() -> None:
    # Upright and at rest, each pole's effective mass is m (1 - 3/4) and every pole force is 0:
    # x'' = F / (M + m1/4 + m2/4), and theta_i'' = -3/4 x'' / l_i.
    force = np.array([10.0])
    d = dp._derivatives(np.zeros((6, 1)), force)
    a = 10.0 / (1.0 + 0.1 / 4 + 0.01 / 4)
    assert d[1, 0] == pytest.approx(a, rel=1e-15)
    assert d[3, 0] == pytest.approx(-0.75 * a / 0.5, rel=1e-15)
    assert d[5, 0] == pytest.approx(-0.75 * a / 0.05, rel=1e-15)
    assert d[0, 0] == d[2, 0] == d[4, 0] == 0.0


def test_a_tilted_pole_falls_under_gravity_alone() -> None:
    # Long pole at angle q, all at rest, no push: its force term is 3/4 m cos q (g sin q), and
    # theta_1'' = -3/4 (x'' cos q + g sin q) / l_1 with g = -9.8 (the benchmark's convention).
    q = 0.07
    s = np.zeros((6, 1))
    s[2] = q
    d = dp._derivatives(s, np.zeros(1))
    g = -9.8
    pole = 0.75 * 0.1 * np.cos(q) * g * np.sin(q)
    mass = 1.0 + 0.1 * (1 - 0.75 * np.cos(q) ** 2) + 0.01 * 0.25
    a = pole / mass
    assert d[1, 0] == pytest.approx(a, rel=1e-14)
    assert d[3, 0] == pytest.approx(-0.75 * (a * np.cos(q) + g * np.sin(q)) / 0.5, rel=1e-14)
    assert d[3, 0] > 0  # it falls further the way it leans


def test_the_dynamics_are_mirror_symmetric() -> None:
    rng = np.random.default_rng(0)
    s = rng.normal(scale=0.1, size=(6, 8))
    f = rng.normal(size=8)
    np.testing.assert_allclose(dp._advance(-s, -f), -dp._advance(s, f), rtol=0, atol=1e-15)


def test_the_grid_is_the_625_generalisation_starts() -> None:
    assert dp.GRID.shape == (625, 4)
    assert dp.GRID[0] == pytest.approx([-1.944, -1.215, -np.deg2rad(3.24), -np.deg2rad(7.74)])
    assert len({tuple(row) for row in dp.GRID}) == 625
    np.testing.assert_allclose(dp.GRID.mean(axis=0), 0.0, atol=1e-15)


class Steady:
    """A fake controller's rates: neuron 0 at ``level`` in every row."""

    def __init__(self, rows: int, level: float) -> None:
        self.rates = np.full((rows, 5), level)


def test_a_fall_ends_the_episode_and_pays_the_balanced_part_only() -> None:
    env = DoublePole()
    env.reset(np.zeros(2, dtype=np.int64), np.random.default_rng(0))
    active = np.ones(2, dtype=bool)
    for t in range(1, 1000):
        _, reward, done = env.step(Steady(2, 0.5).rates, active)
        if done.any():
            break
    assert done.all() and t < 100
    # Fewer than 100 balanced steps: no damping term.
    assert reward == pytest.approx(0.1 * (t - 1) / 1000)
    assert not env.success(reward, np.full(2, t)).any()


def test_a_balanced_episode_earns_the_damping_term(monkeypatch: pytest.MonkeyPatch) -> None:
    # Freeze the physics: the cart stays at the standard start, balanced throughout, and each of
    # the last 100 steps adds |theta_1| = 0.07 to the jiggle.
    monkeypatch.setattr(dp, "_advance", lambda s, force: s)
    env = DoublePole(steps=150)
    env.reset(np.zeros(1, dtype=np.int64), np.random.default_rng(0))
    total = 0.0
    for _ in range(150):
        _, reward, done = env.step(Steady(1, 0.5).rates, np.ones(1, dtype=bool))
        total += reward[0]
    assert done[0]
    assert total == pytest.approx(0.1 * 150 / 1000 + 0.9 * 0.75 / (100 * 0.07), rel=1e-12)
    assert env.success(np.array([total]), np.array([150])).tolist() == [True]


def test_a_random_network_does_not_solve_it() -> None:
    net = dnnevo.Network.random(5, 3, seed=1)
    solved, long, score = dp.solves(net)
    assert not solved and long < 1000 and score == 0
    result = rollout([net], DoublePole(start="grid"), episodes=625, max_steps=1000)
    assert result.returns.shape == (1, 625) and (result.lengths < 1000).all()


def test_random_starts_fill_the_grids_box_from_the_episodes_generator() -> None:
    env = DoublePole(start="random")
    first = env.reset(np.arange(500), np.random.default_rng(5))
    state = env.state.copy()
    low, high = np.array(dp.START_SPANS).T
    assert ((state[:4].T >= low) & (state[:4].T <= high)).all() and (state[4:] == 0).all()
    assert (state[:4].min(axis=1) < low + 0.1 * (high - low)).all()  # the whole box, not a corner
    np.testing.assert_array_equal(env.reset(np.arange(500), np.random.default_rng(5)), first)
    assert not np.array_equal(env.reset(np.arange(500), np.random.default_rng(6)), first)
    # Rows of one episode (the rollout's networks x episodes) start alike: common random numbers.
    env.reset(np.tile(np.arange(4), 3), np.random.default_rng(1))
    np.testing.assert_array_equal(env.state[:, :4], env.state[:, 4:8])
    np.testing.assert_array_equal(env.state[:, :4], env.state[:, 8:])
    assert len({tuple(env.state[:, k]) for k in range(4)}) == 4


def test_bad_settings_are_named() -> None:
    with pytest.raises(InvalidArgumentError, match="start is 'sideways'"):
        DoublePole(start="sideways")
    with pytest.raises(InvalidArgumentError, match="steps is 0"):
        DoublePole(steps=0)


@pytest.mark.parametrize("name", ["double_pole.DoublePole", "categorical.CategoricalPerception",
                                  "walker.LeggedWalker"])
def test_each_classic_task_can_be_named_in_a_config(name: str) -> None:
    """observation_size is on the class, so `dnnevo run python:...` accepts it before calling it."""
    from dnnevo.closedloop import named

    assert named.environment_class(f"python:dnnevo.classic.{name}").__name__ == name.split(".")[1]


def test_the_walker_preset_runs_resumes_and_is_judged_from_the_command_line(tmp_path) -> None:
    from cli_helpers import run_cli

    run = tmp_path / "walker"
    r = run_cli("run", "legged-walker", "--quick", "--set", "generations=2", "--set", "population=8",
                "--set", "task_params.episodes=2", "--out", run)
    assert r.returncode == 0, r.stderr
    assert 'task = "python:dnnevo.classic.walker.LeggedWalker"' in (run / "config.toml").read_text()
    r = run_cli("resume", run, "--generations", "3")
    assert r.returncode == 0 and "3 generations" in r.stdout, r.stdout + r.stderr
    r = run_cli("assess", run, "--trials", "10")
    assert r.returncode in (0, 1) and "success needs >= 90%" in r.stdout, r.stdout + r.stderr


def test_the_judging_helpers_compute_in_the_precision_they_are_given() -> None:
    """A champion evolved in f32 is judged in f32: each helper passes ``precision`` to the loop
    (an unknown precision is named from there), and an f32 trajectory is close to f64's but not
    the same."""
    from dnnevo.classic import categorical as cp
    from dnnevo.classic import walker as lw

    net = dnnevo.Network.random(5, 1, seed=3)
    f64, f32 = (lw.gait(net, precision=p)[1] for p in ("f64", "f32"))
    assert not np.array_equal(f64, f32) and np.allclose(f64, f32, atol=1e-3)
    assert not np.array_equal(*(lw.velocities(net, episodes=3, precision=p) for p in ("f64", "f32")))
    seer = dnnevo.Network.random(8, 7, seed=4)
    offsets = [cp.paths(seer, pairs=2, precision=p)[1] for p in ("f64", "f32")]
    assert not np.array_equal(*offsets) and np.allclose(*offsets, atol=1e-2)
    assert cp.grid_accuracy(seer, pairs=2, precision="f32")[1] == 4
    pole = dnnevo.Network.random(5, 3, seed=5)
    assert 0 <= dp.generalization(pole, precision="f32") <= len(dp.GRID)
    assert dp.long_test(pole, steps=50, precision="f32") <= 50
    # Each helper hands its precision to the loop, which names a precision it does not know.
    for judge in (dp.long_test, dp.generalization, dp.solves, lw.velocities, lw.gait, cp.grid_accuracy, cp.paths):
        net = pole if judge in (dp.long_test, dp.generalization, dp.solves) else seer if judge in (
            cp.grid_accuracy, cp.paths) else dnnevo.Network.random(5, 1, seed=3)
        with pytest.raises(InvalidArgumentError, match='precision is "f16"'):
            judge(net, precision="f16")  # type: ignore[operator]
