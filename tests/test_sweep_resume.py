"""``dnnevo sweep`` run again on its folder continues the sweep, with the same results as a sweep
that was never stopped, and refuses other settings; on a local Dask cluster too."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from cli_helpers import assert_one_line_error, run_cli

import dnnevo
from dnnevo import presets

OVERRIDES = ["population=12", "generations=8"]
ARGS = ["sequence-1bit", "--quick", *(a for o in OVERRIDES for a in ("--set", o)),
        "--eval-trials", "5", "--no-dt-check"]


def sweep(out: Path, seeds: str) -> str:
    r = run_cli("sweep", *ARGS, "--seeds", seeds, "--out", out)
    assert r.returncode == 0, r.stderr
    return r.stdout


def results(out: Path) -> list[dict[str, Any]]:
    """summary.json's seeds without their wall times, which differ from run to run."""
    runs = json.loads((out / "summary.json").read_text())["runs"]
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in runs]


def log_without_times(run: Path) -> list[list[str]]:
    """log.csv without its speed and wall-time columns, which differ from run to run."""
    rows = [line.split(",") for line in (run / "log.csv").read_text().splitlines()]
    keep = [i for i, name in enumerate(rows[0]) if name not in ("evals_per_s", "elapsed_s")]
    return [[row[i] for i in keep] for row in rows]


def test_a_stopped_sweep_continues_to_the_same_results(tmp_path: Path) -> None:
    whole = tmp_path / "whole"
    sweep(whole, "0-2")
    # A sweep stopped during seed 1: seed 0 finished, seed 1 at generation 3 of 8, seed 2 not begun.
    parts = tmp_path / "parts"
    sweep(parts, "0")
    config = presets.get("sequence-1bit", quick=True, overrides=OVERRIDES)
    dnnevo.evolve(config.task, config, seed=1, out=parts / "seed-1", progress=False,
                  callback=lambda stats, ga: ga.generation >= 3)
    assert len(dnnevo.runs.rundir.RunDir(parts / "seed-1").read_checkpoint().history) == 3
    # show on the folder of the stopped sweep: the statistics of its one finished seed.
    shown = run_cli("show", parts)
    assert shown.returncode == 0 and "a sweep of sequence-1bit, 1 finished seed (summary.json" in shown.stdout
    assert "final champions passing on fresh trials:" in shown.stdout, shown.stdout
    printed = sweep(parts, "0-2")
    # The statistics it prints are those show makes again from summary.json.
    shown = run_cli("show", parts).stdout.splitlines()
    assert shown[0].startswith(f"{parts}: a sweep of sequence-1bit, 3 finished seeds")
    assert all(line in printed.splitlines() for line in shown[1:] if "wall" not in line and "   " not in line)
    assert "seed 0: finished; judging its champion again" in printed
    assert "seed 1: resuming at generation 3" in printed
    assert results(parts) == results(whole)
    for seed in range(3):
        best = f"seed-{seed}/best.json"
        assert (parts / best).read_bytes() == (whole / best).read_bytes()
    (parts / "summary.json").write_text('{"runs": [}')
    assert_one_line_error(run_cli("show", parts), "summary.json")


def test_more_generations_extend_a_sweep_to_the_results_of_a_longer_one(tmp_path: Path) -> None:
    longer = tmp_path / "longer"
    assert run_cli("sweep", *ARGS, "--set", "generations=12", "--seeds", "0-1", "--out", longer).returncode == 0
    extended = tmp_path / "extended"
    sweep(extended, "0-1")
    r = run_cli("sweep", *ARGS, "--set", "generations=12", "--seeds", "0-2", "--out", extended)
    assert r.returncode == 0, r.stderr
    assert "extending the sweep from 8 to 12 generations" in r.stdout
    assert "seed 1: resuming at generation 8" in r.stdout
    assert "seed 2: never met the rule; final champion fail" in r.stdout  # as soon as it is judged
    assert json.loads((extended / "sweep.json").read_text())["config"]["generations"] == 12
    assert run_cli("sweep", *ARGS, "--set", "generations=12", "--seeds", "0-2", "--out", longer).returncode == 0
    assert results(extended) == results(longer)
    for seed in range(3):
        path = f"seed-{seed}/best.json"
        assert (extended / path).read_bytes() == (longer / path).read_bytes(), path
        assert log_without_times(extended / f"seed-{seed}") == log_without_times(longer / f"seed-{seed}")
    # Fewer generations than the sweep's, or more with another change, are refused as before.
    r = run_cli("sweep", *ARGS, "--set", "generations=10", "--seeds", "0", "--out", extended)
    assert_one_line_error(r, "holds a sweep with config.generations = 12, not 10")
    r = run_cli("sweep", *ARGS, "--set", "generations=20", "--set", "elitism=2", "--seeds", "0", "--out", extended)
    assert_one_line_error(r, "holds a sweep with config.generations = 12, not 20")


