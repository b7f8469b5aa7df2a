"""Reactive navigation (dnnevo.robots.Navigate): the destination sensor on hand-computed poses,
the reward and the success rule, the hand-designed network shipped in the package, and the
static and cyclic detectors on hand-built trajectories and in the U-shaped trap."""

from __future__ import annotations

import json
import sys
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import dnnevo
from dnnevo.closedloop import rollout
from dnnevo.errors import InvalidArgumentError
from dnnevo.experiments import examples
from dnnevo.robots import Navigate
from dnnevo.robots.navigation import (INTEGRATOR, WORLDS, Detectors, bearing, design, destination,
                                      hand_designed, looping, navigation_world, navigator, stuck)

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples"))

import reactive_navigation  # noqa: E402

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


def trajectories(steps: int = 200) -> np.ndarray:
    """Three hand-built tracks of 0.1 s steps (3, steps + 1, 2): a robot that stays within a
    few centimetres of one spot, one that circles (radius 0.5 m at 0.5 m/s: a lap in 6.3 s)
    and one that drives straight at 0.5 m/s."""
    t = np.arange(steps + 1) * 0.1
    rng = np.random.default_rng(0)
    still = np.array([2.0, 2.0]) + rng.uniform(-0.03, 0.03, (steps + 1, 2))
    circle = np.stack([2.0 + 0.5 * np.cos(t), 2.0 + 0.5 * np.sin(t)], axis=1)
    straight = np.stack([0.5 + 0.5 * t, np.full_like(t, 1.0)], axis=1)
    return np.stack([still, circle, straight])


def test_static_detector_fires_on_a_stuck_robot_only() -> None:
    track = trajectories()
    assert stuck(track, 30, 0.2).tolist() == [True, False, False]
    assert stuck(track[:, :20], 30, 0.2).tolist() == [False] * 3  # not yet 3 s of track
    gone = track.copy()
    gone[0, -25] = np.nan  # a gap in the record (the memory was cleared): not stuck yet
    assert stuck(gone, 30, 0.2).tolist() == [False, False, False]
    # Slow but steady: 0.05 m/s for 3 s is 0.15 m, under 0.2 m; 0.1 m/s is not.
    slow = track[2:] * np.array([0.1, 1.0])
    assert stuck(slow, 30, 0.2).tolist() == [True]
    assert stuck(track[2:] * np.array([0.2, 1.0]), 30, 0.2).tolist() == [False]


def test_detector_windows_and_tracks_of_the_wrong_shape_are_named() -> None:
    straight = np.stack([np.linspace(0, 3, 40), np.zeros(40)], axis=1)[None]
    for bad in (0, -1, 1.5, True):
        with pytest.raises(InvalidArgumentError, match="span is .*; it must be an integer >= 1"):
            stuck(straight, bad, 0.2)
        with pytest.raises(InvalidArgumentError, match="after is .*; it must be an integer >= 1"):
            looping(straight, bad, 0.3)
    with pytest.raises(InvalidArgumentError, match=r"track has shape \(40, 2\)"):
        stuck(straight[0], 3, 0.2)
    assert stuck(straight, 3, 0.2).tolist() == [False] and looping(straight, 3, 0.05).tolist() == [False]


def test_cyclic_detector_fires_on_a_circling_robot_not_a_straight_one() -> None:
    track = trajectories()
    assert looping(track[:, -300:], 60, 0.3).tolist() == [True, True, False]
    # Looking back 7 to 8 s only, the circling robot is 0.7 to 1.7 rad past where it was.
    assert looping(track[:, 120:], 70, 0.3).tolist() == [True, False, False]
    # A lap of 12.6 s (radius 1 m) is a loop only once the detector looks back that far.
    t = np.arange(301) * 0.1
    wide = np.stack([1.0 * np.cos(0.5 * t), 1.0 * np.sin(0.5 * t)], axis=1)[None]
    assert looping(wide[:, -100:], 60, 0.3).tolist() == [False]
    assert looping(wide, 60, 0.3).tolist() == [True]


def test_detectors_fire_and_the_frustration_input_follows() -> None:
    # A robot held still fires the static detector after 3 s, and frustration turns on.
    env = placed([1.0, 1.0, 0.0], detectors=True)
    for _ in range(29):
        obs, _, _ = env.step(STILL, ONE)
    assert obs[0, 10] == 0.0 and env.fired.tolist() == [[0, 0]]
    obs, _, _ = env.step(STILL, ONE)
    assert obs[0, 10] == 1.0 and env.fired.tolist() == [[1, 0]] and env.escapes.tolist() == [1]
    # Held still, the escape is stuck too: after 3 s more it turns to the other side, and back.
    sides = [env.step(STILL, ONE)[0][0, 10] for _ in range(61)]
    assert sides[:29] == [1.0] * 29 and sides[29:59] == [-1.0] * 30 and sides[59:] == [1.0] * 2
    assert env.fired.tolist() == [[3, 0]] and env.escapes.tolist() == [3]
    # Free to move, an escape ends after escape_seconds at most, and the memory starts again.
    env = placed([3.0, 3.0, 0.0], detectors=Detectors(escape_seconds=2.0))
    seen = [env.step(STILL, ONE)[0][0, 10] for _ in range(30)]
    back = np.array([[0.3, 0.3]])  # backwards at 0.4 m/s, away from the goal at (7, 3)
    seen += [env.step(back, ONE)[0][0, 10] for _ in range(25)]
    assert seen[29:49] == [1.0] * 20 and seen[49:] == [0.0] * 6
    assert env.fired.tolist() == [[1, 0]]
    # An escape ends as soon as the robot is 0.1 m nearer the goal than it ever was (4 m here).
    env = placed([3.0, 3.0, 0.0], detectors=True)
    for _ in range(30):
        env.step(STILL, ONE)
    ahead = [env.step(np.array([[0.75, 0.75]]), ONE)[0][0, 10] for _ in range(5)]  # 0.05 m a step
    assert ahead == [1.0, 1.0, 0.0, 0.0, 0.0]
    # Driving round in a circle (wheels 0.25 and 0.75 m/s: radius 0.45 m) fires the cyclic one.
    env = placed([1.5, 1.5, 0.0], detectors=True)
    turn = np.array([[0.625, 0.875]])
    fired = [env.step(turn, ONE)[0][0, 10] for _ in range(100)]
    assert env.fired.tolist() == [[0, 1]] and 55 <= fired.index(1.0) <= 80  # a lap is about 5.7 s
    # Driving straight across the open room fires neither, and without detectors nothing fires.
    env = placed([0.5, 0.8, 0.0], detectors=True)
    for _ in range(60):
        obs, _, _ = env.step(np.array([[0.75, 0.75]]), ONE)
    assert env.fired.tolist() == [[0, 0]] and obs[0, 10] == 0.0
    env = placed([1.0, 1.0, 0.0])
    for _ in range(100):
        obs, _, _ = env.step(STILL, ONE)
    assert env.fired.tolist() == [[0, 0]] and obs[0, 10] == 0.0


