"""The example scripts run, and what they claim by construction holds."""

from __future__ import annotations

import dataclasses
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import dnnevo

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples"))

import incremental_plateau  # noqa: E402
import nav1d_parents  # noqa: E402
import nav1d_transfer  # noqa: E402
import trigger_answers  # noqa: E402
import cartpole_memory  # noqa: E402
import double_pole  # noqa: E402
import categorical_perception  # noqa: E402
import legged_walker  # noqa: E402
import pendulum  # noqa: E402
import predator_avoidance  # noqa: E402


def assert_rendered(tmp_path: Path, name: str, script: str, argv: list[str], summary: list[str]) -> None:
    """The record an example wrote with ``--record`` renders into a page's markers: its command
    (``argv`` without the ``--record``), its table and the ``summary`` lines it printed; and the
    page, once rendered, is not stale."""
    from dnnevo.experiments import examples, results

    recorded = examples.read(tmp_path / "results" / "examples" / f"{name}.json")
    given = argv[:argv.index("--record")] + argv[argv.index("--record") + 2:]
    assert recorded["command"] == examples.command(script, given) == " ".join(["python", script, *given])
    assert recorded["summary"][-len(summary):] == summary
    page = tmp_path / "page.md"
    page.write_text(f"<!-- results:example:{name}:begin -->\nold\n<!-- results:example:{name}:end -->\n")
    assert results.render(tmp_path, results_dir=tmp_path / "results", files=[page]) == [page]
    text = page.read_text()
    assert f"`{recorded['command']}`:" in text and "old" not in text
    assert "| " + " | ".join(recorded["columns"]) + " |" in text
    assert all("| " + " | ".join(row) + " |" in text for row in recorded["rows"])
    assert all(f"\n{line}\n" in text for line in summary)
    assert results.render(tmp_path, results_dir=tmp_path / "results", files=[page], check=True) == []


def test_a_records_command_leaves_out_where_it_was_written() -> None:
    from dnnevo.experiments import examples

    for given in (["--record", "r.json"], ["--record=r.json"], ["--rec", "r.json"]):
        assert examples.command("examples/x.py", ["--seeds", "2", *given, "--out", "f.png"]) == \
            "python examples/x.py --seeds 2 --out f.png"
    assert examples.command("examples/x.py", ["--out", "my figure.png"]) == "python examples/x.py --out 'my figure.png'"


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


