"""A write that fails (a full disk, a file-size limit, a read-only folder) stops a command in one
line naming the file, keeps what the file held, and leaves a run that resumes to the same end."""

from __future__ import annotations

import errno
import json
import os
import resource
import subprocess
import sys
from pathlib import Path

import pytest
from cli_helpers import run_cli

from dnnevo.cli.command import main
from dnnevo.errors import WriteError
from dnnevo.runs import files as files_module
from dnnevo.runs import rundir as rundir_module
from dnnevo.runs.files import write_atomic, write_error

QUICK = ("sequence-1bit", "--quick", "--seed", "2")


def run_limited(limit: int, *args: object) -> subprocess.CompletedProcess[str]:
    """``python -m dnnevo ARGS`` with every file it writes limited to ``limit`` bytes (Python
    ignores SIGXFSZ, so a write past the limit fails with EFBIG)."""

    def limit_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return subprocess.run([sys.executable, "-m", "dnnevo", *map(str, args)], capture_output=True,
                          text=True, timeout=300, preexec_fn=limit_files)


def history(run: Path) -> list[dict[str, float]]:
    rows = json.loads((run / "checkpoint.json").read_text())["history"]
    for row in rows:
        row.pop("elapsed_s"), row.pop("evals_per_s")
    return rows


def test_a_file_size_limit_stops_a_run_in_one_line_and_it_resumes_to_the_same_end(tmp_path: Path) -> None:
    whole, run = tmp_path / "whole", tmp_path / "run"
    assert run_cli("run", *QUICK, "--set", "generations=12", "--out", whole).returncode == 0
    assert run_cli("run", *QUICK, "--set", "generations=3", "--out", run).returncode == 0
    before = (run / "checkpoint.json").read_bytes()
    # The next checkpoint holds more history than this limit allows.
    r = run_limited(len(before) + 64, "resume", run, "--generations", "12")
    # The progress bar's last line, then the error's one line.
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert r.stderr.strip().splitlines()[-1] == (
        f"dnnevo: error: {run / 'checkpoint.json'} could not be written: it would pass the "
        "file-size limit (ulimit -f); what it held before is kept")
    # The checkpoint is whole: the one before the failed write (the run may have written one
    # that fitted on its way).
    kept = history(run)
    assert 3 <= len(kept) < 12 and kept == history(whole)[:len(kept)]
    assert not list(run.glob(".*.tmp*")), "no temporary file is left behind"
    assert run_cli("resume", run, "--generations", "12").returncode == 0
    assert history(run) == history(whole)
    assert (run / "best.json").read_text() == (whole / "best.json").read_text()


@pytest.mark.parametrize("code, why", [
    (errno.ENOSPC, "no space is left on the device"),
    (errno.EROFS, "the file system is read-only"),
    (errno.EACCES, "permission denied: the folder is read-only to this user"),
    (errno.EIO, "Input/output error"),
])
def test_each_failure_is_named(tmp_path: Path, code: int, why: str) -> None:
    error = write_error(tmp_path / "log.csv", OSError(code, os.strerror(code)))
    assert isinstance(error, WriteError) and isinstance(error, OSError)
    assert str(error) == f"{tmp_path / 'log.csv'} could not be written: {why}; what it held before is kept"


def test_a_folder_that_cannot_take_the_temporary_file_is_a_write_error(tmp_path: Path) -> None:
    with pytest.raises(WriteError, match="missing/x.json could not be written: No such file"):
        write_atomic(tmp_path / "missing" / "x.json", "{}")


@pytest.fixture
def read_only(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every file dnnevo writes fails as on a read-only file system (root ignores permissions,
    so a chmod would not do)."""

    def refuse(*args: object, **kwargs: object) -> None:
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    monkeypatch.setattr(files_module.tempfile, "mkstemp", refuse)
    monkeypatch.setattr(rundir_module, "os", _ReadOnlyOs())


class _ReadOnlyOs:
    """The os module as a read-only file system shows it to the writer's lock: opening a file
    to write fails with EROFS."""

    def __getattr__(self, name: str) -> object:
        return getattr(os, name)

    @staticmethod
    def open(path: object, flags: int, *args: object, **kwargs: object) -> int:
        if flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS))
        return os.open(path, flags, *args, **kwargs)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    run = tmp_path_factory.mktemp("disk") / "run"
    assert run_cli("run", *QUICK, "--set", "generations=3", "--out", run).returncode == 0
    return run


def snapshot(run: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(run.iterdir())}


@pytest.mark.parametrize("command, written", [
    (["show"], "fitness.png"),
    (["analyze", "--no-lesions", "--steps", "11"], "analysis.json"),
])
def test_reading_commands_answer_on_a_read_only_folder(
        finished_run: Path, read_only: None, command: list[str], written: str,
        capsys: pytest.CaptureFixture[str]) -> None:
    before = snapshot(finished_run)
    assert main([command[0], str(finished_run), *command[1:]]) == 0
    out, err = capsys.readouterr()
    assert "last generation" in out or "analysed in" in out
    assert (f"dnnevo: note: {finished_run / written} could not be written: the file system is "
            "read-only; what it held before is kept") in err.splitlines()
    assert snapshot(finished_run) == before


def test_plot_on_a_read_only_folder_is_one_line(finished_run: Path, read_only: None,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plot", str(finished_run)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].endswith("could not be written: the file system is read-only; "
                                             "what it held before is kept")



def test_assess_answers_on_a_read_only_folder(finished_run: Path, read_only: None,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    before = snapshot(finished_run)
    assert main(["assess", str(finished_run), "--trials", "5"]) in (0, 1)  # pass or fail
    assert "overall:" in capsys.readouterr().out
    assert snapshot(finished_run) == before


def test_resume_on_a_read_only_folder_is_one_line(finished_run: Path, read_only: None,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    before = snapshot(finished_run)
    assert main(["resume", str(finished_run), "--generations", "5"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"dnnevo: error: {finished_run} cannot be written: the file system is read-only"]
    assert snapshot(finished_run) == before
