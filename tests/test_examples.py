"""The example scripts run, and what they claim by construction holds."""

from __future__ import annotations

import dataclasses
import re
import sys
from pathlib import Path

import pytest

import dnnevo

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples"))

import incremental_plateau  # noqa: E402
import nav1d_transfer  # noqa: E402
import trigger_answers  # noqa: E402
import cartpole_memory  # noqa: E402
import double_pole  # noqa: E402
import categorical_perception  # noqa: E402
import legged_walker  # noqa: E402
import pendulum  # noqa: E402


def test_incremental_plateau(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A composite with zero cross weights answers as its 1-bit part on every trial."""
    alternating = tmp_path / "alt.json"
    dnnevo.Network.random(5, 2, seed=4).save(alternating)
    one_bit = ROOT / "tests" / "data" / "sequence-1bit-seed0-champion.json"
    incremental_plateau.main([str(one_bit), str(alternating), "--trials", "3", "--timings", "3"])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "composite output identical to the 1-bit part's on 12 of 12 trials"
    assert len(lines) == 2 + 7 and lines[2].startswith("composite, cross weights 0")
    assert lines[-1].startswith("relay: w[0][5] = -16, theta[0] = -8")


def test_trigger_answers(capsys: pytest.CaptureFixture[str]) -> None:
    """The 1-bit champion, trial by trial: 0s for 0*, and 1s for 1* once it has switched."""
    one_bit = ROOT / "tests" / "data" / "sequence-1bit-seed0-champion.json"
    trigger_answers.main([str(one_bit), "--preset", "sequence-1bit", "--trials", "2"])
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(":")[0] for line in lines] == ["  0* trial 0", "  0* trial 1", "  1* trial 0",
                                                      "  1* trial 1"]
    for line in lines:
        wanted, answered, correct = (line.split(word + " ")[1].split()[0]
                                     for word in ("wanted", "answered", "correct"))
        assert len(wanted) == len(answered) == len(correct) >= 8
        assert correct.endswith("++++") and answered.endswith(wanted[-4:])


def test_nav1d_transfer(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """One row per run; its first cell is the champion's rate in its own world, as
    dnnevo.tasks.nav1d.assess gives it, and the other cells judge changed worlds."""
    from cli_helpers import run_cli

    from dnnevo.tasks import nav1d

    run = tmp_path / "single"
    r = run_cli("run", "nav1d-single", "--quick", "--set", "generations=2", "--out", run, "--seed", "3")
    assert r.returncode == 0, r.stderr
    nav1d_transfer.main([str(run), "--chains", "6", "--seed", "11"])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "| run | " + " | ".join(nav1d_transfer.VARIANTS) + " |" and len(lines) == 3
    cells = lines[2].strip("| ").split(" | ")[1:]
    assert len(cells) == len(nav1d_transfer.VARIANTS)
    part = nav1d.load_part(run)
    own = nav1d.assess(part.config, part.network, 6, 11)
    assert cells[0] == f"{100 * own['rate']:.1f}%" + ("" if own["success"] else " (fail)")
    longer = nav1d.assess(dataclasses.replace(part.config, task_params={**part.config.task_params,
                                                                        "trials_per_environment": 10}),
                          part.network, 6, 11)
    assert cells[1] == f"{100 * longer['rate']:.1f}%" + ("" if longer["success"] else " (fail)")


def test_cartpole_memory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A row per seed, a solved count per kind, and the figure; the reactive networks are
    reactive (their recurrent weights are zero to 1e-9)."""
    from cli_helpers import assert_png

    cartpole_memory.main(["--seeds", "1", "--population", "20", "--generations", "2",
                          "--episodes", "5", "--out", str(tmp_path / "m.png")])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "| seed | CTRNN fresh mean return | reactive fresh mean return |"
    assert lines[2].startswith("| 0 | ") and lines[-1].startswith("reactive: ")
    assert_png(tmp_path / "m.png")
    config = dnnevo.EvolutionConfig(size=5, n_inputs=2, ranges=cartpole_memory.REACTIVE)
    net = dnnevo.GeneticAlgorithm(config, seed=0).ask().networks[0]
    assert abs(net.weights).max() <= 1e-9



def test_double_pole(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A row per seed, the solved count with its interval, and the figure."""
    from cli_helpers import assert_png

    from dnnevo.experiments import examples

    double_pole.main(["--seeds", "2", "--set", "population=10", "--budget", "120", "--workers", "2",
                      "--out", str(tmp_path / "d.png"), "--record", str(tmp_path / "d.json")])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:3] == ["seed", "episodes", "generations"] and len(lines) == 4
    assert lines[1].split()[:3] == ["0", ">120", "-"] and lines[2].split()[0] == "1"
    assert lines[-1].startswith("solved 0 of 2 seeds within 120 episodes (95% interval 0%-")
    recorded = examples.read(tmp_path / "d.json")
    assert recorded["command"] == ("python examples/double_pole.py --seeds 2 --set population=10 --budget 120 "
                                   f"--workers 2 --out {tmp_path / 'd.png'}")
    assert recorded["rows"][0][:3] == ["0", "not within 120", "-"] and recorded["summary"] == [lines[-1]]
    assert_png(tmp_path / "d.png")


def test_categorical_perception(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A row per seed with both steps' counts and intervals, the summary, and the figure."""
    from cli_helpers import assert_png

    categorical_perception.main(["--seeds", "2", "--population", "6", "--generations", "1",
                                 "--episodes", "2", "--out", str(tmp_path / "c.png")])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("seed  correct at dt 0.1") and len(lines) == 5
    assert [line.split()[0] for line in lines[1:3]] == ["0", "1"]
    assert "/202 (" in lines[1]
    assert re.fullmatch(r"[0-2] of 2 seeds classify at least 90% of the grid correctly at both "
                        r"steps \(95% interval \d+%-\d+%\)", lines[3])
    assert re.fullmatch(r"median correct at dt 0.1: \d+ of 202", lines[4])
    assert_png(tmp_path / "c.png")


def test_categorical_perception_refuses_an_odd_episode_count(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        categorical_perception.main(["--episodes", "3"])
    assert "--episodes is 3; it must be an even number >= 2" in capsys.readouterr().err


def test_legged_walker(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The optimum, a row per seed with its verdict, the summary, and the figure."""
    from cli_helpers import assert_png

    legged_walker.main(["--seeds", "2", "--population", "6", "--generations", "1",
                        "--episodes", "1", "--out", str(tmp_path / "w.png")])
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "optimal controller: 0.6264; walking: at least 0.3132"
    assert lines[1].startswith("seed  velocity  walks") and len(lines) == 6
    assert [line.split()[0] for line in lines[2:4]] == ["0", "1"]
    assert all(line.endswith(("does not walk", "central", "needs its sensor")) for line in lines[2:4])
    assert re.fullmatch(r"[0-2] of 2 seeds walk in at least 90% of fresh starts \(95% interval "
                        r"\d+%-\d+%\); [0-2] of them walk with the sensor cut", lines[4])
    assert_png(tmp_path / "w.png")


def test_pendulum(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The torque-0 baseline, a row per seed with its interval and upright count, the figure."""
    from cli_helpers import assert_png

    pendulum.main(["--seeds", "1", "--population", "6", "--generations", "1", "--episodes", "1",
                   "--out", str(tmp_path / "p.png")])
    lines = capsys.readouterr().out.splitlines()
    assert re.fullmatch(r"torque 0 throughout: fresh mean return -\d+\.\d", lines[0])
    assert re.fullmatch(r"\s+0\s+-?\d+\.\d \(\s*-?\d+\.\d to\s+-?\d+\.\d\)\s+\d+/100 "
                        r"\(\d+%-\d+%\)\s+\d+", lines[2])
    assert lines[3].startswith("median of the seeds' fresh mean returns: ")
    assert_png(tmp_path / "p.png")


def test_legged_walker_without_its_sensor(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Evolved without the sensor, a walker that walks is central by construction, and the
    figure draws its one gait."""
    from cli_helpers import assert_png

    legged_walker.main(["--seeds", "1", "--population", "6", "--generations", "1",
                        "--episodes", "1", "--no-sensor", "--out", str(tmp_path / "w.png")])
    row = capsys.readouterr().out.splitlines()[2]
    assert row.endswith(("does not walk", "central"))
    assert_png(tmp_path / "w.png")
