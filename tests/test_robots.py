"""2-D robots in closed loop (dnnevo.robots, dnnevo._core.Fleet): a trial against an independent
NumPy step of the same robot, pursuers and sensors; bad inputs; the example task in evolution; the
example script."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import dnnevo
import reference as ref
from dnnevo import _core
from dnnevo.closedloop import ClosedLoop, rollout
from dnnevo.errors import InvalidArgumentError, TaskError
from dnnevo.robots import Avoid, RobotWorld

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples"))

import robot_avoid  # noqa: E402

# ---------------------------------------------------------------------------------------------
# a whole trial against NumPy

# A 14 x 12 room. The robots start in the middle and drive at most 0.25 m/s for 10 s, so they
# never come near a wall or a box (the NumPy step is the motion in open space); the sonars,
# reaching 6.5 m, see the walls, the two boxes (one turned) and the pursuers.
WORLD = {
    "room": [14.0, 12.0],
    "start": {"min": [5.0, 4.0], "max": [9.0, 8.0]},
    "boxes": [{"center": [13.0, 6.0], "size": [0.8, 3.0], "angle_deg": 0.0},
              {"center": [2.0, 10.5], "size": [1.5, 0.6], "angle_deg": 30.0}],
}
SETTINGS = {
    "dt": 0.1,
    "robot": {"radius": 0.265, "wheel_base": 0.45, "max_speed": 0.25},
    "sonar": {"angles_deg": [0.0, 40.0, 90.0, 180.0, -90.0, -40.0], "cone_deg": 25.0, "rays": 3,
              "min_range": 0.15, "max_range": 6.5},
    "pursuers": {"count": 2, "radius": 0.2, "speed": 0.3, "max_turn_rate": 1.2,
                 "capture_radius": 0.5, "min_start_distance": 2.0},
    "sectors": {"count": 4, "range": 5.0},
}
STEPS = 100
SUBSTEPS = 5


class Traced(RobotWorld):
    """RobotWorld keeping every step's state."""

    def reset(self, episodes, rng):
        obs = super().reset(episodes, rng)
        self.trace = [self._state()]
        return obs

    def step(self, rates, active):
        out = super().step(rates, active)
        self.trace.append(self._state())
        return out

    def _state(self):
        f = self.fleet
        return {"poses": f.poses, "pursuers": f.pursuers, "ranges": f.ranges, "sectors": f.sectors,
                "captured": f.captured, "contacts": f.contacts}


def wrap(a):
    a = np.mod(a, 2 * np.pi)
    return np.where(a > np.pi, a - 2 * np.pi, a)


def drive(x, y, h, v, omega, dt):
    """A differential drive in open space: along the chord of the arc of constant v and omega,
    2 v / omega sin(omega dt / 2) long at the mean heading; the heading turns by omega dt."""
    with np.errstate(divide="ignore", invalid="ignore"):
        chord = np.where(omega == 0, v * dt, 2 * v / omega * np.sin(omega * dt / 2))
    mean = h + omega * dt / 2
    return x + chord * np.cos(mean), y + chord * np.sin(mean), wrap(h + omega * dt)


def ray_distances(o, u):
    """Distance along each ray (origins o, unit directions u, shape (..., 2)) to the room's walls
    (seen from inside) and to each box (the slab method in the box's frame); inf for a miss."""
    w, h = WORLD["room"]
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(u[..., 0] > 0, (w - o[..., 0]) / u[..., 0], -o[..., 0] / u[..., 0])
        ty = np.where(u[..., 1] > 0, (h - o[..., 1]) / u[..., 1], -o[..., 1] / u[..., 1])
        best = np.minimum(np.abs(tx), np.abs(ty))
        for b in WORLD["boxes"]:
            a = np.deg2rad(b["angle_deg"])
            c, s = np.cos(a), np.sin(a)
            q = o - b["center"]
            px, py = c * q[..., 0] + s * q[..., 1], -s * q[..., 0] + c * q[..., 1]
            dx, dy = c * u[..., 0] + s * u[..., 1], -s * u[..., 0] + c * u[..., 1]
            hx, hy = b["size"][0] / 2, b["size"][1] / 2
            x1, x2 = (-hx - px) / dx, (hx - px) / dx
            y1, y2 = (-hy - py) / dy, (hy - py) / dy
            enter = np.maximum(np.minimum(x1, x2), np.minimum(y1, y2))
            leave = np.minimum(np.maximum(x1, x2), np.maximum(y1, y2))
            best = np.minimum(best, np.where((enter <= leave) & (leave >= 0), np.maximum(enter, 0), np.inf))
    return best


