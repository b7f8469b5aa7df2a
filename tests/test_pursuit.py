"""Predator avoidance (dnnevo.robots.Pursuit): its reward and success rule on hand-built cases,
the baselines, a short evolution, the preset from the command line, and the example script
with its record."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import dnnevo
from dnnevo.closedloop import ClosedLoop, rollout
from dnnevo.errors import InvalidArgumentError
from dnnevo.robots import Pursuit
from dnnevo.robots.pursuit import ARENA, PURSUERS, TRANSFER, TRANSFER_FACTORS, drive, escape, transfer_part

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples"))

import predator_avoidance  # noqa: E402

STILL = np.array([[0.5, 0.5]])  # rates of 0.5: both wheels at 0 m/s
AHEAD = np.array([[1.0, 1.0]])  # full speed ahead
ONE = np.array([True])


def placed(robot: list[float], pursuers: list[list[float]], **kwargs: object) -> Pursuit:
    """A Pursuit of one row with its robot and pursuers placed by hand."""
    env = Pursuit(**kwargs)  # type: ignore[arg-type]
    env.reset(np.array([0]), np.random.default_rng(0))
    env.fleet.place([robot], [pursuers])
    return env


def run(env: Pursuit, rates: np.ndarray, steps: int) -> tuple[list[float], list[bool]]:
    rewards, done = [], []
    for _ in range(steps):
        _, r, d = env.step(rates, ONE)
        rewards.append(float(r[0]))
        done.append(bool(d[0]))
        if d[0]:
            break
    return rewards, done


# ---------------------------------------------------------------------------------------------
# the reward and the success rule on hand-built cases


def test_a_caught_robot_is_paid_for_the_steps_it_survived_and_fails() -> None:
    # A still robot at (1, 5), a pursuer 1.5 m to its right facing it, the other far away: the
    # gap closes at 0.4 m/s, 0.04 m per step, and reaches the capture radius of 0.5 m after
    # 1.0 / 0.04 = 25 steps. The 24 steps before pay 1/50 each; the step of the capture nothing.
    env = placed([1.0, 5.0, 0.0], [[2.5, 5.0, np.pi], [7.5, 0.5, 0.0]], steps=50)
    rewards, done = run(env, STILL, 50)
    assert len(rewards) == 25 and done[-1] and not any(done[:-1])
    assert rewards[:-1] == [pytest.approx(1 / 50)] * 24 and rewards[-1] == 0.0
    assert env.caught[0] and env.contact_steps[0] == 0
    assert not env.success(np.array([sum(rewards)]), np.array([25]))[0]


def test_a_robot_against_a_wall_pays_for_each_step_it_is_stopped() -> None:
    # Full speed at the left wall from x = 1: 0.735 m to go at 0.1 m per step, so the eighth
    # step is the first the wall cuts short, and every step after it pays nothing (penalty 1);
    # with penalty 2 those steps cost as much as a free step pays.
    for penalty, stopped in ((1.0, 0.0), (2.0, -1 / 50)):
        env = placed([1.0, 3.0, np.pi], [[7.0, 5.5, 0.0], [7.0, 0.6, 0.0]], steps=50,
                     contact_penalty=penalty)
        rewards, done = run(env, AHEAD, 20)
        assert not any(done) and not env.caught[0]
        assert rewards[:7] == [pytest.approx(1 / 50)] * 7
        assert rewards[8:] == [pytest.approx(stopped)] * 12
        assert env.contact_steps[0] in (12, 13)  # the eighth step may or may not be cut short


def test_the_success_rule_needs_no_capture_the_whole_trial_and_few_contacts() -> None:
    env = Pursuit(steps=450)  # at most 2% of 450 steps, 9, in contact
    env.reset(np.arange(5), np.random.default_rng(0))
    env.caught[:] = [False, True, False, False, False]
    env.contact_steps[:] = [0, 0, 9, 10, 0]
    lengths = np.array([450, 450, 450, 450, 449])  # the last cut short by max_steps
    assert env.success(np.ones(5), lengths).tolist() == [True, False, True, False, False]


def test_the_world_and_settings_are_the_documented_ones() -> None:
    env = Pursuit()
    assert env.world["room"] == ARENA["room"] and len(env.world["boxes"]) == 3
    assert {k: env.settings["pursuers"][k] for k in PURSUERS} == PURSUERS
    assert env.observation_size == 12 and env.steps == 450
    # A section given changes only its keys.
    env = Pursuit(pursuers={"speed": 0.2})
    assert env.settings["pursuers"]["speed"] == 0.2 and env.settings["pursuers"]["detour"] is True
    assert env.settings["pursuers"]["count"] == 2
    moved = Pursuit(**TRANSFER)
    assert moved.world["room"] == TRANSFER["world"]["room"] and moved.sector_noise_sd == 0.2


def params(env: Pursuit, prefix: str = "") -> dict[str, object]:
    """Every parameter of ``env``'s world, one per leaf: ``world.room``, ``settings.pursuers.speed``..."""
    def flat(d: dict, p: str) -> dict[str, object]:
        out: dict[str, object] = {}
        for k, v in d.items():
            out.update(flat(v, f"{p}{k}.") if isinstance(v, dict) else {f"{p}{k}": v})
        return out
    return flat({"world": env.world, "settings": env.settings, "sector_noise_sd": env.sector_noise_sd,
                 "steps": env.steps, "contact_penalty": env.contact_penalty, "max_contact": env.max_contact}, prefix)