def test_nav1d_parents(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """One row per near seeker, under its own seed; the founder is the first network of the
    founded run's first population, scored as evaluation scores it."""
    from cli_helpers import run_cli

    from dnnevo.evolution.seeding import Seeding

    run = tmp_path / "near"
    r = run_cli("run", "nav1d-near", "--quick", "--set", "task_params.chained=true", "--set",
                "task_params.reinforcement_input=true", "--set", "n_inputs=2", "--set", "generations=2",
                "--out", run, "--seed", "5")
    assert r.returncode == 0, r.stderr
    nav1d_parents.main([str(run)])
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 3 and lines[0].startswith("| seed | founder |")
    cells = lines[2].strip("| ").split(" | ")
    assert cells[0] == "5" and all(0.0 <= float(c) <= 2.0 for c in cells[1:])
    cfg = dnnevo.presets.get(nav1d_parents.PRESET)
    founder = Seeding((run,), False, 0.0, nav1d_parents.SPARE).networks(cfg.size, 5)[0]
    score = dnnevo.evaluate(cfg.task, [founder], generation=0, seed=5, config=cfg)[0]
    assert cells[1] == f"{score:.3f}"


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

    argv = ["--seeds", "1", "--population", "20", "--generations", "2", "--episodes", "5",
            "--out", str(tmp_path / "m.png"), "--record", str(tmp_path / "results/examples/m.json")]
    cartpole_memory.main(argv)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "| seed | CTRNN fresh mean return | reactive fresh mean return |"
    assert lines[2].startswith("| 0 | ") and re.match(r"CTRNN: [01] of 1 seeds solved", lines[-2])
    assert re.fullmatch(r"reactive: [01] of 1 seeds solved \(95% interval \d+%-\d+%\); fresh mean "
                        r"returns from (\d+\.\d) to \1", lines[-1])
    assert_png(tmp_path / "m.png")
    assert_rendered(tmp_path, "m", "examples/cartpole_memory.py", argv, lines[-2:])
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

    argv = ["--seeds", "2", "--population", "6", "--generations", "1", "--episodes", "2",
            "--out", str(tmp_path / "c.png"), "--record", str(tmp_path / "results/examples/c.json")]
    categorical_perception.main(argv)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("seed  correct at dt 0.1") and len(lines) == 8
    assert [line.split()[0] for line in lines[1:3]] == ["0", "1"]
    assert "/202 (" in lines[1]
    assert re.fullmatch(r"[0-2] of 2 seeds classify at least 90% of the grid correctly at both "
                        r"steps \(95% interval \d+%-\d+%\)", lines[3])
    assert re.fullmatch(r"median correct at dt 0.1: \d+ of 202", lines[4])
    counts = [[int(c.split("/")[0]) for c in line.split()[1:4:2]] for line in lines[1:3]]
    assert lines[5] == f"largest difference between the two steps: {max(abs(a - b) for a, b in counts)} falls " \
                       f"(seed {max((0, 1), key=lambda s: abs(counts[s][0] - counts[s][1]))})"
    assert re.fullmatch(r"Beer's performance: 0\.\d{3} to 0\.\d{3}", lines[6])
    assert re.fullmatch(r"best seed at both steps \(the figure draws its paths\): [01]", lines[7])
    assert_png(tmp_path / "c.png")
    assert_rendered(tmp_path, "c", "examples/categorical_perception.py", argv, lines[3:])


def test_categorical_perception_refuses_an_odd_episode_count(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        categorical_perception.main(["--episodes", "3"])
    assert "--episodes is 3; it must be an even number >= 2" in capsys.readouterr().err


def test_legged_walker(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The optimum, a row per seed with its verdict, the summary, and the figure."""
    from cli_helpers import assert_png

    from dnnevo.experiments import examples

    argv = ["--seeds", "2", "--population", "6", "--generations", "1", "--episodes", "1",
            "--out", str(tmp_path / "w.png"), "--record", str(tmp_path / "results/examples/w.json")]
    legged_walker.main(argv)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "optimal controller: 0.6264; walking: at least 0.3132"
    assert lines[1].startswith("seed  velocity  walks") and len(lines) == 10
    assert [line.split()[0] for line in lines[2:4]] == ["0", "1"]
    assert all(line.endswith(("does not walk", "central", "needs its sensor")) for line in lines[2:4])
    assert re.fullmatch(r"[0-2] of 2 seeds walk in at least 90% of fresh starts \(95% interval "
                        r"\d+%-\d+%\); [0-2] of them walk with the sensor cut", lines[4])
    velocities = sorted(line.split()[1] for line in lines[2:4])
    assert lines[6].startswith(f"velocities from {velocities[0]} to {velocities[1]} (")
    assert lines[7].startswith("with the sensor cut: velocities from ")
    assert re.fullmatch(r"[0-2] of 2 networks oscillate with their input at 0( \(periods .*\))?", lines[8])
    assert lines[9].startswith("at dt 0.05: velocities change by at most ")
    assert_png(tmp_path / "w.png")
    assert_rendered(tmp_path, "w", "examples/legged_walker.py", argv, lines[4:])
    recorded = examples.read(tmp_path / "results/examples/w.json")
    assert recorded["summary"][0] == "optimal controller: 0.6264" and len(recorded["columns"]) == 9


def test_pendulum(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The torque-0 baseline, a row per seed with its interval and upright count, how many seeds
    solve it, the figure."""
    from cli_helpers import assert_png

    argv = ["--seeds", "1", "--population", "6", "--generations", "1", "--episodes", "1",
            "--out", str(tmp_path / "p.png"), "--record", str(tmp_path / "results/examples/p.json")]
    pendulum.main(argv)
    lines = capsys.readouterr().out.splitlines()
    assert re.fullmatch(r"torque 0 throughout: fresh mean return -\d+\.\d", lines[0])
    row = re.fullmatch(r"\s+0\s+(-?\d+\.\d) \(\s*-?\d+\.\d to\s+-?\d+\.\d\)\s+(\d+)/100 "
                       r"\(\d+%-\d+%\)\s+\d+", lines[2])
    assert row is not None and len(lines) == 7
    assert lines[3] == f"median of the seeds' fresh mean returns: {row[1]}"
    idle = lines[0].split()[-1]
    assert lines[4] == (f"{int(float(row[1]) > float(idle))} of 1 champions have a higher fresh mean return "
                        f"than torque 0 throughout ({idle})")
    assert lines[5] == f"fresh episodes that end within 10 degrees of upright: {row[2]} to {row[2]} of 100, by seed"
    solved = float(row[1]) > -200 and int(row[2]) >= 95
    assert lines[6] == (f"{int(solved)} of 1 champions solve it (fresh mean return above -200 and at least "
                        "95 of 100 episodes ending upright)")
    assert_png(tmp_path / "p.png")
    assert_rendered(tmp_path, "p", "examples/pendulum.py", argv, lines[3:])


def test_pendulum_equations_are_gymnasiums() -> None:
    """Evolution runs Pendulum-v1's equations in NumPy; on the same seeds they give every return
    of Gymnasium's own environment bit for bit."""
    import numpy as np

    from dnnevo.closedloop import rollout

    nets = [dnnevo.Network.random(5, 3, seed=s) for s in range(6)]
    gym_run, numpy_run = (rollout(nets, env, episodes=4, max_steps=pendulum.STEPS, substeps=2, seed=5)
                          for env in (pendulum.Pendulum(), pendulum.PendulumEquations()))
    assert np.array_equal(gym_run.returns, numpy_run.returns)
    assert np.array_equal(gym_run.lengths, numpy_run.lengths)


def test_legged_walker_without_its_sensor(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Evolved without the sensor, a walker that walks is central by construction, and the
    figure draws its one gait."""
    from cli_helpers import assert_png

    from dnnevo.experiments import examples

    legged_walker.main(["--seeds", "1", "--population", "6", "--generations", "1", "--episodes", "1",
                        "--no-sensor", "--out", str(tmp_path / "w.png"), "--record", str(tmp_path / "w.json")])
    lines = capsys.readouterr().out.splitlines()
    assert lines[2].endswith(("does not walk", "central"))
    assert re.fullmatch(r"[01] of 1 seeds walk in at least 90% of fresh starts \(95% interval \d+%-\d+%\)",
                        lines[3])
    assert not any(line.startswith("with the sensor cut") for line in lines)
    assert_png(tmp_path / "w.png")
    recorded = examples.read(tmp_path / "w.json")
    assert "sensor cut" not in recorded["columns"] and len(recorded["rows"][0]) == 7


def test_predator_avoidance_ablation_judges_saved_champions(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--ablation evolves nothing: it loads a saved champion, judges it and the baselines in each
    world of the ablation, and records one row per world."""
    from dnnevo import presets

    nets = tmp_path / "nets"
    nets.mkdir()
    cfg = presets.get("predator-avoidance")
    dnnevo.Network.random(cfg.size, cfg.n_inputs, seed=3).save(nets / "seed-0.json")
    record = tmp_path / "results" / "examples" / "predator-avoidance-ablation.json"
    argv = ["--ablation", str(nets), "--seeds", "1", "--fresh", "4", "--random", "1",
            "--set", "task_params.max_steps=40", "--record", str(record)]
    predator_avoidance.main(argv)
    lines = capsys.readouterr().out.splitlines()
    worlds = list(predator_avoidance.ablation_worlds(cfg))
    assert lines[0].split("  ") == ["seed", *worlds] and lines[1].split()[0] == "0"
    assert all(re.fullmatch(r"[0-4]/4", cell) for cell in lines[1].split()[1:])
    summary = lines[-2:]
    assert summary[0].startswith("pooled escapes the champions gain (+) or lose (-) against the training world's")
    assert_rendered(tmp_path, "predator-avoidance-ablation", "examples/predator_avoidance.py", argv, summary)
    from dnnevo.experiments import examples

    rows = examples.read(record)["rows"]
    assert [row[0] for row in rows] == worlds and all(re.fullmatch(r"[0-4]", row[3]) for row in rows)
    assert all(row[5].startswith(("0/4 ", "1/4 ", "2/4 ", "3/4 ", "4/4 ")) for row in rows)  # 1 random network
    with pytest.raises(SystemExit):  # a champion missing is named before anything runs
        predator_avoidance.main(["--ablation", str(nets), "--seeds", "2"])
    assert "has no seed-1.json" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        predator_avoidance.main(["--ablation", str(nets), "--seeds", "1", "--figure", str(tmp_path / "x.png")])
    assert not (tmp_path / "x.png").exists()


@pytest.mark.skipif(shutil.which("cargo") is None or not (ROOT / "crates").is_dir(),
                    reason="the Rust example needs cargo and the source tree")
def test_the_rust_example_evolves_saves_loads_and_analyses_its_own_task() -> None:
    """crates/ctrnn/examples/own_task.rs, which docs/rust.md shows, runs: its own Task evolves
    (a fixed seed, so the figures are fixed), the champion goes through a file and back, and
    its equilibria are found."""
    r = subprocess.run(["cargo", "run", "-q", "-p", "ctrnn", "--example", "own_task"], cwd=ROOT,
                       capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, r.stderr
    best = [float(b) for b in re.findall(r"best ([0-9.]+)", r.stdout)]
    assert len(best) == 4 and best[-1] > 5 * best[0], r.stdout
    assert "champion swing from rest" in r.stdout and "equilibrium at rates" in r.stdout, r.stdout