def disc_distances(o, u, centres, radius):
    """Distance along each ray (..., 2) to the nearest of the discs ``centres`` (..., K, 2)."""
    q = o[..., None, :] - centres  # (..., K, 2)
    b = np.einsum("...d,...kd->...k", u, q)
    c = np.einsum("...kd,...kd->...k", q, q) - radius**2
    disc = b * b - c
    t = -b - np.sqrt(np.maximum(disc, 0))
    t = np.where((disc >= 0) & (b <= 0), t, np.inf)
    return np.where(c <= 0, 0.0, t).min(axis=-1)


def numpy_trial(nets, episodes, poses, pursuers):
    """The whole closed loop in NumPy from the starts ``poses`` (B, 3) and ``pursuers``
    (B, K, 3): the networks (tests/reference.py's Euler step), the robots, the pursuers and the
    sensors. Returns the state after each step, as Traced records it."""
    s = SETTINGS
    rows = len(poses)
    tau, theta, weights, sensor_weights = (np.repeat(np.stack([getattr(n, k) for n in nets]), episodes, 0)
                                           for k in ("tau", "theta", "weights", "sensor_weights"))
    sonar, rob, pur, sec = s["sonar"], s["robot"], s["pursuers"], s["sectors"]
    cone = np.deg2rad(sonar["cone_deg"])
    axes = np.deg2rad(sonar["angles_deg"])
    offsets = np.linspace(-cone / 2, cone / 2, sonar["rays"])

    def sense(p, q):
        h = p[:, 2:3]
        mount = p[:, None, :2] + rob["radius"] * np.stack([np.cos(h + axes), np.sin(h + axes)], -1)
        angle = (h + axes)[:, :, None] + offsets  # (B, S, R)
        u = np.stack([np.cos(angle), np.sin(angle)], -1)
        o = np.broadcast_to(mount[:, :, None, :], u.shape)
        d = np.minimum(ray_distances(o, u), disc_distances(o, u, q[:, None, None, :, :2], pur["radius"]))
        ranges = np.clip(d.min(axis=2), sonar["min_range"], sonar["max_range"])
        rel = q[:, :, :2] - p[:, None, :2]
        gap = np.maximum(np.hypot(rel[..., 0], rel[..., 1]) - rob["radius"] - pur["radius"], 0)
        width = 2 * np.pi / sec["count"]
        sector = np.floor((wrap(np.arctan2(rel[..., 1], rel[..., 0]) - h) + width / 2) / width) % sec["count"]
        sectors = np.full((rows, sec["count"]), sec["range"])
        for k in range(q.shape[1]):
            at = sector[:, k].astype(int)
            sectors[np.arange(rows), at] = np.minimum(sectors[np.arange(rows), at], gap[:, k])
        captured = (np.hypot(rel[..., 0], rel[..., 1]) <= pur["capture_radius"]).any(axis=1)
        obs = np.concatenate([np.minimum(1, 0.5 / ranges), 1 - sectors / sec["range"]], axis=1)
        return {"poses": p.copy(), "pursuers": q.copy(), "ranges": ranges, "sectors": sectors,
                "captured": captured}, obs

    p, q = poses.copy(), pursuers.copy()
    state, obs = sense(p, q)
    trace = [dict(state)]
    v = np.zeros(tau.shape)
    active = np.ones(rows, dtype=bool)
    for _ in range(STEPS):
        for _ in range(SUBSTEPS):
            v = np.where(active[:, None], ref.euler_step(v, 0.1, (tau, theta, weights, sensor_weights), obs), v)
        rates = ref.sigmoid(v - theta)
        left, right = (rob["max_speed"] * (2 * rates[:, k] - 1) for k in (0, 1))
        speed, turn = (left + right) / 2, (right - left) / rob["wheel_base"]
        # Pursuers turn towards where the robot was, as far as they may, and drive on.
        bearing = np.arctan2(p[:, None, 1] - q[..., 1], p[:, None, 0] - q[..., 0])
        omega = np.clip(wrap(bearing - q[..., 2]) / s["dt"], -pur["max_turn_rate"], pur["max_turn_rate"])
        moved = np.stack(drive(*p.T, speed, turn, s["dt"]), -1)
        chased = np.stack(drive(q[..., 0], q[..., 1], q[..., 2], pur["speed"], omega, s["dt"]), -1)
        p = np.where(active[:, None], moved, p)
        q = np.where(active[:, None, None], chased, q)
        new, new_obs = sense(p, q)
        for key in new:
            state[key] = np.where(active.reshape((-1,) + (1,) * (new[key].ndim - 1)), new[key], state[key])
        obs = np.where(active[:, None], new_obs, obs)
        trace.append({k: x.copy() for k, x in state.items()})
        active = active & ~state["captured"]
    return trace