def changed(a: dict[str, object], b: dict[str, object]) -> set[str]:
    assert a.keys() == b.keys()
    return {k for k in a if a[k] != b[k]}


# TRANSFER as it was when the reference runs and docs/results/examples/predator-avoidance.json
# judged champions in it.
TRANSFER_AS_RECORDED = {
    "world": {"room": [7.0, 7.0], "start": {"min": [0.4, 0.4], "max": [6.6, 6.6]},
              "boxes": [{"center": [2.0, 5.0], "size": [1.4, 0.5], "angle_deg": 0.0},
                        {"center": [5.0, 5.2], "size": [0.7, 0.7], "angle_deg": 45.0},
                        {"center": [3.5, 3.0], "size": [0.5, 1.5], "angle_deg": 0.0},
                        {"center": [5.5, 1.8], "size": [0.8, 0.8], "angle_deg": 15.0}]},
    "pursuers": {"speed": 0.45, "max_turn_rate": 2.5}, "sonar": {"noise_sd": 0.05}, "sector_noise_sd": 0.2}
FACTOR_PARAMS = {"room": {"world.room", "world.start.max", "world.boxes"},
                 "pursuers": {"settings.pursuers.speed", "settings.pursuers.max_turn_rate"},
                 "noise": {"settings.sonar.noise_sd", "sector_noise_sd"}}


def test_each_one_factor_world_differs_from_the_training_world_only_in_its_factor() -> None:
    trained, transfer = params(Pursuit()), params(Pursuit(**TRANSFER))
    assert TRANSFER == TRANSFER_AS_RECORDED and transfer == params(Pursuit(**TRANSFER_AS_RECORDED))
    assert list(TRANSFER_FACTORS) == list(FACTOR_PARAMS)
    assert changed(trained, transfer) == set().union(*FACTOR_PARAMS.values())  # the factors are all it changes
    assert transfer_part() == {} and params(Pursuit(**transfer_part())) == trained
    assert transfer_part(*TRANSFER_FACTORS) == TRANSFER
    for factor, keys in FACTOR_PARAMS.items():
        alone = params(Pursuit(**transfer_part(factor)))
        assert changed(trained, alone) == keys, factor
        assert {k: alone[k] for k in keys} == {k: transfer[k] for k in keys}, factor
        others = [f for f in TRANSFER_FACTORS if f != factor]
        assert changed(transfer, params(Pursuit(**transfer_part(*others)))) == keys, factor
    part = transfer_part("pursuers")
    part["pursuers"]["speed"] = 9.0  # a copy: TRANSFER stays as it was
    assert TRANSFER == TRANSFER_AS_RECORDED
    with pytest.raises(InvalidArgumentError, match="no transfer factor 'rooms'"):
        transfer_part("rooms")


