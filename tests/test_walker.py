"""Beer and Gallagher's one-legged walker: one step of the body and leg against hand-computed
cases, its limits, the optimal controller, and the task's conditions and verdict."""

from __future__ import annotations

import math

import numpy as np
import pytest

import dnnevo
from dnnevo.classic import LeggedWalker
from dnnevo.classic import walker as lw
from dnnevo.closedloop import rollout
from dnnevo.errors import InvalidArgumentError

LIMIT = math.pi / 6


def walker(angle: float, *, down: bool = False, velocity: float = 0.0) -> LeggedWalker:
    env = LeggedWalker()
    env.reset(np.zeros(1, dtype=np.int64), np.random.default_rng(0))
    env.angle[:] = angle
    env.foot_x[:] = 15 * math.sin(angle)
    env.foot_y[:] = 15 * math.cos(angle)
    env.foot_down[:] = down
    env.velocity[:] = velocity
    return env


def rates(foot: float, forward: float, backward: float) -> np.ndarray:
    r = np.zeros((1, 5))
    r[0, :3] = foot, forward, backward
    return r


def test_a_lifted_leg_swings_and_the_body_stays() -> None:
    # Forward force 0.05 with the foot up: omega = 0.1 * 0.5 * (0 - 0.05), the angle moves by
    # 0.1 omega, and the foot follows the leg.
    env = walker(LIMIT, velocity=1.0)
    env.step(rates(0.0, 1.0, 0.0), np.ones(1, dtype=bool))
    assert env.omega[0] == pytest.approx(-0.0025, abs=1e-15)
    assert env.angle[0] == pytest.approx(LIMIT - 0.00025, abs=1e-15)
    assert env.x[0] == pytest.approx(0.1)  # the body moved once at its old velocity, then stopped
    assert env.velocity[0] == 0.0
    assert env.foot_x[0] == pytest.approx(0.1 + 15 * math.sin(LIMIT - 0.00025), abs=1e-12)


def test_a_planted_foot_pushes_the_body_and_the_leg_follows() -> None:
    env = walker(LIMIT)
    foot_x, foot_y = env.foot_x[0], env.foot_y[0]
    env.step(rates(1.0, 1.0, 0.0), np.ones(1, dtype=bool))
    assert env.velocity[0] == pytest.approx(0.005, abs=1e-15)  # 0.1 * 0.05
    assert env.x[0] == pytest.approx(0.0005, abs=1e-15)
    angle = math.atan2(foot_x - 0.0005, foot_y)
    assert env.angle[0] == pytest.approx(angle, abs=1e-15)
    assert env.omega[0] == pytest.approx((angle - LIMIT) / 0.1, abs=1e-12)
    assert env.foot_x[0] == foot_x  # the foot stays where it was planted


def test_a_supporting_leg_past_its_limit_only_pushes_back_towards_it() -> None:
    behind = -LIMIT - 0.01
    forward = walker(behind, down=True)
    forward.step(rates(1.0, 1.0, 0.0), np.ones(1, dtype=bool))
    assert forward.velocity[0] == 0.0  # pushing further away: no force
    back = walker(behind, down=True)
    back.step(rates(1.0, 0.0, 1.0), np.ones(1, dtype=bool))
    assert back.velocity[0] == pytest.approx(-0.005, abs=1e-15)


def test_a_lifted_leg_stops_at_its_limits() -> None:
    env = walker(-LIMIT + 0.0001)
    env.omega[:] = -1.0
    env.step(rates(0.0, 1.0, 0.0), np.ones(1, dtype=bool))
    assert env.angle[0] == -LIMIT and env.omega[0] == 0.0


def test_a_foot_trailing_more_than_20_stops_the_body() -> None:
    env = walker(0.0, down=True, velocity=2.0)
    env.foot_x[:] = -20.5  # the body is at 0: the foot 20.5 behind
    env.step(rates(1.0, 0.0, 0.0), np.ones(1, dtype=bool))
    assert env.x[0] == pytest.approx(0.2) and env.velocity[0] == 0.0


def test_the_optimal_controller_and_its_time_step() -> None:
    best = lw.optimal_velocity()
    assert best == pytest.approx(0.6264204545, abs=1e-9)
    # It is a property of the model, not of the step: 0.21% apart at a 10x finer step.
    assert lw.optimal_velocity(0.01) == pytest.approx(best, rel=2.5e-3)


def test_an_episode_pays_its_average_velocity_once() -> None:
    env = LeggedWalker(start="random")
    net = dnnevo.Network.random(5, 1, seed=4)
    result = rollout([net], env, episodes=3, max_steps=env.steps, dt=0.1, substeps=1)
    assert env.steps == 2200 and result.lengths.tolist() == [[2200] * 3]
    np.testing.assert_array_equal(result.returns[0], env.x / 220.0)


def test_random_starts_are_common_and_the_sensor_reads_the_angle() -> None:
    env = LeggedWalker(start="random")
    episodes = np.tile(np.arange(4), 3)
    obs = env.reset(episodes, np.random.default_rng(1))
    angles = env.angle.reshape(3, 4)
    assert (angles == angles[:1]).all() and (np.abs(angles) <= LIMIT).all()
    np.testing.assert_allclose(obs[:, 0], env.angle / LIMIT, rtol=0, atol=1e-15)
    cut = LeggedWalker(sensor=False, start="random")
    assert (cut.reset(episodes, np.random.default_rng(1)) == 0).all()
    assert LeggedWalker().reset(np.zeros(2, dtype=np.int64), None).tolist() == [[1.0], [1.0]]


def test_an_episode_walks_at_half_the_optimal_velocity() -> None:
    half = lw.WALKING * lw.optimal_velocity()
    verdict = LeggedWalker().success(np.array([half, half - 1e-9, 0.6]), np.zeros(3, dtype=np.int64))
    assert verdict.tolist() == [True, False, True]


def test_a_gait_and_fresh_velocities() -> None:
    net = dnnevo.Network.random(5, 1, seed=0)
    t, angle, down, x = lw.gait(net)
    assert t.shape == angle.shape == down.shape == x.shape == (2201,)
    assert angle[0] == LIMIT and t[-1] == pytest.approx(220.0)
    v = lw.velocities(net, episodes=4)
    assert v.shape == (4,) and (np.abs(v) <= 6).all()


def test_bad_settings_are_named() -> None:
    with pytest.raises(InvalidArgumentError, match="start is 'grid'"):
        LeggedWalker(start="grid")
    with pytest.raises(InvalidArgumentError, match="dt is -1"):
        LeggedWalker(dt=-1)
