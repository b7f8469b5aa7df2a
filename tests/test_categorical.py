"""Beer's categorical perception task: its ray geometry against hand-computed cases and a brute
search along each ray, its motion, its score and its success rule."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import dnnevo
from dnnevo.classic import CategoricalPerception
from dnnevo.classic import categorical as cp
from dnnevo.closedloop import rollout
from dnnevo.errors import InvalidArgumentError

MIDDLE, RIGHTMOST = 3, 6
H = 30 / math.sqrt(2)  # a diamond of side 30: half its diagonal


def distances(x: float, y: float, diamond: bool, agent: float = 0.0) -> np.ndarray:
    return cp.ray_distances(np.array([agent]), np.array([x]), np.array([y]),
                            np.array([diamond]))[0]


def test_the_middle_ray_meets_an_object_straight_above() -> None:
    # The ray starts at the agent's edge (height 15); the object's centre is at height 100.
    assert distances(0.0, 100.0, False)[MIDDLE] == pytest.approx(100 - 15 - 15, abs=1e-12)
    assert distances(0.0, 100.0, True)[MIDDLE] == pytest.approx(100 - 15 - H, abs=1e-12)
    # The agent is at 40; the object moved with it.
    assert distances(40.0, 100.0, False, agent=40.0)[MIDDLE] == pytest.approx(70, abs=1e-12)


def test_a_slanted_ray_through_the_centre() -> None:
    # The rightmost ray leaves at 15 degrees; put the centre 100 along it from its origin. A
    # circle is met 15 before the centre; a diamond where s (sin 15 + cos 15) = H, that is
    # s = 15 sqrt(2) / (sqrt(6) / 2) = 30 / sqrt(3).
    a = math.pi / 12
    x, y = 115 * math.sin(a), 115 * math.cos(a)
    assert distances(x, y, False)[RIGHTMOST] == pytest.approx(85, abs=1e-10)
    assert distances(x, y, True)[RIGHTMOST] == pytest.approx(100 - 30 / math.sqrt(3), abs=1e-10)


def test_rays_miss_an_object_off_to_the_side_and_ignore_one_out_of_range() -> None:
    assert np.isinf(distances(150.0, 100.0, False)).all()
    assert np.isinf(distances(150.0, 100.0, True)).all()
    env = CategoricalPerception(start="grid")
    env.reset(np.array([0, 1]), np.random.default_rng(0))
    env.x[:] = 0.0
    env.y[:] = 15 + 221 + 15  # the circle's nearest point is 221 from the ray's origin
    assert (env._sense()[0] == 0).all()
    env.y[:] = 100.0
    assert env._sense()[0, MIDDLE] == pytest.approx(1 - 70 / 220)


def _inside(px: np.ndarray, py: np.ndarray, diamond: bool) -> np.ndarray:
    return (np.abs(px) + np.abs(py) < H) if diamond else (px * px + py * py < 15 * 15)


@settings(max_examples=300, deadline=None)
@given(x=st.floats(-120, 120), y=st.floats(-40, 300), diamond=st.booleans())
def test_each_ray_finds_the_first_point_inside_the_object(x: float, y: float, diamond: bool) -> None:
    """Against a search along each ray: no point before the distance found is inside the
    object within the ray's length, and the point at it is on the boundary."""
    found = distances(x, y, diamond)
    t = np.linspace(0.0, 220.0, 22_001)
    for ray, angle in enumerate(cp.RAY_ANGLES):
        ox, oy = 15 * math.sin(angle), 15 * math.cos(angle)
        px, py = ox + t * math.sin(angle) - x, oy + t * math.cos(angle) - y
        inside = _inside(px, py, diamond)
        d = found[ray]
        if math.isinf(d):
            assert not inside.any()
            continue
        assert not inside[t < d - 1e-6].any()
        bx, by = ox + d * math.sin(angle) - x, oy + d * math.cos(angle) - y
        edge = abs(bx) + abs(by) - H if diamond else math.hypot(bx, by) - 15
        assert edge == pytest.approx(0, abs=1e-9) or (d == 0 and edge <= 1e-9)