def test_the_ablations_training_and_transfer_worlds_are_the_examples() -> None:
    """--ablation judges in the same training and transfer worlds, integrated alike, as the
    evolving run of the example; its one-factor worlds start where the training world does
    (the room aside)."""
    from dnnevo import presets

    cfg = presets.get("predator-avoidance")
    judged, ablated = predator_avoidance.worlds(cfg), predator_avoidance.ablation_worlds(cfg)
    assert list(ablated) == ["training world", "room only", "pursuers only", "noise only", "all but the room",
                             "all but the pursuers", "all but the noise", "transfer world"]
    for mine, theirs in (("training world", "trained"), ("transfer world", "transfer")):
        loop, other = ablated[mine][1], judged[theirs]
        assert params(loop.env) == params(other.env) and loop.settings == other.settings
    assert ablated["training world"][0] == "nothing"
    assert ablated["room only"][0] == "room (7 m x 7 m, 4 boxes)"
    starts = {}
    for world in ("training world", "pursuers only", "noise only"):
        env = ablated[world][1].env
        drive(escape(env), env, episodes=20, max_steps=0, seed=predator_avoidance.FRESH_SEED, purpose="evaluate")
        starts[world] = env.fleet.poses.copy(), env.fleet.pursuers.copy()
    for world in ("pursuers only", "noise only"):
        assert all(np.array_equal(a, b) for a, b in zip(starts[world], starts["training world"]))


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"steps": 0}, "steps is 0"),
    ({"steps": 4.5}, "steps is 4.5"),
    ({"contact_penalty": -1}, "contact_penalty is -1"),
    ({"max_contact": 1.5}, "max_contact is 1.5"),
    ({"sector_noise_sd": "loud"}, "sector_noise_sd is 'loud'"),
    ({"pursuers": 3}, "pursuers is 3"),
    ({"pursuers": {"sped": 1.0}}, "settings.pursuers.sped"),
    ({"world": "landmark3"}, "world is 'landmark3'"),
])
def test_bad_settings_are_named(kwargs: dict, message: str) -> None:
    with pytest.raises(InvalidArgumentError, match=message):
        Pursuit(**kwargs)


def test_without_the_detour_a_robot_that_never_moves_hides_and_with_it_is_caught() -> None:
    """Pure pursuit stops at a box between a pursuer and the robot; the detour goes round it."""
    def still(obs: np.ndarray) -> np.ndarray:
        return np.full((len(obs), 2), 0.5)

    escaped = {}
    for detour in (False, True):
        env = Pursuit(pursuers={"detour": detour})
        r = drive(still, env, episodes=40, max_steps=env.steps, seed=1)
        escaped[detour] = int(env.success(r.returns[0], r.lengths[0]).sum())
    assert escaped[False] >= 8 and escaped[True] == 0, escaped


def test_sector_noise_changes_only_the_pursuer_sensor() -> None:
    rng = np.random.default_rng
    quiet = Pursuit().reset(np.arange(6), rng(3))
    loud_env = Pursuit(sector_noise_sd=0.3)
    loud = loud_env.reset(np.arange(6), rng(3))
    assert np.array_equal(quiet[:, :8], loud[:, :8])  # the same starts and sonars
    assert not np.array_equal(quiet[:, 8:], loud[:, 8:])
    assert ((loud[:, 8:] >= 0) & (loud[:, 8:] <= 1)).all()


# ---------------------------------------------------------------------------------------------
# the baselines


def test_drive_meets_the_starts_a_networks_rollout_meets() -> None:
    a, b = Pursuit(steps=5), Pursuit(steps=5)
    drive(escape(a), a, episodes=4, max_steps=0, seed=9, purpose="evaluate")
    rollout([dnnevo.Network.random(6, 12, seed=0)], b, episodes=4, max_steps=0, seed=9, purpose="evaluate")
    assert np.array_equal(a.fleet.poses, b.fleet.poses) and np.array_equal(a.fleet.pursuers, b.fleet.pursuers)
    with pytest.raises(InvalidArgumentError, match="episodes is 0"):
        drive(escape(a), a, episodes=0, max_steps=5)


