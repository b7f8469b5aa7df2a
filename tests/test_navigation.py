"""Reactive navigation (dnnevo.robots.Navigate): the destination sensor on hand-computed poses,
the reward and the success rule, the hand-designed network shipped in the package, and the
static and cyclic detectors on hand-built trajectories and in the U-shaped trap."""

from __future__ import annotations

import json
from importlib import resources

import numpy as np
import pytest

import dnnevo
from dnnevo.closedloop import rollout
from dnnevo.errors import InvalidArgumentError
from dnnevo.robots import Navigate
from dnnevo.robots.navigation import (INTEGRATOR, WORLDS, bearing, design, destination,
                                      navigation_world, navigator)

ONE = np.array([True])
STILL = np.array([[0.5, 0.5]])  # rates of 0.5: both wheels at 0 m/s
AHEAD = np.array([[1.0, 1.0]])  # full speed ahead


def placed(pose: list[float], world: str = "open-room", **kwargs: object) -> Navigate:
    """A Navigate of one row with its robot placed by hand."""
    env = Navigate(world, **kwargs)  # type: ignore[arg-type]
    env.reset(np.array([0]), np.random.default_rng(0))
    env.place([pose])
    return env


def test_bearing_and_destination_sensor_on_hand_computed_poses() -> None:
    goal = [2.0, 1.0]
    poses = [[1.0, 1.0, 0.0],             # goal dead ahead
             [2.0, 0.0, 0.0],             # goal to the left, 90 degrees
             [2.0, 2.0, 0.0],             # goal to the right, 90 degrees
             [3.0, 1.0, 0.0],             # goal straight behind
             [1.0, 0.0, np.pi / 4],       # goal ahead again, facing it at 45 degrees
             [1.0, 1.0, 2 * np.pi + 0.5]]  # heading past a full turn: goal 0.5 rad to the right
    b = bearing(poses, goal)
    assert b == pytest.approx([0.0, np.pi / 2, -np.pi / 2, np.pi, 0.0, -0.5], abs=1e-12)
    sensor = destination(poses, goal)
    assert sensor == pytest.approx(np.array([[0, 0], [0.5, 0], [0, 0.5], [1, 0], [0, 0], [0, 0.5 / np.pi]]), abs=1e-12)
    # Through the task: the two goal inputs and the frustration input, 0 without detectors.
    env = placed([1.0, 3.0, np.pi / 2])  # goal (7, 3) to the right, 90 degrees
    obs = env.observe()
    assert obs.shape == (1, 11)
    assert obs[0, 8:] == pytest.approx([0.0, 0.5, 0.0])
    assert obs[0, :8] == pytest.approx(np.minimum(1.0, 0.5 / env.fleet.ranges[0]))


def test_reward_is_progress_arrival_and_contact() -> None:
    env = placed([4.95, 3.0, 0.0], steps=100)  # 2.05 m from the goal, facing it
    rewards, done = [], []
    for _ in range(40):
        _, r, d = env.step(AHEAD, ONE)
        rewards.append(r[0])
        done.append(d[0])
        if d[0]:
            break
    # Full speed for 1.55 m (to within the goal radius of 0.5 m) takes 16 steps of 0.1 s.
    assert len(rewards) == 16 and done[-1] and not any(done[:-1])
    assert sum(rewards) == pytest.approx(1.6 / 2.05 + 1.0, abs=1e-9)  # 16 steps of 0.1 m
    assert env.success(np.array(sum(rewards)), np.array(len(rewards))).tolist() == [True]
    # Pressed against the room's wall: a contact costs 1 / steps, and standing still is not success.
    env = placed([0.3, 3.0, np.pi], steps=10)
    total = sum(env.step(AHEAD, ONE)[1][0] for _ in range(10))
    assert env.contact_steps.tolist() == [10]
    assert total == pytest.approx(-1.0, abs=0.01) and env.done(ONE).tolist() == [True]
    assert env.success(np.array([total]), np.array([10])).tolist() == [False]
    env = placed([1.0, 1.0, 0.0], steps=5)
    for _ in range(5):
        env.step(STILL, ONE)
    assert env.arrived.tolist() == [False] and env.contact_steps.tolist() == [0]


def test_worlds_ship_with_goals_and_bad_input_is_named() -> None:
    for name in WORLDS:
        world, goal, radius = navigation_world(name)
        assert "goal" not in world and radius == 0.5
        env = Navigate(name)
        assert env.world["room"][0] >= goal[0] and env.observation_size == 11
    with pytest.raises(InvalidArgumentError, match="goal is None; a navigation world needs goal"):
        Navigate({"room": [4.0, 4.0], "start": {"min": [0.5, 0.5], "max": [3.5, 3.5]}})
    with pytest.raises(InvalidArgumentError, match=r"goal is \[9.0, 1.0\]; it must lie in the room"):
        Navigate("open-room", goal=(9.0, 1.0))
    with pytest.raises(InvalidArgumentError, match="world is 'maze'; expected one of 'open-room'"):
        Navigate("maze")
    with pytest.raises(InvalidArgumentError, match="steps is 0"):
        Navigate(steps=0)
    with pytest.raises(InvalidArgumentError, match="detectors is 'yes'"):
        Navigate(detectors="yes")  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="goal_radius is -1"):
        Navigate(goal_radius=-1)


def test_network_file_loads_from_the_installed_package_and_is_the_design() -> None:
    text = resources.files("dnnevo.robots").joinpath("data", "navigator.json").read_text(encoding="utf-8")
    doc = json.loads(text)
    assert doc["integrator"] == INTEGRATOR and doc["meta"]["task"] == "reactive-navigation"
    assert len(doc["meta"]["input_labels"]) == 11
    net = navigator()
    built = design()
    assert (net.size, net.n_inputs) == (4, 11)
    for field in ("tau", "theta", "weights", "sensor_weights"):
        assert np.array_equal(getattr(net, field), getattr(built, field)), field
    assert not np.array_equal(design(goal_gain=3.0).weights, net.weights)


def test_hand_designed_network_reaches_the_goal_in_the_open_room() -> None:
    env = Navigate("open-room", steps=400)
    result = rollout([navigator()], env, episodes=6, max_steps=env.steps, seed=3, purpose="evaluate",
                     **INTEGRATOR)
    assert env.success(result.returns[0], result.lengths[0]).all()
    assert (env.contact_steps == 0).all()
    assert (result.returns > 1.5).all()  # most of the way plus the arrival bonus
    # A random network of the same size does not.
    env = Navigate("open-room", steps=400)
    result = rollout([dnnevo.Network.random(4, 11, seed=0)], env, episodes=6, max_steps=env.steps,
                     seed=3, purpose="evaluate", **INTEGRATOR)
    assert not env.success(result.returns[0], result.lengths[0]).all()