def test_a_trial_agrees_with_an_independent_numpy_step_to_1e_9() -> None:
    # Networks whose robots all drive and turn (most random networks' robots barely move).
    nets = [dnnevo.Network.random(5, 10, seed=s) for s in (0, 4, 13, 27)]
    env = Traced(WORLD, **{k: v for k, v in SETTINGS.items() if k != "dt"})
    result = rollout(nets, env, episodes=3, max_steps=STEPS, dt=0.1, substeps=SUBSTEPS, seed=3)
    rust = env.trace
    assert len(rust) == STEPS + 1 and not any(t["contacts"].any() for t in rust)
    assert (result.lengths < STEPS).any(), "some robot should be captured"
    ours = numpy_trial(nets, 3, rust[0]["poses"], rust[0]["pursuers"])
    worst = 0.0
    for t, (a, b) in enumerate(zip(rust, ours)):
        assert np.array_equal(a["captured"], b["captured"]), t
        for key in ("poses", "pursuers", "ranges", "sectors"):
            diff = np.abs(a[key] - b[key])
            if key in ("poses", "pursuers"):  # a heading near pi may wrap either way
                diff[..., 2] = np.abs(wrap(a[key][..., 2] - b[key][..., 2]))
            worst = max(worst, float(diff.max()))
    assert worst < 1e-9, worst
    poses = np.array([t["poses"] for t in rust])
    assert (np.hypot(*np.diff(poses[..., :2], axis=0).transpose(2, 0, 1)).sum(axis=0) > 0.5).all()
    assert (np.abs(np.diff(poses[..., 2], axis=0)).sum(axis=0) > 0.05).mean() > 0.5
    # The sonars saw something besides the walls and the range's end.
    ranges = np.array([t["ranges"] for t in rust])
    assert ((ranges > 0.15) & (ranges < 6.5)).mean() > 0.3


