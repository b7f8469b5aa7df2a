"""Run folders under damage, kills and concurrent writers (issue #17).

Every command on a damaged folder either fails with exit status 2 and one line naming the
problem, or succeeds and leaves a folder whose files agree. A kill at any moment leaves a folder
that resumes to the end of an uninterrupted run, bit for bit, with no temporary file left.

CI runs a reduced version; ``DNNEVO_FULL_HARDENING=1 python -m pytest tests/test_hardening.py``
runs the full one (more damage examples, 30 kills).
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from cli_helpers import assert_one_line_error, run_cli
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dnnevo.runs import RunDir

FULL = os.environ.get("DNNEVO_FULL_HARDENING") == "1"
SMALL = ["--set", "population=12", "--set", "generations=6"]
LEFTOVER = {".dnnevo.lock"}


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished small sequence run, copied by each test that damages it."""
    out = tmp_path_factory.mktemp("pristine") / "run"
    r = run_cli("run", "sequence-1bit", "--quick", *SMALL, "--seed", "3", "--out", out)
    assert r.returncode == 0, r.stderr
    return out


def copy(pristine: Path, where: Path) -> Path:
    shutil.copytree(pristine, where)
    return where


def assert_consistent(run: Path) -> None:
    """The four files agree: resume and show accept them and no temporary file is left."""
    rd = RunDir(run)
    config, table = rd.read_config()
    cp = rd.read_checkpoint()
    assert cp.run is not None and cp.run["seed"] == table["seed"]
    assert len(rd.read_log(config)) == len(cp.history)
    rd.read_best(config, table)
    assert {p.name for p in run.iterdir() if p.name.startswith(".")} <= LEFTOVER