def test_the_escape_rule_outlasts_random_networks() -> None:
    env = Pursuit(steps=300)
    ruled = drive(escape(env), env, episodes=12, max_steps=300, seed=4, purpose="evaluate")
    nets = [dnnevo.Network.random(6, 12, seed=s) for s in range(5)]
    randoms = rollout(nets, Pursuit(steps=300), episodes=12, max_steps=300, seed=4, purpose="evaluate")
    assert ruled.returns.mean() > randoms.fitness.max() + 0.1, (ruled.returns.mean(), randoms.fitness)


def test_the_escape_rule_turns_away_from_a_pursuer_and_from_a_wall() -> None:
    env = Pursuit()
    policy = escape(env)
    obs = np.zeros((3, 12))
    obs[0, 8] = 0.9    # a pursuer straight ahead: turn (the wheels differ) and do not drive on
    obs[1, 9] = 0.9    # a pursuer on the left: turn right, the left wheel faster
    obs[2, 0] = 1.0    # a wall right ahead, no pursuer
    rates = policy(obs)
    assert rates.shape == (3, 2) and ((rates >= 0) & (rates <= 1)).all()
    assert rates[0].mean() <= 0.5 + 1e-12 and rates[0, 0] != rates[0, 1]
    assert rates[1, 0] > rates[1, 1]
    assert rates[2].mean() <= 0.5 + 1e-12


# ---------------------------------------------------------------------------------------------
# evolution and the preset


def test_a_champion_evolves_past_random_networks() -> None:
    """A short evolution on the task's own fitness beats the random networks it started from
    on the same fresh episodes."""
    config = dnnevo.EvolutionConfig(population=30, generations=8, size=6, n_inputs=12, selection="rank",
                                    elitism=2, validation_candidates=3)
    env = Pursuit(steps=200)
    result = dnnevo.evolve(ClosedLoop(env, episodes=3, max_steps=200, validation_episodes=6), config,
                           seed=2, progress=False)
    nets = [dnnevo.Network.random(6, 12, seed=s) for s in range(5)]
    fresh = rollout([result.best, *nets], Pursuit(steps=200), episodes=16, max_steps=200, seed=5,
                    purpose="evaluate")
    assert fresh.fitness[0] > fresh.fitness[1:].max(), fresh.fitness


def test_the_preset_runs_resumes_and_is_judged_from_the_command_line(tmp_path: Path) -> None:
    from cli_helpers import run_cli

    run_dir = tmp_path / "pursuit"
    r = run_cli("run", "predator-avoidance", "--quick", "--set", "generations=2", "--set", "population=8",
                "--set", "task_params.episodes=2", "--set", "task_params.validation_episodes=4",
                "--out", run_dir)
    assert r.returncode == 0, r.stderr
    config = (run_dir / "config.toml").read_text()
    assert 'task = "python:dnnevo.robots.pursuit.Pursuit"' in config and "validation_candidates = 5" in config
    r = run_cli("resume", run_dir, "--generations", "3")
    assert r.returncode == 0 and "3 generations" in r.stdout, r.stdout + r.stderr
    r = run_cli("assess", run_dir, "--trials", "10")
    assert r.returncode in (0, 1) and "success needs >= 80%" in r.stdout, r.stdout + r.stderr