def test_rows_give_the_same_bits_on_one_thread_and_on_all() -> None:
    code = (
        "import hashlib, numpy as np\n"
        "from dnnevo import _core\n"
        "f = _core.Fleet(_core.sim2d_landmark_world(2), {'pursuers': {'count': 2}, 'sectors': {'count': 4},"
        " 'sonar': {'noise_sd': 0.05}})\n"
        "f.reset(np.arange(200) % 7, 9)\n"
        "rng = np.random.default_rng(0)\n"
        "for t in range(100):\n"
        "    f.step(rng.uniform(-0.3, 1.0, (200, 2)), rng.random(200) < 0.9)\n"
        "print(hashlib.sha256(b''.join(a.tobytes() for a in (f.poses, f.pursuers, f.ranges, f.sectors,"
        " f.contacts, f.captured))).hexdigest())\n"
    )
    digests = set()
    for threads in ("1", "2", "3"):
        env = {**os.environ, "RAYON_NUM_THREADS": threads}
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                              timeout=60, check=True)
        digests.add(done.stdout.strip())
    assert len(digests) == 1


# ---------------------------------------------------------------------------------------------
# bad inputs


def fleet(rows: int = 2) -> _core.Fleet:
    f = _core.Fleet(_core.sim2d_landmark_world(1), {"pursuers": {"count": 1}})
    f.reset(np.arange(rows), 0)
    return f


@pytest.mark.parametrize("wheels, active, message", [
    ([[0.1, np.nan], [0.1, 0.1]], None, r"wheels\[0, 1\] is NaN; it must be a finite number"),
    ([[0.1, 0.1], [np.inf, 0.1]], None, r"wheels\[1, 0\] is inf"),
    ([0.1, 0.1], None, r"wheels has shape \(2,\); expected \(2, 2\)"),
    ([["a", "b"], ["c", "d"]], None, "wheels is not a numeric array"),
    ([[0.1, 0.1], [0.1, 0.1]], [1, 0], "active is an array of dtype int64 and shape"),
    ([[0.1, 0.1], [0.1, 0.1]], [True], r"active is an array of dtype bool and shape \(1,\); expected"),
])
def test_a_bad_step_names_its_argument_and_moves_nothing(wheels, active, message) -> None:
    f = fleet()
    before = f.poses
    with pytest.raises(InvalidArgumentError, match=message):
        f.step(wheels, active)
    assert np.array_equal(f.poses, before)


def test_an_ended_row_may_hold_any_wheel_speed() -> None:
    f = fleet()
    before = f.poses
    f.step([[0.2, 0.2], [np.nan, np.nan]], np.array([True, False]))
    assert np.array_equal(f.poses[1], before[1]) and not np.array_equal(f.poses[0], before[0])


@pytest.mark.parametrize("settings, message", [
    ({"robot": {"radius": "big"}}, r"settings\.robot\.radius: invalid type: string \"big\""),
    ({"robot": {"radious": 0.3}}, r"settings\.robot\.radious: unknown field `radious`, expected one of `radius`"),
    ({"sonars": {}}, r"settings\.sonars: unknown field `sonars`"),
    ({"dt": 0}, "dt is 0; it must be a finite number > 0"),
    ({"sonar": {"cone_deg": 200}}, r"sonar\.cone_deg is 200; it must be in \(0, 180\)"),
    ({"sonar": {"angles_deg": [0, float("nan")]}}, r"settings: sonar.angles_deg\[1\] is NaN"),
    ({"pursuers": {"count": 2, "speed": -1}}, "pursuers.speed is -1"),
    ({"pursuers": {"count": -1}}, r"settings\.pursuers\.count: invalid value: integer `-1`"),
    ({"sectors": {"range": 0}}, "sectors.range is 0"),
    ([1, 2], "settings must be a dict"),
])
def test_bad_settings_name_the_field(settings, message) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        _core.Fleet(_core.sim2d_landmark_world(1), settings)


