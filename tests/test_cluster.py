"""Clusters that fail: a worker that runs another dnnevo is refused, and a cluster lost in the
middle of a sweep ends the command in one line, leaving runs that the same command continues to
the results of a sweep that never stopped."""

from __future__ import annotations

import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from cli_helpers import assert_one_line_error, run_cli

from dnnevo.errors import ConfigError, DnnevoError
from dnnevo.experiments import scheduler
from dnnevo.experiments.runsview import RunsView

pytest.importorskip("distributed")

SWEEP = ["sweep", "sequence-1bit", "--quick", "--set", "population=12", "--set", "generations=120",
         "--eval-trials", "5", "--no-dt-check"]


def test_a_worker_that_runs_another_dnnevo_is_refused_in_one_line() -> None:
    with scheduler.dask_client(workers=1, scheduler=None) as client:  # the same dnnevo: accepted
        other = {**scheduler.identity(), "commit": "0123456789ab"}
        with pytest.raises(ConfigError) as refused:
            scheduler.check_workers(client, other)
    message = str(refused.value)
    assert "runs dnnevo" in message and "its results could differ" in message
    assert scheduler.identity()["commit"] in message and "\n" not in message


def test_a_task_on_a_worker_that_runs_another_dnnevo_refuses_to_run() -> None:
    """A worker that joined after the cluster was checked is held to the same dnnevo."""
    other = {**scheduler.identity(), "version": "0.0.0"}
    with pytest.raises(ConfigError, match="this Dask worker runs dnnevo .* the command dnnevo 0.0.0"):
        scheduler._checked_call(other, abs, (-1,), {})
    assert scheduler._checked_call(scheduler.identity(), abs, (-1,), {}) == 1


def test_waiting_on_a_lost_cluster_is_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    from distributed.comm.core import CommClosedError

    class Lost:
        @staticmethod
        def as_completed(futures: list[Any]) -> Any:
            raise CommClosedError("in <TCP (closed)>: Stream is closed")

    class Client:
        def submit(self, *args: Any, key: str, **kwargs: Any) -> Any:
            return type("Future", (), {"key": key})()

    monkeypatch.setattr(scheduler, "_distributed", lambda: Lost)
    tasks = [scheduler.Task("a", (), abs, (-1,)), scheduler.Task("b", (), abs, (-2,))]
    with pytest.raises(DnnevoError, match=r"lost the Dask cluster after 0 of 2 tasks \(CommClosedError: "
                                          r".*run the same command again to continue"):
        scheduler.run_on_dask(tasks, RunsView(2, stream=io.StringIO()), Client())


def _start(command: list[str], cwd: Path) -> subprocess.Popen[bytes]:
    return subprocess.Popen(command, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)


def _cluster(folder: Path) -> tuple[subprocess.Popen[bytes], subprocess.Popen[bytes], str]:
    """A scheduler and one worker of one thread, in processes of their own; its address."""
    dask = str(Path(sys.executable).parent / "dask")
    file = folder / "scheduler.json"
    file.unlink(missing_ok=True)
    boss = _start([dask, "scheduler", "--port", "0", "--no-dashboard", "--scheduler-file", str(file)], folder)
    for _ in range(300):
        if file.exists() and file.stat().st_size:
            break
        time.sleep(0.1)
    address = json.loads(file.read_text())["address"]
    worker = _start([dask, "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard"], folder)
    return boss, worker, address


def _stop(*processes: subprocess.Popen[bytes]) -> None:
    for p in processes:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
        p.wait()


@pytest.mark.slow
def test_a_sweep_whose_scheduler_dies_ends_in_one_line_and_continues_to_the_same_results(tmp_path: Path) -> None:
    here = run_cli(*SWEEP, "--seeds", "0-2", "--out", tmp_path / "here")
    assert here.returncode == 0, here.stderr
    out = tmp_path / "there"
    boss, worker, address = _cluster(tmp_path)
    try:
        sweep = subprocess.Popen([sys.executable, "-m", "dnnevo", *SWEEP, "--seeds", "0-2", "--out", str(out),
                                  "--scheduler", address], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True)
        # The scheduler dies once the first seed has written its first checkpoint.
        for _ in range(600):
            if list(out.glob("seed-*/checkpoint.json")) or sweep.poll() is not None:
                break
            time.sleep(0.05)
        assert sweep.poll() is None, "the sweep ended before its scheduler could be stopped"
        _stop(boss)
        stdout, stderr = sweep.communicate(timeout=120)
    finally:
        _stop(boss, worker)
    lost = subprocess.CompletedProcess(sweep.args, sweep.returncode, stdout, stderr)
    assert_one_line_error(lost, "lost the Dask cluster", "run the same command again to continue")
    boss, worker, address = _cluster(tmp_path)
    try:
        again = run_cli(*SWEEP, "--seeds", "0-2", "--out", out, "--scheduler", address)
    finally:
        _stop(boss, worker)
    assert again.returncode == 0, again.stderr

    def runs(folder: Path) -> list[dict[str, Any]]:
        summary = json.loads((folder / "summary.json").read_text())
        return [{k: v for k, v in r.items() if k != "wall_s"} for r in summary["runs"]]

    assert runs(out) == runs(tmp_path / "here")
    for seed in range(3):
        best = f"seed-{seed}/best.json"
        assert (out / best).read_bytes() == (tmp_path / "here" / best).read_bytes()


def test_a_second_reproduce_on_the_same_folder_is_refused_and_changes_nothing(tmp_path: Path) -> None:
    from dnnevo.runs.rundir import RunDir

    out = tmp_path / "reproduction"
    with RunDir(out).writing(create=True):  # another dnnevo reproduce holds the folder
        before = sorted((p.name, p.read_bytes()) for p in out.iterdir())
        r = run_cli("reproduce", "--quick", "--seeds", "0", "--only", "nav1d", "--out", out)
        assert sorted((p.name, p.read_bytes()) for p in out.iterdir()) == before
    assert_one_line_error(r, "is in use by another dnnevo process", f"PID {os.getpid()}")