def test_the_example_runs_and_records(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from cli_helpers import assert_png

    from dnnevo.experiments import examples, results

    record = tmp_path / "results" / "examples" / "predator-avoidance.json"
    argv = ["--seeds", "2", "--workers", "2", "--set", "population=8", "--set", "generations=2",
            "--set", "task_params.episodes=2", "--set", "task_params.validation_episodes=4",
            "--fresh", "6", "--random", "2", "--figure", str(tmp_path / "p.png"),
            "--animation", str(tmp_path / "p.gif"), "--champions", str(tmp_path / "nets"),
            "--record", str(record)]
    predator_avoidance.main(argv)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("seed") and [line.split()[0] for line in lines[1:3]] == ["0", "1"]
    assert all("/6 (" in line for line in lines[1:3])
    summary = lines[3:]
    assert summary[0].startswith("champions that meet the success rule") and "of 2 seeds" in summary[0]
    assert any(line.startswith("fresh episodes escaped in the transfer world, pooled: champions ")
               and "; escape rule " in line and "/6 (" in line and "; random networks " in line
               and "/12 (" in line for line in summary)
    assert summary[-1].startswith("seeds whose champion keeps its escape rate at half the step")
    assert_png(tmp_path / "p.png")
    assert (tmp_path / "p.gif").read_bytes()[:6] == b"GIF89a"
    assert dnnevo.Network.load(tmp_path / "nets" / "seed-1.json").n_inputs == 12
    # A saved champion drawn again, in a chosen episode, without evolving anything.
    predator_avoidance.main(["--draw", str(tmp_path / "nets" / "seed-1.json"), "--episode", "2",
                             "--figure", str(tmp_path / "again.png")])
    assert_png(tmp_path / "again.png") and capsys.readouterr().out == ""
    with pytest.raises(SystemExit):
        predator_avoidance.main(["--draw", str(tmp_path / "nets" / "seed-1.json")])
    with pytest.raises(SystemExit):  # a negative episode is refused, not drawn from the end
        predator_avoidance.main(["--draw", str(tmp_path / "nets" / "seed-1.json"), "--episode", "-1",
                                 "--figure", str(tmp_path / "never.png")])
    assert not (tmp_path / "never.png").exists()
    doc = examples.read(record)
    given = argv[:argv.index("--record")]
    assert doc["command"] == " ".join(["python", "examples/predator_avoidance.py", *given])
    assert doc["summary"] == summary and len(doc["rows"]) == 2
    page = tmp_path / "page.md"
    page.write_text("<!-- results:example:predator-avoidance:begin -->\nold\n"
                    "<!-- results:example:predator-avoidance:end -->\n")
    assert results.render(tmp_path, results_dir=tmp_path / "results", files=[page]) == [page]
    text = page.read_text()
    assert "old" not in text and all("| " + " | ".join(row) + " |" in text for row in doc["rows"])
    assert results.render(tmp_path, results_dir=tmp_path / "results", files=[page], check=True) == []


def test_the_drawn_episode_is_the_first_the_champion_escapes() -> None:
    from dnnevo import presets

    # In 3 s no pursuer reaches the robot, so an episode is escaped when the robot touches
    # nothing: this random network does so in some of the first six fresh episodes, not the first.
    cfg = presets.get("predator-avoidance", overrides=["task_params.max_steps=30"])
    net = dnnevo.Network.random(6, 12, seed=1)
    env = Pursuit(steps=30)
    i = cfg.integrator
    r = rollout([net], env, episodes=6, max_steps=30, dt=i.dt, substeps=i.substeps, seed=predator_avoidance.FRESH_SEED,
                purpose="evaluate")
    ok = env.success(r.returns[0], r.lengths[0])
    assert ok.any() and not ok[0]
    shown = predator_avoidance.trace(net, cfg, "random", episodes=6)
    assert shown.episode == int(np.flatnonzero(ok)[0]) and not shown.caught and shown.contact_steps == 0
    assert len(shown.robot) == len(shown.chasers) == 31
    assert shown.title == f"random, fresh episode {shown.episode}: not caught in 3 s, touching a wall or box for 0.0 s"
    # The robot's path is the traced row's: it starts where that episode starts.
    start = Pursuit(steps=30)
    drive(escape(start), start, episodes=6, max_steps=0, seed=predator_avoidance.FRESH_SEED, purpose="evaluate")
    assert np.array_equal(shown.robot[0], start.fleet.poses[shown.episode])
    assert np.array_equal(shown.chasers[0], start.fleet.pursuers[shown.episode])
    again = predator_avoidance.trace(net, cfg, "random", episodes=6, episode=0)
    assert again.episode == 0 and again.contact_steps > 0


def test_the_examples_counts_and_comparisons() -> None:
    row = {"trained": {"successes": 18, "episodes": 20}, "half step": {"successes": 12, "episodes": 20}}
    assert not predator_avoidance.kept(row)  # 60% lies outside 90%'s interval (70%-97%)
    row["half step"]["successes"] = 16
    assert predator_avoidance.kept(row)
    assert predator_avoidance.beats({"successes": 18, "episodes": 20}, {"successes": 2, "episodes": 20})
    assert not predator_avoidance.beats({"successes": 12, "episodes": 20}, {"successes": 8, "episodes": 20})
    assert predator_avoidance.rate(3, 10) == "3/10 (30%, 11%-60%)"