def test_bad_worlds_resets_and_placements_name_the_argument(tmp_path: Path) -> None:
    with pytest.raises(InvalidArgumentError, match="world is 'landmark3'; expected one of 'landmark1'"):
        RobotWorld("landmark3")
    with pytest.raises(FileNotFoundError, match="world file .*missing.toml does not exist"):
        RobotWorld(tmp_path / "missing.toml")
    (tmp_path / "latin.toml").write_bytes(b"room = [6.0, 5.0] # \xff\n")
    with pytest.raises(InvalidArgumentError, match="latin.toml is not UTF-8 text"):
        RobotWorld(tmp_path / "latin.toml")
    with pytest.raises(InvalidArgumentError, match=r"a world file's name ends in .toml, not .TOML"):
        RobotWorld("my_world.TOML")
    (tmp_path / "bad.toml").write_text("room = [-4.0, 3.0]\nstart = { min = [0, 0], max = [1, 1] }\n")
    with pytest.raises(InvalidArgumentError, match=r"room\[0\] is -4"):
        RobotWorld(tmp_path / "bad.toml")
    with pytest.raises(InvalidArgumentError, match="world file: line 1"):
        _core.Fleet("rooms = [1, 2]")
    with pytest.raises(InvalidArgumentError, match="world is of type int"):
        _core.Fleet(3)
    with pytest.raises(InvalidArgumentError, match="robot is 0.3; expected a dict of settings"):
        RobotWorld(robot=0.3)
    with pytest.raises(InvalidArgumentError, match="left and right are both neuron 1"):
        RobotWorld(left=1, right=1)
    with pytest.raises(InvalidArgumentError, match="right is -1; expected a neuron index"):
        RobotWorld(right=-1)
    with pytest.raises(InvalidArgumentError, match="steps is 0"):
        Avoid(steps=0)
    f = fleet()
    with pytest.raises(InvalidArgumentError, match=r"episodes\[1\] is -2; it must be an integer"):
        f.reset([0, -2], 0)
    with pytest.raises(InvalidArgumentError, match="episodes is an array of dtype float64"):
        f.reset([0.5], 0)
    with pytest.raises(InvalidArgumentError, match="seed is -1"):
        f.reset([0], -1)
    with pytest.raises(InvalidArgumentError, match=r"poses has shape \(2, 2\); expected \(2, 3\)"):
        f.place([[1, 1], [1, 1]])
    with pytest.raises(InvalidArgumentError, match=r"pursuers has shape \(2, 3\); expected \(2, 1, 3\)"):
        f.place([[1, 1, 0], [1, 1, 0]], [[4, 4, 0], [4, 4, 0]])
    with pytest.raises(InvalidArgumentError, match=r"poses\[1\] is \(0.1, 1\) with clearance"):
        f.place([[1, 1, 0], [0.1, 1, 0]])
    # Beyond the walls the clearance to them is large: a pose there is outside the room all the same.
    with pytest.raises(InvalidArgumentError, match=r"poses\[1\] is \(100, 100\).*inside the room"):
        f.place([[1, 1, 0], [100, 100, 0]])
    with pytest.raises(InvalidArgumentError, match=r"pursuers.min_start_distance is 50"):
        _core.Fleet(_core.sim2d_landmark_world(1), {"pursuers": {"count": 1, "min_start_distance": 50}}).reset([0], 0)


def test_placed_robots_and_readouts() -> None:
    f = fleet(3)
    f.place([[1, 1, 0], [3, 1, np.pi / 2], [5, 4, np.pi]], [[[1.3, 1, 0]], [[5, 4.5, 0]], [[1, 4, 0]]])
    assert f.captured.tolist() == [True, False, False]
    assert f.poses.shape == (3, 3) and f.pursuers.shape == (3, 1, 3) and f.ranges.shape == (3, 8)
    assert f.sectors.shape == (3, 0) and f.contacts.dtype == bool and f.episodes.tolist() == [0, 1, 2]
    # Robot 1 at (3, 1) faces +y, towards the landmark's bottom face y = 2.2: 1.2 - 0.265.
    assert abs(f.ranges[1, 0] - 0.935) < 1e-12
    assert len(f) == f.rows == 3 and "pursuers=1" in repr(f)


# ---------------------------------------------------------------------------------------------
# the example task and script