def test_other_settings_are_refused_in_one_line(tmp_path: Path) -> None:
    out = tmp_path / "s"
    sweep(out, "0")
    r = run_cli("sweep", *ARGS, "--set", "elitism=2", "--seeds", "0", "--out", out)
    assert_one_line_error(r, "holds a sweep with config.elitism = 0, not 2")
    (out / "sweep.json").write_text("{not json")
    assert_one_line_error(run_cli("sweep", *ARGS, "--seeds", "0", "--out", out), "sweep.json: unreadable")
    # --force starts afresh whatever the folder held.
    assert run_cli("sweep", *ARGS, "--set", "elitism=2", "--seeds", "0", "--out", out, "--force").returncode == 0
    assert json.loads((out / "sweep.json").read_text())["config"]["elitism"] == 2


def test_a_sweep_recorded_before_a_later_setting_continues(tmp_path: Path) -> None:
    """A sweep.json written before ``champion_step_check`` existed reads as having its default:
    the sweep continues and is extended; turning the setting on is refused like any change."""
    out = tmp_path / "s"
    sweep(out, "0")
    manifest = out / "sweep.json"
    recorded = json.loads(manifest.read_text())
    del recorded["config"]["champion_step_check"]
    manifest.write_text(json.dumps(recorded))
    assert "seed 0: finished" in sweep(out, "0")
    r = run_cli("sweep", *ARGS, "--set", "champion_step_check=true", "--seeds", "0", "--out", out)
    assert_one_line_error(r, "holds a sweep with config.champion_step_check = False, not True")
    r = run_cli("sweep", *ARGS, "--set", "generations=10", "--seeds", "0", "--out", out)
    assert r.returncode == 0 and "extending the sweep from 8 to 10 generations" in r.stdout, r.stderr


def test_a_sweep_on_a_local_dask_cluster_gives_the_same_results(tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    here, there = tmp_path / "here", tmp_path / "there"
    sweep(here, "0-3")
    # Seeds 0-1 stopped in process, then continued on two workers with two more seeds.
    sweep(there, "0-1")
    r = run_cli("sweep", *ARGS, "--seeds", "0-3", "--out", there, "--workers", "2")
    assert r.returncode == 0, r.stderr
    assert "a local Dask cluster of 2 workers" in r.stdout
    assert "seed 0: finished; judging its champion again" in r.stdout
    assert results(there) == results(here)
    for seed in range(4):
        best = f"seed-{seed}/best.json"
        assert (there / best).read_bytes() == (here / best).read_bytes()


def test_a_seed_that_fails_on_dask_is_named_and_the_exit_status_says_so(tmp_path: Path) -> None:
    pytest.importorskip("distributed")
    out = tmp_path / "s"
    sweep(out, "0-1")
    (out / "seed-1" / "config.toml").write_text("population = 'many'\n")
    r = run_cli("sweep", *ARGS, "--seeds", "0-1", "--out", out, "--workers", "1")
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert "dnnevo: seed-1 failed:" in r.stderr and "Traceback" not in r.stderr
    assert "1 seed(s) failed" in r.stdout
    assert [run["seed"] for run in results(out)] == [0]


@pytest.mark.slow
def test_a_sweep_stopped_by_ctrl_c_leaves_the_stopped_seed_out_and_exits_130(tmp_path: Path) -> None:
    import signal
    import subprocess
    import sys
    import time

    # Ctrl-C's default handler (a test's background process may start with SIGINT ignored) and a
    # checkpoint every generation, so the stop lands inside seed 1.
    launcher = ("import signal, sys, dnnevo; signal.signal(signal.SIGINT, signal.default_int_handler); "
                "sys.modules['dnnevo.evolution.evolve'].CHECKPOINT_SECONDS = 0.0; "
                "from dnnevo.cli.command import main; sys.exit(main(sys.argv[1:]))")
    out = tmp_path / "s"
    args = ["sweep", "sequence-1bit", "--quick", "--set", "population=12", "--set", "generations=400",
            "--eval-trials", "5", "--no-dt-check", "--threads", "1", "--seeds", "0-2", "--out", str(out)]
    proc = subprocess.Popen([sys.executable, "-c", launcher, *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    checkpoint = out / "seed-1" / "checkpoint.json"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not checkpoint.exists():
        time.sleep(0.02)
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130, (stdout, stderr)
    assert "interrupted during seed 1, which the statistics leave out" in stdout, stdout
    assert "cover the 1 finished seed(s)" in stdout and "Traceback" not in stderr
    assert [r["seed"] for r in json.loads((out / "summary.json").read_text())["runs"]] == [0]
    assert [row.split(",")[0] for row in (out / "summary.csv").read_text().splitlines()] == ["seed", "0", "all"]