def text_damage(text: str) -> list[tuple[str, str]]:
    """Named ways to damage a text file."""
    return [
        ("empty", ""),
        ("truncated", text[: len(text) // 2]),
        ("invalid utf-8", text[:10] + "\udcff" + text[10:]),
        ("null", "null"),
        ("list", "[]"),
        ("string", '"x"'),
        ("number", "3"),
        ("nested", "[" * 100_000 + "]" * 100_000),
    ]


def write(path: Path, text: str) -> None:
    path.write_bytes(text.encode("utf-8", "surrogateescape"))


def checkpoint_edits(doc: dict) -> list[tuple[str, Callable[[dict], None]]]:
    def set_(path: str, value: object) -> Callable[[dict], None]:
        def edit(d: dict) -> None:
            *head, last = path.split(".")
            for k in head:
                d = d[int(k)] if isinstance(d, list) else d[k]
            if isinstance(d, list):
                d[int(last)] = value
            else:
                d[last] = value
        return edit

    def evolution(key: str, value: object) -> Callable[[dict], None]:
        def edit(d: dict) -> None:
            evo = json.loads(d["state"]["evolution"])
            evo[key] = value
            d["state"]["evolution"] = json.dumps(evo)
        return edit

    return [
        ("state list", set_("state", [])),
        ("history dict", set_("history", {})),
        ("history string value", set_("history.0.best", "0.5")),
        ("history nan", set_("history.2.mean", float("nan"))),
        ("history short", lambda d: d["history"].pop()),
        ("no state.config", lambda d: d["state"].pop("config")),
        ("config edited", set_("state.config.population", 13)),
        ("targets edited", set_("state.config.task_params", {"targets": ["1"]})),
        ("generation beyond end", evolution("generation", 99)),
        ("seed edited", evolution("seed", 4)),
        ("evolution not json", set_("state.evolution", "{")),
        ("digest edited", set_("config_sha256", "0" * 64)),
        ("version 3", set_("version", 3)),
    ]


COMMANDS = [["resume"], ["show"], ["assess", "--trials", "2", "--seed", "0"], ["plot"],
            ["analyze", "--no-lesions", "--steps", "5"]]


def check_outcome(r: subprocess.CompletedProcess[str], run: Path, command: str) -> None:
    """Exit 2 with one line, or success (evaluate: any verdict) with a consistent folder."""
    if r.returncode == 2:
        assert_one_line_error(r)
    else:
        assert r.returncode in ((0, 1, 3) if command == "assess" else (0,)), r.stderr
        assert "Traceback" not in r.stderr
        if command == "resume":
            assert_consistent(run)


@pytest.mark.parametrize("name", ["checkpoint.json", "log.csv", "config.toml", "best.json"])
@pytest.mark.slow
def test_damaged_files_are_one_line_or_repaired(pristine: Path, tmp_path: Path, name: str) -> None:
    damages = text_damage((pristine / name).read_text())
    if not FULL:
        damages = [d for d in damages if d[0] in ("empty", "invalid utf-8", "nested", "list")]
    for label, text in damages:
        for command in COMMANDS:
            run = copy(pristine, tmp_path / f"{label}-{command[0]}".replace(" ", "_"))
            write(run / name, text)
            r = run_cli(command[0], run, *command[1:])
            check_outcome(r, run, command[0])
            # A reader never repairs anything: the damage is reported.
            if command[0] in ("show", "plot") and name in ("log.csv", "config.toml"):
                assert r.returncode == 2, (label, command, r.stdout)


def test_checkpoint_edits_are_refused(pristine: Path, tmp_path: Path) -> None:
    doc = json.loads((pristine / "checkpoint.json").read_text())
    for label, edit in checkpoint_edits(doc):
        run = copy(pristine, tmp_path / label.replace(" ", "_"))
        d = json.loads((run / "checkpoint.json").read_text())
        edit(d)
        (run / "checkpoint.json").write_text(json.dumps(d))
        r = run_cli("resume", run)
        assert_one_line_error(r, "checkpoint.json")


@pytest.mark.parametrize(("field", "value"), [
    ("population", "13"), ("generations", "7"), ("mutation_rate", "0.5"), ("size", "6"),
    ("task", '"landmark"'),
])
def test_edited_config_toml_is_refused_naming_the_field(pristine: Path, tmp_path: Path, field: str,
                                                         value: str) -> None:
    run = copy(pristine, tmp_path / "run")
    lines = (run / "config.toml").read_text().splitlines()
    lines = [f"{field} = {value}" if line.startswith(f"{field} = ") else line for line in lines]
    (run / "config.toml").write_text("\n".join(lines) + "\n")
    r = run_cli("resume", run)
    assert_one_line_error(r, f"at {field}:")
    # The readers apply the same rule: what they would report is not what the run was made with.
    for command in (["show"], ["assess", "--trials", "2"], ["plot"]):
        r = run_cli(command[0], run, *command[1:])
        assert_one_line_error(r, "config.toml was edited after the run", f"{field} is")


@pytest.mark.slow
def test_log_damage_in_show_and_plot(pristine: Path, tmp_path: Path) -> None:
    text = (pristine / "log.csv").read_text()
    header, *rows = text.splitlines()
    cases = {
        "header only": header + "\n",
        "short row": "\n".join([header, rows[0], rows[1].rsplit(",", 1)[0]]) + "\n",
        "other columns": text.replace("generation", "gen", 1),
        "non-numeric": text.replace(rows[1].split(",")[1], "abc", 1),
        # Python's float() takes these; no log holds them
        "underscored": "\n".join([header, rows[0], rows[1].replace(rows[1].split(",")[1], "1_0", 1)]) + "\n",
        "spaced": "\n".join([header, rows[0], rows[1].replace(rows[1].split(",")[1], " 0.5", 1)]) + "\n",
        "inf": "\n".join([header, rows[0], rows[1].replace(rows[1].split(",")[1], "inf", 1)]) + "\n",
        "duplicated row": "\n".join([header, rows[0], rows[0], *rows[1:]]) + "\n",
    }
    for label, damaged in cases.items():
        run = copy(pristine, tmp_path / label.replace(" ", "_"))
        (run / "log.csv").write_text(damaged)
        for command in ("show", "plot"):
            assert_one_line_error(run_cli(command, run), "log.csv")
        # resume rebuilds the log from the checkpoint
        r = run_cli("resume", run)
        assert r.returncode == 0, r.stderr
        assert (run / "log.csv").read_text() == text


def test_wrong_champion_and_deleted_best_json(pristine: Path, tmp_path: Path) -> None:
    import dnnevo

    run = copy(pristine, tmp_path / "run")
    dnnevo.Network.random(4, 2, seed=0).save(run / "best.json")
    for command in ("assess", "plot", "analyze"):
        assert_one_line_error(run_cli(command, run), "best.json", "size 4")
    (run / "best.json").unlink()
    assert run_cli("resume", run).returncode == 0
    assert (run / "best.json").read_bytes() == (pristine / "best.json").read_bytes()
    # A champion that says it was run with another step, or in another precision, than the run.
    best = dnnevo.Network.load(pristine / "best.json")
    assert best.integrator is not None
    best.save(run / "best.json", integrator={**best.integrator, "dt": 1.0})
    assert_one_line_error(run_cli("assess", run), "best.json", "integrator is")
    best.save(run / "best.json", meta={"precision": "f32"})
    assert_one_line_error(run_cli("assess", run), "best.json", "meta.precision is 'f32'")


def test_figures_never_follow_symlinks(pristine: Path, tmp_path: Path) -> None:
    run = copy(pristine, tmp_path / "run")
    target = tmp_path / "important"
    target.write_text("keep")
    (run / "fitness.png").unlink(missing_ok=True)
    (run / "fitness.png").symlink_to(target)
    assert run_cli("show", run).returncode == 0
    assert target.read_text() == "keep" and not (run / "fitness.png").is_symlink()
    mode = 0o666 & ~_umask()
    for name in ("fitness.png", "log.csv", "checkpoint.json", "best.json", "config.toml"):
        assert (run / name).stat().st_mode & 0o777 == mode, name


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@settings(max_examples=40 if FULL else 8, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.binary(max_size=200), name=st.sampled_from(["checkpoint.json", "log.csv", "config.toml"]))
def test_random_bytes_are_one_line(pristine: Path, tmp_path_factory: pytest.TempPathFactory,
                                   data: bytes, name: str) -> None:
    run = copy(pristine, tmp_path_factory.mktemp("fuzz") / "run")
    (run / name).write_bytes(data)
    command = "resume" if name == "checkpoint.json" else "show"
    check_outcome(run_cli(command, run), run, command)


def test_two_writers_on_one_folder(tmp_path: Path) -> None:
    out = tmp_path / "d"
    first = subprocess.Popen([sys.executable, "-m", "dnnevo", "run", "sequence-1bit", "--quick",
                              "--set", "generations=100000", "--seed", "3", "--out", str(out)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not (out / "config.toml").exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        for args in (["run", "sequence-1bit", "--quick", "--seed", "4", "--out", out, "--force"],
                     ["resume", out],
                     ["sweep", "sequence-1bit", "--quick", "--seeds", "0", "--out", out, "--force"]):
            assert_one_line_error(run_cli(*args), f"PID {first.pid}")
        # Readers keep working during the run, once it has logged a generation.
        while len((out / "log.csv").read_text().splitlines()) < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert run_cli("show", out).returncode == 0
    finally:
        first.send_signal(signal.SIGINT)
        first.communicate(timeout=60)
    seed = RunDir(out).read_config()[1]["seed"]
    assert seed == 3 and RunDir(out).read_checkpoint().run["seed"] == 3  # type: ignore[index]
    assert_consistent(out)
    # The lock died with its holder: the next writer is welcome.
    done = len(RunDir(out).read_checkpoint().history)
    r = run_cli("resume", out, "--generations", done + 2)
    assert r.returncode == 0, r.stderr
    assert len(RunDir(out).read_log()) == done + 2


def test_force_clears_the_old_runs_figures(pristine: Path, tmp_path: Path) -> None:
    run = copy(pristine, tmp_path / "run")
    assert run_cli("plot", run).returncode == 0
    (run / "notes.txt").write_text("mine")
    r = run_cli("run", "sequence-1bit", "--quick", *SMALL, "--seed", "5", "--out", run, "--force")
    assert r.returncode == 0, r.stderr
    names = {p.name for p in run.iterdir()}
    assert names == {".dnnevo.lock", "notes.txt", "config.toml", "log.csv", "best.json", "checkpoint.json"}


def test_sweep_force_clears_the_old_sweeps_other_seeds(pristine: Path, tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    out.mkdir()
    for seed in (0, 7, 8):
        copy(pristine, out / f"seed-{seed}")
    (out / "seed-8" / "notes.txt").write_text("mine")
    (out / "summary.csv").write_text("old")
    r = run_cli("sweep", "sequence-1bit", "--quick", *SMALL, "--seeds", "0", "--out", out, "--force",
                "--eval-trials", "5", "--no-dt-check")
    assert r.returncode == 0, r.stderr
    # Seed 7 was the old sweep's alone and is gone; seed 8 keeps only what was not dnnevo's.
    assert sorted(p.name for p in out.iterdir()) == [".dnnevo.lock", "seed-0", "seed-8", "summary.csv",
                                                      "summary.json", "sweep.json"]
    assert sorted(p.name for p in (out / "seed-8").iterdir()) == [".dnnevo.lock", "notes.txt"]
    assert "old" not in (out / "summary.csv").read_text()


def test_generations_extends_a_run_keeping_files_in_agreement(pristine: Path, tmp_path: Path) -> None:
    run = copy(pristine, tmp_path / "run")
    longer = tmp_path / "longer"
    r = run_cli("run", "sequence-1bit", "--quick", "--set", "population=12", "--set", "generations=9",
                "--seed", "3", "--out", longer)
    assert r.returncode == 0
    assert_one_line_error(run_cli("resume", run, "--generations", "3"), "generations is 3")
    assert run_cli("resume", run, "--generations", "9").returncode == 0
    assert_consistent(run)
    assert "generations = 9" in (run / "config.toml").read_text()
    for name in ("best.json", "checkpoint.json"):
        a, b = (json.loads((d / name).read_text()) for d in (run, longer))
        for doc in (a, b):
            for row in doc.get("history", []):
                row.pop("elapsed_s"), row.pop("evals_per_s")
        assert a == b, name


def test_a_log_written_with_float_generations_reads_shows_and_resumes(pristine: Path, tmp_path: Path) -> None:
    """log.csv files written before the generation and champion_success were integers (``0.0``,
    ``1.0``) read the same, ``show`` takes them, and the folder extends bit for bit."""
    run = copy(pristine, tmp_path / "run")
    header, *lines = (run / "log.csv").read_text().splitlines()
    assert [line.split(",")[0] for line in lines] == [str(g) for g in range(len(lines))]
    rows = RunDir(run).read_log()
    # The old writer: repr(float(value)) for every column.
    old = [header, *(",".join(repr(float(cell)) for cell in line.split(",")) for line in lines)]
    assert old[1].startswith("0.0,")
    (run / "log.csv").write_text("\n".join(old) + "\n")
    assert json.dumps(RunDir(run).read_log()) == json.dumps(rows)
    r = run_cli("show", run)
    assert r.returncode == 0 and "last generation (5): gen best" in r.stdout, (r.stdout, r.stderr)
    longer = tmp_path / "longer"
    r = run_cli("run", "sequence-1bit", "--quick", "--set", "population=12", "--set", "generations=9",
                "--seed", "3", "--out", longer)
    assert r.returncode == 0, r.stderr
    r = run_cli("resume", run, "--generations", "9")
    assert r.returncode == 0, r.stderr
    assert_consistent(run)

    def without_timing(path: Path) -> list[list[str]]:
        table = [line.split(",") for line in path.read_text().splitlines()]
        return [row[:-2] for row in table]

    assert without_timing(run / "log.csv") == without_timing(longer / "log.csv")
    assert [row[0] for row in without_timing(run / "log.csv")[1:]] == [str(g) for g in range(9)]
    assert (run / "best.json").read_text() == (longer / "best.json").read_text()


def test_a_run_whose_checkpoint_is_gone_is_not_quietly_started_again(pristine: Path, tmp_path: Path) -> None:
    """Without checkpoint.json, resume would start from generation 0: refused while log.csv or
    best.json shows work it would lose; a folder with only config.toml starts again."""
    run = copy(pristine, tmp_path / "run")
    (run / "checkpoint.json").unlink()
    before = {p.name: p.read_bytes() for p in run.iterdir()}
    r = run_cli("resume", run)
    assert_one_line_error(r, "has no checkpoint.json, but log.csv records 6 generations",
                          "restore checkpoint.json")
    assert {p.name: p.read_bytes() for p in run.iterdir()} == before
    (run / "log.csv").unlink()
    assert_one_line_error(run_cli("resume", run), "records 0 generations and best.json a champion")
    (run / "best.json").unlink()
    r = run_cli("resume", run)
    assert r.returncode == 0, r.stderr
    assert (run / "log.csv").read_text() .count("\n") == 7


def test_a_run_that_failed_in_its_first_generation_is_not_sent_round_to_resume(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "boom0.py").write_text(
        "import numpy as np\n"
        "class Boom:\n"
        "    observation_size = 1\n"
        "    def reset(self, episodes, rng):\n"
        "        return np.zeros((len(episodes), 1))\n"
        "    def step(self, rates, active):\n"
        "        raise RuntimeError('broken')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    run = tmp_path / "run"
    r = run_cli("run", "python:boom0.Boom", "--set", "task_params.max_steps=5", "--set", "population=6",
                "--set", "generations=2", "--out", run)
    assert r.returncode == 2 and "broken" in r.stderr, r.stderr
    assert (run / "checkpoint.json").exists() and not (run / "best.json").exists()
    assert_one_line_error(run_cli("assess", run), "no generation has finished: its run stopped in generation 0")


def test_an_edited_seed_is_blamed_on_config_toml(pristine: Path, tmp_path: Path) -> None:
    run = copy(pristine, tmp_path / "run")
    text = (run / "config.toml").read_text()
    assert "seed = 3\n" in text
    (run / "config.toml").write_text(text.replace("seed = 3\n", "seed = 4\n"))
    for command in ("show", "assess"):
        assert_one_line_error(run_cli(command, run), "config.toml was edited after the run: run.seed is 4 "
                              "in config.toml and 3 in checkpoint.json")


def test_a_folder_being_written_is_named_as_such_by_show_and_run(pristine: Path, tmp_path: Path) -> None:
    run = copy(pristine, tmp_path / "run")
    assert RunDir(run).writer() is None
    with RunDir(run).writing(create=False):
        assert RunDir(run).writer() == str(os.getpid())
        shown = run_cli("show", run)
        assert shown.returncode == 0 and f"the run is going on (PID {os.getpid()})" in shown.stdout, shown.stdout
        assert_one_line_error(run_cli("run", "sequence-1bit", "--quick", "--out", run),
                              f"is in use by another dnnevo process (PID {os.getpid()})")
        (run / "best.json").unlink()
        assert_one_line_error(run_cli("assess", run), f"has no best.json yet: its run is going on (PID {os.getpid()})")
    assert RunDir(run).writer() is None


def test_resume_says_which_damaged_file_it_writes_again(pristine: Path, tmp_path: Path) -> None:
    run = copy(pristine, tmp_path / "run")
    (run / "log.csv").write_text("garbled\n1,2\n")
    (run / "best.json").unlink()
    r = run_cli("resume", run, "--generations", "7")
    assert r.returncode == 0, r.stderr
    assert "log.csv was damaged" in r.stderr and "best.json was gone" in r.stderr, r.stderr
    assert "written again from checkpoint.json" in r.stderr
    assert_consistent(run)
    r = run_cli("resume", run, "--generations", "8")
    assert r.returncode == 0 and "written again" not in r.stderr, r.stderr


KILLS = 30 if FULL else 8
KILL_GENERATIONS = 100
KILL_RUN = ["sequence-1bit", "--quick", "--set", "population=40", "--set", f"generations={KILL_GENERATIONS}"]
#: The command, checkpointing after every generation so that kills land inside writes too.
FREQUENT = ("import sys, dnnevo; e = sys.modules['dnnevo.evolution.evolve']; e.CHECKPOINT_SECONDS = 0.0; "
            "e.LOG_SECONDS = 0.0; from dnnevo.cli.command import main; sys.exit(main(sys.argv[1:]))")


@pytest.mark.slow
def test_kill_at_random_moments_then_resume_is_bit_identical(tmp_path: Path) -> None:
    """SIGKILL at random moments (from start-up on, so also before the first checkpoint and
    inside writes), then resume, again and again: the end equals an uninterrupted run."""
    ref = tmp_path / "ref"
    started = time.monotonic()
    assert run_cli("run", *KILL_RUN, "--seed", "1", "--out", ref).returncode == 0
    # Kill times spread over a whole run as long as this machine takes now, however loaded.
    span = max(1.0, 1.2 * (time.monotonic() - started))
    out = tmp_path / "killed"
    rng = random.Random(17)
    start = ["run", *KILL_RUN, "--seed", "1", "--out", str(out)]
    progress = []
    for i in range(KILLS):
        args = start if not (out / "checkpoint.json").exists() else ["resume", str(out)]
        p = subprocess.Popen([sys.executable, "-c", FREQUENT, *args],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(rng.uniform(0.0, span))
        p.kill()
        _, err = p.communicate(timeout=60)
        assert "Traceback" not in err, err
        if (out / "checkpoint.json").exists():
            progress.append(len(RunDir(out).read_checkpoint().history))
            if progress[-1] == KILL_GENERATIONS and not any(0 < n < KILL_GENERATIONS for n in progress):
                # The machine got quicker than during the reference run, so a whole run fit
                # before the kill: start again with kill times over a shorter span.
                shutil.rmtree(out)
                span = max(0.5, span / 2)
    assert any(0 < n < KILL_GENERATIONS for n in progress), progress  # some kills landed mid-run
    r = run_cli("resume", out) if (out / "checkpoint.json").exists() else run_cli(*start)
    assert r.returncode == 0, r.stderr
    assert (out / "best.json").read_bytes() == (ref / "best.json").read_bytes()
    a, b = (json.loads((d / "checkpoint.json").read_text()) for d in (out, ref))
    assert a["state"] == b["state"] and a["config_sha256"] == b["config_sha256"]
    strip = ("elapsed_s", "evals_per_s")
    assert [{k: v for k, v in row.items() if k not in strip} for row in a["history"]] == \
        [{k: v for k, v in row.items() if k not in strip} for row in b["history"]]
    assert {p.name for p in out.iterdir() if p.name.startswith(".")} <= LEFTOVER


def test_ctrl_c_during_start_up_is_one_line(tmp_path: Path) -> None:
    rng = random.Random(3)
    # The interpreter's own start-up, before any dnnevo code runs, is out of dnnevo's reach:
    # measured here, so that a loaded machine does not make the test interrupt it.
    bare = max(_wall([sys.executable, "-c", "pass"]) for _ in range(3))
    for i in range(12 if FULL else 4):
        p = subprocess.Popen([sys.executable, "-m", "dnnevo", "run", *KILL_RUN, "--out",
                              str(tmp_path / f"r{i}")], stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, text=True)
        time.sleep(2 * bare + rng.uniform(0.0, 0.45))
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=60)
        lines = [line for line in err.splitlines() if line and not line.startswith("[")]  # progress
        assert "Traceback" not in err and len(lines) <= 1, err


def test_an_interrupt_wrapped_during_import_is_one_line() -> None:
    """Python 3.11 turns a Ctrl-C that lands while a class is created into a RuntimeError from
    ``__set_name__``: the start-up hook still reports it as an interrupt, and nothing else."""
    code = (
        "import dnnevo\n"
        "for error in (KeyboardInterrupt, ValueError):\n"
        "    try:\n"
        "        try:\n"
        "            raise error('inner')\n"
        "        except BaseException as e:\n"
        "            raise RuntimeError('wrapped') from e\n"
        "    except RuntimeError as e:\n"
        "        dnnevo._startup.interrupted_import(type(e), e, e.__traceback__)\n"
    )
    err = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stderr
    assert err.startswith("dnnevo: interrupted\nTraceback"), err
    assert "ValueError: inner" in err and err.count("dnnevo: interrupted") == 1, err


def _wall(command: list[str]) -> float:
    """Seconds ``command`` takes to run."""
    t0 = time.monotonic()
    subprocess.run(command, check=True)
    return time.monotonic() - t0


LIMITS_SCRIPT = r"""
import resource, sys
resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))  # 2 GiB: a regression cannot take the machine
import dnnevo
import numpy as np
from dnnevo import ConfigError, FormatError

def refused(call, kind, fragment):
    try:
        call()
    except kind as e:
        assert fragment in str(e), (fragment, str(e))
    else:
        raise AssertionError(f"no {kind.__name__}: {call}")

refused(lambda: dnnevo.Network.random(10**6, 1, seed=0), ConfigError, "the limit is")
refused(lambda: dnnevo.Network.random(2**62, 2**62, seed=0), ConfigError, "the limit is")
small = dnnevo.EvolutionConfig(population=10**12, size=5, n_inputs=2)
refused(lambda: dnnevo.GeneticAlgorithm(small), ConfigError, "TiB")
wide = dnnevo.EvolutionConfig(population=10, size=100_000, n_inputs=2)
refused(lambda: dnnevo.GeneticAlgorithm(wide), ConfigError, "the limit is")
refused(lambda: dnnevo.GeneticAlgorithm.from_state_dict({}), ConfigError, "'config' and 'evolution'")
from dnnevo import InvalidArgumentError
refused(lambda: dnnevo.Network.random(3, -1, seed=0), InvalidArgumentError, "n_inputs is -1")
refused(lambda: dnnevo.Network.random(3, 1, seed=2**64), InvalidArgumentError, "seed is 18446744073709551616")
refused(lambda: dnnevo.Network.random(3, 1, seed=-1), InvalidArgumentError, "seed is -1")
nets = [dnnevo.Network.random(5, 2, seed=0)]
refused(lambda: dnnevo.evaluate("sequence", nets, generation=-1, seed=0), InvalidArgumentError, "generation is -1")
refused(lambda: dnnevo.evaluate("sequence", nets, generation=0, seed=0, threads=-2), InvalidArgumentError, "threads is -2")
refused(lambda: dnnevo.EvolutionConfig(task_params={"perf_base": float("nan")}), ConfigError, "task_params.perf_base is nan")
from dnnevo import analysis
from dnnevo.tasks import landmark
from dnnevo.tasks import nav1d
from dnnevo import presets
from dnnevo.tasks import sequence
refused(lambda: nets[0].run(np.zeros((3, 2)), substeps=2**64), InvalidArgumentError, "substeps is 18446744073709551616")
refused(lambda: dnnevo.run_population(nets, np.zeros((3, 2)), substeps=2**70), InvalidArgumentError, "substeps is")
# Sizes within the integer types that ask for years of work or terabytes: refused, never aborted.
blind = dnnevo.Network.random(3, 0, seed=0)
refused(lambda: blind.run(np.zeros((10**12, 0))), InvalidArgumentError, "integration steps")
refused(lambda: blind.run(np.zeros((2**35, 0))), InvalidArgumentError, "cannot allocate the recorded states")
refused(lambda: dnnevo.run_population([blind], np.zeros((10**12, 0))), InvalidArgumentError, "the limit is 68719476736")
refused(lambda: dnnevo.run_population([blind] * 4, np.zeros((2**33, 0))), InvalidArgumentError, "cannot allocate")
refused(lambda: nets[0].run(np.zeros((3, 2)), substeps=2**63), InvalidArgumentError, "integration steps")
refused(lambda: dnnevo.Batch(nets, replicas=2**40), InvalidArgumentError, "the limit is 16777216")
refused(lambda: dnnevo.Batch(nets, substeps=2**62).step(np.zeros((1, 2))), InvalidArgumentError, "integration steps")
refused(lambda: analysis.equilibria(nets[0], [0.0, 0.0], starts=2**70), InvalidArgumentError, "starts is")
refused(lambda: analysis.equilibria(nets[0], [0.0, 0.0], starts=10**9), InvalidArgumentError, "starts is 1000000000")
refused(lambda: nav1d.fresh_chains(presets.get("nav1d-far"), 10**13, 3, 0), InvalidArgumentError, "count is 10000000000000")
refused(lambda: nav1d.assess(presets.get("nav1d-far"), dnnevo.Network.random(5, 1, seed=0), 0, 0), InvalidArgumentError, "count is 0")
refused(lambda: landmark.assess(presets.get("landmark"), dnnevo.Network.random(8, 1, seed=0), 10**9, seed=0), InvalidArgumentError, "per_landmark is")
refused(lambda: sequence.assess(presets.get("sequence-1bit"), nets[0], 2**40, 0), InvalidArgumentError, "trials_per_target is")
import numpy as np
from dnnevo import InvalidNetworkError
stack = {"tau": np.ones((2, 3)), "theta": np.zeros((2, 3)), "weights": np.zeros((2, 3, 3)),
         "sensor_weights": np.zeros((2, 3, 1)), "states": np.zeros((2, 3))}
refused(lambda: dnnevo.run_population(stack, np.zeros((4, 1))), InvalidNetworkError, "unknown key 'states'")
deep = []
for _ in range(100_000):
    deep = [deep]
net = dnnevo.Network.random(2, 1, seed=0)
refused(lambda: net.save(sys.argv[1], meta={"x": deep}), FormatError, "deeper than 128")
d = net.to_dict()
d["meta"] = {"x": deep}
refused(lambda: dnnevo.Network.from_dict(d), FormatError, "deeper than 128")
print("ok")
"""


def test_api_limits_are_typed_errors_in_a_memory_limited_child(tmp_path: Path) -> None:
    r = subprocess.run([sys.executable, "-c", LIMITS_SCRIPT, str(tmp_path / "n.json")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr[-2000:]


def test_cli_sizes_past_the_limit_are_one_line(tmp_path: Path) -> None:
    import resource

    def limit() -> None:  # 2 GiB of address space: a regression cannot take the machine down
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    cases = [("sequence-1bit", s) for s in (
        "population=1000000000000", "size=100000", "task_params.trials_per_target=1000000000000",
        "task_params.perf_base=nan")]
    # Settings each within its own limit whose product is a trial of years or terabytes.
    cases += [("sequence-1bit", "task_params.gap=[1, 1000000000000]"),
              ("sequence-1bit", "integrator.substeps=1000000000"),
              ("landmark", "task_params.trial_seconds=1e12"),
              ("landmark", "task_params.sim={dt=1e-9}"),
              ("nav1d-far", "integrator.substeps=9223372036854775808")]
    for preset, setting in cases:
        r = subprocess.run([sys.executable, "-m", "dnnevo", "run", preset, "--quick", "--set",
                            setting, "--out", str(tmp_path / "x"), "--force"],
                           capture_output=True, text=True, timeout=120, preexec_fn=limit)
        assert_one_line_error(r)


def test_an_edited_fitness_function_of_the_same_name_is_refused(tmp_path: Path,
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    import importlib
    import tomllib

    import dnnevo
    from dnnevo.errors import ConfigError

    source = "def fit(nets):\n    return [abs(net.theta[0]) {} 1.0 for net in nets]\n"
    module = tmp_path / "edited_fitness.py"
    module.write_text(source.format("+"))
    monkeypatch.syspath_prepend(str(tmp_path))
    import edited_fitness  # type: ignore[import-not-found]

    cfg = dnnevo.EvolutionConfig(population=10, generations=4, size=2, n_inputs=1)
    out = tmp_path / "run"
    dnnevo.evolve(edited_fitness.fit, cfg, seed=1, out=out, progress=False,
                  callback=lambda stats, ga: ga.generation >= 2)
    # Unchanged: it resumes. Edited under the same name: refused, or accepted and recorded.
    module.write_text(source.format("-"))
    importlib.reload(edited_fitness)
    with pytest.raises(ConfigError, match="not an edited python:edited_fitness.fit"):
        dnnevo.resume(out, edited_fitness.fit, progress=False)
    dnnevo.resume(out, edited_fitness.fit, progress=False, new_fitness=True)
    run = tomllib.loads((out / "config.toml").read_text())["run"]
    assert [c["task"] for c in run["fitness_changes"]] == ["python:edited_fitness.fit"]