def test_detectors_turn_u_trap_failures_into_arrivals() -> None:
    ok = {}
    for detectors in (False, True):
        env = Navigate("u-trap", detectors=detectors)
        result = rollout([navigator()], env, episodes=8, max_steps=env.steps, seed=0, purpose="evaluate",
                         **INTEGRATOR)
        ok[detectors] = env.success(result.returns[0], result.lengths[0])
        if detectors:
            assert env.escapes[~ok[False]].min() >= 1  # every rescued start needed an escape
    assert (~ok[False]).sum() >= 3  # the network alone is caught in the trap
    assert (ok[True] & ~ok[False]).sum() >= 3  # ... and the detectors get it out


def test_hand_designed_counts_what_a_rollout_of_the_network_does() -> None:
    """The one function the example and ``dnnevo reproduce`` call counts the arrivals, contacts
    and firings of a rollout from the same starts, with and without detectors."""
    for detectors in (False, True):
        env = Navigate("u-trap", detectors=detectors, steps=600)
        r = rollout([navigator()], env, episodes=6, max_steps=env.steps, seed=11, purpose="evaluate", **INTEGRATOR)
        got = hand_designed("u-trap", 6, seed=11, detectors=detectors, steps=600)
        ok = env.arrived
        assert (got["world"], got["detectors"], got["dt"], got["starts"]) == ("u-trap", detectors, 0.1, 6)
        assert got["arrived"] == int(ok.sum())
        assert got["contact"] == env.contact_steps.sum() / r.lengths.sum()
        assert [got["static"], got["cyclic"]] == env.fired.mean(axis=0).tolist()
        assert np.isnan(got["time"]) if not ok.any() else got["time"] == (r.lengths[0][ok] * 0.1).mean()
    finer = hand_designed("open-room", 2, seed=11, finer=2, steps=300)
    assert finer["dt"] == 0.05 and finer["arrived"] == 2
    for name, kwargs in (("starts", {"starts": 0}), ("finer", {"finer": 0}), ("steps", {"steps": -1})):
        with pytest.raises(InvalidArgumentError, match=f"{name} is"):
            hand_designed("open-room", **{"starts": 1, "seed": 0, **kwargs})  # type: ignore[arg-type]


def test_bad_detector_settings_are_named() -> None:
    with pytest.raises(InvalidArgumentError, match="static_seconds is 0; expected a number in"):
        Detectors(static_seconds=0)
    with pytest.raises(InvalidArgumentError, match="cycle_window is 5.0; it must be longer than cycle_after"):
        Detectors(cycle_window=5.0)


def test_example_runs_with_tiny_settings_and_records(tmp_path: Path) -> None:
    record, png = tmp_path / "reactive.json", tmp_path / "paths.png"
    assert reactive_navigation.main(["--starts", "3", "--steps", "40", "--paths", "2",
                                     "--figure", str(png), "--record", str(record)]) == 0
    doc = examples.read(record)
    assert doc["command"] == "python examples/reactive_navigation.py --starts 3 --steps 40 --paths 2 " \
                             f"--figure {png}"
    assert len(doc["rows"]) == 12 and len(doc["summary"]) == 6
    assert [r[:3] for r in doc["rows"][:2]] == [["open-room", "off", "0.1 s"], ["open-room", "on", "0.1 s"]]
    assert all(r[3].endswith("%)") and "/3 (" in r[3] for r in doc["rows"])
    assert png.stat().st_size > 1000


def test_example_evolved_comparison_runs_with_tiny_settings(tmp_path: Path) -> None:
    record = tmp_path / "evolved.json"
    assert reactive_navigation.main(["--evolve", "1", "--generations", "1", "--starts", "2",
                                     "--record", str(record)]) == 0
    doc = examples.read(record)
    assert [r[0] for r in doc["rows"]] == ["hand-designed, detectors off", "hand-designed, detectors on",
                                           "evolved, seed 0"]
    assert all("/2 (" in cell for r in doc["rows"] for cell in r[1:4])
    assert doc["summary"][-1].endswith("The paper evolved no network for this task.")


def test_a_missing_navigation_world_file_is_file_not_found(tmp_path: Path) -> None:
    from dnnevo.robots import Navigate

    with pytest.raises(FileNotFoundError, match="world file .*gone.toml does not exist"):
        Navigate(tmp_path / "gone.toml")