def test_avoid_evolves_and_resumes_to_the_end_of_an_unbroken_run(tmp_path: Path) -> None:
    config = dnnevo.EvolutionConfig(population=12, generations=3, size=4, n_inputs=8,
                                    selection="rank", validation_candidates=2)
    fitness = ClosedLoop(Avoid(steps=20), episodes=2, max_steps=20, validation_episodes=4)
    whole = dnnevo.evolve(fitness, config, seed=4, progress=False, out=tmp_path / "whole")
    part = dnnevo.evolve(fitness, config, seed=4, progress=False, out=tmp_path / "part",
                         callback=lambda stats, ga: ga.generation >= 2)
    assert len(part.history["best"]) == 2
    assert 'task = "python:dnnevo.robots.avoid.Avoid"' in (tmp_path / "part" / "config.toml").read_text()
    with pytest.raises(dnnevo.ConfigError, match=r"Avoid as made here \(the environment.s attributes differ"):
        dnnevo.resume(tmp_path / "part", ClosedLoop(Avoid(steps=21), episodes=2, max_steps=20,
                                                    validation_episodes=4), progress=False)
    resumed = dnnevo.resume(tmp_path / "part", ClosedLoop(Avoid(steps=20), episodes=2, max_steps=20,
                                                          validation_episodes=4), progress=False)
    assert np.array_equal(resumed.history["best"], whole.history["best"])
    assert resumed.best == whole.best
    # dnnevo plot draws a robot task's paths: the room, and the champion's robot in it.
    from dnnevo.figures import draw_run

    assert draw_run(tmp_path / "whole", seed=3) == ["fitness.png", "episodes.png", "paths.png"]
    assert (tmp_path / "whole" / "paths.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # The path ends where the robot ended, after its last step (it ended one step short).
    from dnnevo.tasks.user import record

    from dnnevo.runs import RunDir

    config, _ = RunDir(tmp_path / "whole").read_config()
    episode = record(config, whole.best, 1, seed=3, probe=lambda env: {"pose": env.fleet.poses})[0]
    again = Avoid(steps=20)
    ended = rollout([whole.best], again, max_steps=20, seed=3, purpose="evaluate")
    assert len(episode.probed("pose")) == len(episode.rewards) + 1 == int(ended.lengths[0, 0]) + 1
    np.testing.assert_array_equal(episode.probed("pose")[-1], again.fleet.poses[0])


def test_a_count_of_robot_parts_past_the_limit_is_named_not_allocated() -> None:
    """A typing error (10**9 rays) allocated until the machine ran out of memory."""
    import re

    for settings, message in [(dict(sonar={"rays": 10**7}), "sonar.rays is 10000000; it must be in [1, 4096]"),
                              (dict(sectors={"count": 10**9}), "sectors.count is 1000000000; it must be in [0, 4096]"),
                              (dict(pursuers={"count": 10**9}), "pursuers.count is 1000000000; it must be in [0, 4096]"),
                              (dict(sonar={"angles_deg": [1000.0]}), "sonar.angles_deg[0] is 1000; it must be in [-360, 360]")]:
        with pytest.raises(InvalidArgumentError, match=re.escape(message)):
            RobotWorld("landmark1", **settings)


def test_a_world_file_that_does_not_parse_is_named(tmp_path: Path) -> None:
    """With a training and a transfer world, "world file: line 1" did not say which."""
    bad = tmp_path / "room_b.toml"
    bad.write_text("[room]\nsize = [6.0, 5.0]\n")
    with pytest.raises(InvalidArgumentError, match=f"^world file {bad}: line 1: room: "):
        RobotWorld(bad)


def test_avoid_pays_for_speed_and_charges_for_contacts() -> None:
    # Full speed ahead against the wall: the first steps pay, the ones stuck at the wall cost.
    env = Avoid(steps=50)
    env.reset(np.array([0]), np.random.default_rng(0))
    env.fleet.place([[1.0, 1.0, np.pi]])
    rewards = [env.step(np.array([[1.0, 1.0, 0.5]]), np.array([True]))[1][0] for _ in range(50)]
    assert rewards[0] == pytest.approx(1 / 50) and rewards[-1] == pytest.approx(0.0)
    assert env.touched[0] and not env.success(np.array([sum(rewards)]), np.array([50]))[0]


def test_the_example_script_runs(capsys: pytest.CaptureFixture[str]) -> None:
    robot_avoid.main(["--seeds", "2", "--population", "8", "--generations", "2", "--episodes", "2",
                      "--steps", "20", "--fresh", "10"])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("seed") and len(lines) == 1 + 2 + 1
    assert lines[1].split()[0] == "0" and "/10 (" in lines[1]
    assert "of 2 seeds" in lines[-1] and "95% interval" in lines[-1]


def test_a_world_file_array_of_three_numbers_is_refused_not_cut_to_two(tmp_path: Path) -> None:
    world = tmp_path / "room.toml"
    world.write_text("room = [5.0, 4.0, 3.0]\nstart = { min = [0.5, 0.5], max = [4.5, 3.5] }\n")
    with pytest.raises(InvalidArgumentError, match=r"line 1: room: invalid length 3, expected an array of 2"):
        RobotWorld(world)


def test_a_world_dict_error_names_the_field() -> None:
    world = {"room": [6.0, 5.0], "start": {"min": [0.4, 0.4], "max": [5.6, 4.6]},
             "boxes": [{"center": [3.0, 2.0], "size": [1.0, 1.0]}, {"center": [1.0, 1.0], "colour": 1}]}
    with pytest.raises(InvalidArgumentError, match=r"world.boxes\[1\].colour: unknown field `colour`"):
        RobotWorld(world)
    world["boxes"] = [{"center": [3.0, 2.0], "size": [1.0]}]
    with pytest.raises(InvalidArgumentError, match=r"world.boxes\[0\].size: invalid length 1"):
        RobotWorld(world)


def test_a_start_region_with_too_little_room_is_refused_when_the_world_is_made() -> None:
    # A 1.2 m box in a 2 m room leaves a robot of radius 0.265 no place 0.05 m from everything.
    crowded = {"room": [2.0, 2.0], "start": {"min": [0.3, 0.3], "max": [1.7, 1.7]},
               "boxes": [{"center": [1.0, 1.0], "size": [1.2, 1.2]}]}
    with pytest.raises(InvalidArgumentError, match=r"start region is free .* at 0.00% of its points"):
        RobotWorld(crowded)


def test_networks_too_small_for_the_wheels_are_named() -> None:
    with pytest.raises(TaskError, match=r"wheels \(left, right\) read neurons \[0, 1\]; the networks have "
                                        r"1 neuron: give them at least 2"):
        rollout([dnnevo.Network.random(1, 8, seed=1)], RobotWorld("landmark1"), max_steps=3)
    with pytest.raises(TaskError, match=r"read neurons \[0, 7\]; the networks have 4 neurons"):
        rollout([dnnevo.Network.random(4, 8, seed=1)], RobotWorld("landmark1", right=7), max_steps=3)


def test_the_command_line_takes_n_inputs_from_the_instance_not_the_class() -> None:
    from dnnevo import presets
    config = presets.get("python:dnnevo.robots.RobotWorld",
                         overrides=["task_params.max_steps=50", "task_params.sonar={angles_deg=[0, 90]}"])
    assert config.n_inputs == 2
    config = presets.get("python:dnnevo.robots.RobotWorld",
                         overrides=["task_params.max_steps=50", "task_params.sectors={count=4}"])
    assert config.n_inputs == 12
    assert presets.get("python:dnnevo.robots.RobotWorld",
                       overrides=["task_params.max_steps=50", "n_inputs=3"]).n_inputs == 3