def test_the_motors_move_the_agent_and_the_walls_stop_it() -> None:
    env = CategoricalPerception(start="grid")
    env.reset(np.array([0, 1]), np.random.default_rng(0))
    rates = np.zeros((2, 7))
    rates[0, 1] = 1.0  # row 0: the right motor only, speed 5
    rates[1, 0] = 0.5  # row 1: half the left motor, speed -2.5
    env.step(rates, np.ones(2, dtype=bool))
    assert env.agent.tolist() == pytest.approx([0.5, -0.25], abs=1e-15)
    assert env.y[0] == pytest.approx(275 - 0.3)
    for _ in range(600):
        env.step(rates, np.ones(2, dtype=bool))
    assert env.agent[0] == 200 - 15


def test_an_episode_lasts_until_the_object_reaches_the_agent() -> None:
    assert CategoricalPerception(dt=0.1).steps == 917  # 275 / 0.3 = 916.7
    assert CategoricalPerception(dt=0.05).steps == 1834
    net = dnnevo.Network.random(7, 7, seed=3)
    env = CategoricalPerception(dt=0.05)
    result = rollout([net], env, episodes=2, max_steps=5000, dt=0.05, substeps=1)
    assert result.lengths.tolist() == [[1834, 1834]]


def test_score_and_verdict_from_the_distance_at_landing() -> None:
    env = CategoricalPerception(start="grid")
    env.reset(np.arange(6), np.random.default_rng(0))
    # Circle, diamond at each of 0, 32 (past a circle's reach of 30, inside a diamond's 36.2)
    # and 50 (past the clip at 45).
    env.landed = np.array([0.0, 0.0, 32.0, 32.0, 50.0, 50.0])
    assert env.performance(env.landed).tolist() == pytest.approx(
        [1, 0, 1 - 32 / 45, 32 / 45, 0, 1], abs=1e-15)
    assert env.success(np.zeros(6), np.zeros(6, dtype=np.int64)).tolist() == [
        True, False, False, False, False, True]


def test_circles_and_diamonds_alternate_and_share_their_offsets() -> None:
    env = CategoricalPerception()
    episodes = np.tile(np.arange(8), 3)  # 3 networks x 8 episodes
    env.reset(episodes, np.random.default_rng(5))
    assert env.diamond.tolist() == [e % 2 == 1 for e in episodes]
    offsets = env.offset.reshape(3, 4, 2)
    assert (offsets == offsets[:1]).all() and (offsets[..., 0] == offsets[..., 1]).all()
    assert (np.abs(env.offset) <= 50).all() and len(set(env.offset)) == 4
    grid = CategoricalPerception(start="grid")
    grid.reset(np.arange(202), np.random.default_rng(0))
    assert grid.offset[::2].tolist() == list(range(-50, 51))


def test_a_random_network_scores_and_is_judged_on_the_grid() -> None:
    net = dnnevo.Network.random(7, 7, seed=0)
    correct, total, performance = cp.grid_accuracy(net, pairs=11)
    assert total == 22 and 0 <= correct <= 22 and 0 <= performance <= 1
    height, offset, ok = cp.paths(net, pairs=3)
    assert height.shape == (918,) and offset.shape == (6, 918) and ok.shape == (6,)
    assert offset[:, 0].tolist() == [-50, -50, 0, 0, 50, 50]


def test_bad_settings_are_named() -> None:
    with pytest.raises(InvalidArgumentError, match="start is 'standard'"):
        CategoricalPerception(start="standard")
    with pytest.raises(InvalidArgumentError, match="dt is 0"):
        CategoricalPerception(dt=0)
    with pytest.raises(InvalidArgumentError, match="both neuron 2"):
        CategoricalPerception(left=2, right=2)
    with pytest.raises(InvalidArgumentError, match="right is -1"):
        CategoricalPerception(right=-1)


def test_a_fall_cut_short_is_not_classified_correctly() -> None:
    net = dnnevo.Network.random(7, 7, seed=0)
    env = CategoricalPerception(start="grid")
    result = rollout([net], env, episodes=4, max_steps=10, dt=0.1, substeps=1)
    assert (result.returns == 0).all()
    assert not env.success(result.returns[0], result.lengths[0]).any()
