"""The dnnevo command: every command works and every error is one line with exit status 2."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest


def dnnevo(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "dnnevo", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=600)


def test_help_shows_a_working_example() -> None:
    r = dnnevo("--help")
    assert r.returncode == 0 and "dnnevo run sequence-1bit --quick" in r.stdout
    # --quick takes well under a second, not ten.
    assert "10-second" not in r.stdout and "a tiny demo run (under a second)" in r.stdout


def test_run_show_assess_resume_sweep(tmp_path: Path) -> None:
    out = tmp_path / "demo"
    r = dnnevo("run", "sequence-1bit", "--quick", "--out", str(out), "--seed", "1")
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[-1].startswith(f"next: dnnevo assess {out}")
    r = dnnevo("show", str(out))
    assert r.returncode == 0 and (out / "fitness.png").stat().st_size > 1000
    r = dnnevo("assess", str(out), "--trials", "5", "--seed", "1")
    # Exit status 0 pass, 1 fail, 3 undecided: the overall verdict.
    verdict = {0: "pass", 1: "fail", 3: "undecided"}[r.returncode]
    assert f"overall: {verdict}" in r.stdout and "switch test" in r.stdout, r.stdout
    # A reader that stops reading (`| head`) leaves the verdict as the exit status, quietly.
    gone = subprocess.run(["bash", "-c", f"set -o pipefail; {sys.executable} -m dnnevo assess {out} "
                           "--trials 5 --seed 1 | (exec <&-)"], capture_output=True, text=True, timeout=600)
    assert (gone.returncode, gone.stderr) == (r.returncode, ""), gone
    # The command's old name still works, says it is deprecated, and judges the same.
    old = dnnevo("evaluate", str(out), "--trials", "5", "--seed", "1")
    assert (old.returncode, old.stdout) == (r.returncode, r.stdout)
    assert old.stderr == "dnnevo: 'evaluate' is deprecated; use 'dnnevo assess'\n"
    r = dnnevo("plot", str(out))
    assert r.returncode == 0, r.stderr
    for name in ("fitness.png", "fig4-trials.png", "fig5-switch.png"):
        assert (out / name).stat().st_size > 1000
    r = dnnevo("resume", str(out))  # already finished: nothing to do, still a clean exit
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f"nothing to resume: {out} has run all its 8 generations; to run it "
                               f"longer: dnnevo resume {out} --generations N (N > 8)\n"), r.stdout
    # A finished run whose checkpoint is damaged gets the error alone, not "nothing to resume".
    checkpoint = out / "checkpoint.json"
    whole = checkpoint.read_bytes()
    checkpoint.write_bytes(whole[: len(whole) // 2])
    r = dnnevo("resume", str(out))
    assert r.returncode == 2 and r.stdout == "" and "checkpoint.json" in r.stderr, (r.stdout, r.stderr)
    checkpoint.write_bytes(whole)
    r = dnnevo("resume", str(out), "--generations", "9")
    assert r.returncode == 0 and "nothing to resume" not in r.stdout, r.stdout
    assert r.stdout.startswith("9 generations in "), r.stdout
    r = dnnevo("presets")
    assert r.returncode == 0 and "sequence-1bit" in r.stdout


def test_a_preset_meant_to_start_from_earlier_runs_warns_without_them(tmp_path: Path) -> None:
    r = dnnevo("run", "nav1d-single-incremental", "--quick", "--set", "generations=1",
               "--out", str(tmp_path / "single"))
    assert r.returncode == 0, r.stderr
    assert r.stderr.splitlines()[0] == (
        "dnnevo: warning: nav1d-single-incremental is meant to start from earlier runs (--seed-from "
        "a chained nav1d-near run --spare-neurons 3); without --seed-from this run starts from "
        "random networks")
    r = dnnevo("run", "sequence-1bit", "--quick", "--set", "generations=1", "--out", str(tmp_path / "one"))
    assert r.returncode == 0 and "warning" not in r.stderr, r.stderr


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["run", "no-such-preset"], "unknown preset 'no-such-preset'; presets: categorical-perception, "),
        (["run", "sequence-1bti"], "unknown preset 'sequence-1bti' (did you mean 'sequence-1bit'?)"),
        (["run", "nav1d-clasifier"], "(did you mean 'nav1d-classifier'?)"),
        (["run", "sequence-1bit", "--set", "task=sequnce"], "unknown task 'sequnce' (did you mean 'sequence'?)"),
        (["run", "sequence-1bit", "--quick", "--set", "populaton=3"],
         "unknown setting 'populaton' (did you mean 'population'?)"),
        (["run", "sequence-1bit", "--quick", "--set", "integrator.td=3"],
         "unknown setting 'integrator.td' (did you mean 'integrator.dt'?)"),
        (["run", "sequence-1bit", "--quick", "--set", "population=1"], "population is 1; it must be at least 2"),
        # A negative count reads as 0 does, not as a type error.
        (["run", "sequence-1bit", "--quick", "--set", "population=0"], "population is 0; it must be at least 2"),
        (["run", "sequence-1bit", "--quick", "--set", "population=-5"], "population is -5; it must be at least 2"),
        (["run", "sequence-1bit", "--quick", "--set", "generations=-3"], "generations is -3; it must be at least 1"),
        (["run", "sequence-1bit", "--quick", "--set", "nonsense"], "is not key=value"),
        # A task's parameters are named as the config names them, in the config's words.
        (["run", "sequence-1bit", "--quick", "--set", "task_params.triggers=0"],
         "error: task_params.triggers is 0; it must be >= 1"),
        (["run", "sequence-1bit", "--quick", "--set", "task_params.triggers=1.5"],
         "sequence: task_params.triggers: invalid type: floating point `1.5`, expected an integer >= 0"),
        # A preset that warns when unseeded still gives a bad setting as its one line.
        (["run", "sequence-2bit", "--quick", "--set", "task_params.triggers=0"],
         "error: task_params.triggers is 0; it must be >= 1"),
        # A nested table is reached through its dots, as in config.toml.
        (["run", "landmark-robust", "--quick", "--set", "task_params.training.cone_deg=-1"],
         "error: task_params.training.cone_deg is -1"),
        (["run", "landmark", "--quick", "--set", "task_params.trials_per_landmark.x=1"],
         "task_params.trials_per_landmark.x cannot be set: task_params.trials_per_landmark is 3, not a table"),
        # A number picks a list's entry; one that is not there is named with the entries that are.
        (["run", "landmark", "--quick", "--set", "task_params.sim.sonars.2.lobe_deg=10"],
         "task_params.sim.sonars is a list of 1, so its entries are 0 to 0"),
        (["run", "landmark", "--quick", "--set", "task_params.sim.sonars.0.lobe_deg=-1"],
         "sonars[0].lobe_deg is -1; it must be a finite number > 0"),
        (["run", "sequence-1bit", "--seed", "-1"], "-1 is negative"),
        (["run", "sequence-1bit", "--threads", "0"], "must be >= 1"),
        (["resume", "/no/such/dir"], "/no/such/dir does not exist"),
        (["show", "/no/such/dir"], "/no/such/dir does not exist; give a run folder"),
        (["assess", "/no/such/dir"], "/no/such/dir does not exist; give a run folder"),
        (["analyze", "/no/such/dir"], "/no/such/dir does not exist; give a run folder"),
        (["plot", "/"], "/ has no config.toml; is it a dnnevo run folder?"),
        (["show", __file__], f"{__file__} is a file, not a run folder"),
        (["assess", "x", "--trials", "0"], "must be >= 1"),
        (["sweep", "sequence-1bit", "--out", "x", "--eval-trials", "0"], "must be >= 1"),
        (["sweep", "sequence-1bit", "--out", "x", "--eval-seed", "-3"], "-3 is negative"),
        (["sweep", "sequence-1bit", "--out", "x", "--seeds", "0-1", "--eval-seed", str(2**64 - 1)],
         "--eval-seed + seed is 18446744073709551616"),
        (["sweep", "sequence-1bit", "--seeds", "a-b", "--out", "x"], "not a seed list"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_errors_are_one_line(args: list[str], fragment: str, tmp_path: Path) -> None:
    r = dnnevo(*args, cwd=tmp_path)
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert fragment in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "Traceback" not in r.stderr


def test_run_show_and_the_progress_bar_name_the_same_champion(tmp_path: Path) -> None:
    """``run`` ends with the champion best.json holds, the success rule and the next command;
    ``show`` says the same; the progress bar tells the champion from the generation's best."""
    import dnnevo as dn

    out = tmp_path / "full"
    # Seed 0 at the paper's population meets the success rule in generation 0.
    r = dnnevo("run", "sequence-1bit", "--set", "generations=2", "--out", str(out))
    assert r.returncode == 0, r.stderr
    meta = dn.Network.load(out / "best.json").meta
    champion = (f"champion (best.json): fitness {meta['fitness']:.4f} (generation {meta['generation']}); "
                f"validation rate {meta['validation_rate']:.3f}, score {meta['validation_score']:.4f}")
    success = "success rule: met at generation 0 (the champion passed it on fresh trials)"
    after = f"next: dnnevo assess {out}   (judges the champion on fresh trials, with 95% intervals and a verdict)"
    assert r.stdout.splitlines() == [r.stdout.splitlines()[0], champion, success, after], r.stdout
    assert r.stdout.startswith("2 generations in "), r.stdout
    bar = r.stderr.strip().splitlines()[-1]  # not a terminal: one line at the end
    assert (f"gen 2/2  champion {meta['fitness']:.4f} (validation rate {meta['validation_rate']:.3f})  "
            "gen best ") in bar and " gen mean " in bar, bar
    assert " best " not in bar.replace("gen best", ""), bar
    r = dnnevo("show", str(out))
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[1:3] == [champion, success] and lines[-1] == after, r.stdout
    from dnnevo.runs import RunDir

    row = RunDir(out).read_log()[-1]
    assert lines[3] == f"last generation (1): gen best {row['best']:.4f}, gen mean {row['mean']:.4f}"
    # The quick run does not meet the rule.
    r = dnnevo("run", "sequence-1bit", "--quick", "--out", str(tmp_path / "quick"))
    assert "success rule: not met in 8 generations (the champion failed it on fresh trials)" in r.stdout


def test_show_says_a_python_fitness_has_no_success_rule(tmp_path: Path) -> None:
    import dnnevo as dn
    from dnnevo.cli.show import success_line

    out = tmp_path / "py"
    config = dn.EvolutionConfig(population=10, generations=2, size=2, n_inputs=1)
    dn.evolve(lambda nets: np.array([n.tau[0] for n in nets]), config, out=out, progress=False)
    r = dnnevo("show", str(out))
    assert r.returncode == 0, r.stderr
    assert "success rule: none (a Python fitness function has no success rule)" in r.stdout
    assert "next:" not in r.stdout  # the command line can neither resume nor judge it
    assert success_line("sequence", [0.0, 1.0, 0.0]).startswith(
        "success rule: met at generation 1, but the final champion fails it")
    assert success_line("sequence", [float("nan")]).startswith("success rule: not checked")


def test_non_empty_out_is_refused(tmp_path: Path) -> None:
    (tmp_path / "x").mkdir()
    (tmp_path / "x" / "keep.txt").write_text("mine")
    r = dnnevo("run", "sequence-1bit", "--quick", "--out", str(tmp_path / "x"))
    assert r.returncode == 2 and "not empty" in r.stderr
    assert (tmp_path / "x" / "keep.txt").read_text() == "mine"


@pytest.mark.parametrize("args", [("--debug", "run", "no-such-preset"), ("run", "no-such-preset", "--debug"),
                                  ("show", "--debug", "no-such-folder")])
def test_debug_shows_traceback_before_or_after_the_command(tmp_path: Path, args: tuple[str, ...]) -> None:
    r = dnnevo(*args, cwd=tmp_path)
    # The same exit status as without --debug: 1 would be assess's "fail".
    assert r.returncode == 2 and "Traceback" in r.stderr, r.stderr
    assert r.stderr.strip().splitlines()[-1].startswith("dnnevo: error: ")


def test_without_debug_an_error_is_one_line(tmp_path: Path) -> None:
    r = dnnevo("run", "no-such-preset", cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_console_script_is_installed() -> None:
    from importlib.metadata import entry_points

    (script,) = [e for e in entry_points(group="console_scripts") if e.name == "dnnevo"]
    assert script.value == "dnnevo.cli:main"
    r = subprocess.run([str(Path(sys.executable).parent / "dnnevo"), "--version"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and r.stdout.startswith("dnnevo ")


def test_seed_from_composes_champions_and_records_them(tmp_path: Path) -> None:
    import tomllib

    small = ["--quick", "--set", "generations=1", "--set", "population=10"]
    for name in ("a", "b"):
        r = dnnevo("run", "sequence-1bit", *small, "--out", str(tmp_path / name))
        assert r.returncode == 0, r.stderr
    r = dnnevo("run", "sequence-2bit-paper", *small, "--out", str(tmp_path / "c"),
               "--seed-from", str(tmp_path / "a"), "--seed-from", str(tmp_path / "b"))
    assert r.returncode == 0, r.stderr
    run = tomllib.loads((tmp_path / "c" / "config.toml").read_text())["run"]
    assert run["seeded_from"] == [str(tmp_path / "a"), str(tmp_path / "b")]
    assert run["seeded_with"] == "champions"
    plain = tomllib.loads((tmp_path / "a" / "config.toml").read_text())["run"]
    assert "seeded_from" not in plain
    # Whole populations, member by member: the composite of the two runs' first members is the
    # new run's first genome.
    r = dnnevo("run", "sequence-2bit-paper", *small, "--out", str(tmp_path / "d"), "--seed-populations",
               "--seed-from", str(tmp_path / "a"), "--seed-from", str(tmp_path / "b"))
    assert r.returncode == 0, r.stderr
    assert tomllib.loads((tmp_path / "d" / "config.toml").read_text())["run"]["seeded_with"] == "populations"
    import dnnevo as dn
    from dnnevo.runs import RunDir

    def population(run: Path) -> list[dn.Network]:
        state = RunDir(run).read_checkpoint().state
        return dn.GeneticAlgorithm.from_state_dict(state).ask().networks

    from dnnevo.evolution.seeding import Seeding

    a, b = population(tmp_path / "a"), population(tmp_path / "b")
    seeds = Seeding((tmp_path / "a", tmp_path / "b"), populations=True).networks(10, seed=0)
    assert len(seeds) == len(a) == 10
    for k in (0, 3, 9):
        expected = dn.compose(a[k], b[k])
        assert (seeds[k].weights == expected.weights).all() and (seeds[k].tau == expected.tau).all()
    # Cross weights drawn per member from the run's seed: only the off-diagonal blocks change.
    crossed = Seeding((tmp_path / "a", tmp_path / "b"), populations=True, cross_scale=2.0).networks(10, seed=7)
    na = a[0].size
    for k in (0, 3):
        w, plain_w = crossed[k].weights, seeds[k].weights
        assert (w[:na, :na] == plain_w[:na, :na]).all() and (w[na:, na:] == plain_w[na:, na:]).all()
        for block in (w[:na, na:], w[na:, :na]):
            assert (block != 0).all() and (abs(block) <= 2.0).all()
        assert (w == dn.compose(a[k], b[k], cross_scale=2.0, seed=7, member=k).weights).all()
    assert not (crossed[0].weights[:na, na:] == crossed[1].weights[:na, na:]).all()
    other_seed = Seeding((tmp_path / "a", tmp_path / "b"), populations=True, cross_scale=2.0).networks(10, seed=8)
    assert not (other_seed[0].weights == crossed[0].weights).all()
    r = dnnevo("run", "sequence-2bit-paper", *small, "--out", str(tmp_path / "f"), "--cross-scale", "1",
               "--seed-from", str(tmp_path / "a"), "--seed-from", str(tmp_path / "b"))
    assert r.returncode == 0, r.stderr
    assert tomllib.loads((tmp_path / "f" / "config.toml").read_text())["run"]["cross_scale"] == 1.0
    for bad, fragment in ((["--cross-scale", "1"], "--cross-scale needs"),
                          (["--cross-scale", "-1", "--seed-from", str(tmp_path / "a")], "--cross-scale is -1.0"),
                          (["--cross-scale", "nan", "--seed-from", str(tmp_path / "a")], "--cross-scale is nan")):
        r = dnnevo("run", "sequence-2bit-paper", *small, "--out", str(tmp_path / "g"), *bad)
        assert r.returncode == 2 and fragment in r.stderr and "Traceback" not in r.stderr, r.stderr
    r = dnnevo("run", "sequence-2bit-paper", *small, "--out", str(tmp_path / "e"), "--seed-populations")
    assert r.returncode == 2 and "--seed-populations needs" in r.stderr
    # Spare neurons: a random network composed last, unconnected, so neuron 0 answers as before.
    spared = Seeding((tmp_path / "a", tmp_path / "b"), populations=True, spare=3).networks(13, seed=7)
    assert spared[0].size == 13 and spared[0].n_inputs == seeds[0].n_inputs
    assert (spared[0].weights[:10, :10] == seeds[0].weights).all()
    assert (spared[0].weights[:10, 10:] == 0).all() and (spared[0].weights[10:, :10] == 0).all()
    assert not (spared[0].weights[10:, 10:] == spared[1].weights[10:, 10:]).all()
    inputs = np.random.default_rng(0).uniform(0, 1, (300, 2))
    assert (seeds[0].run(inputs).outputs[:, 0] == spared[0].run(inputs).outputs[:, 0]).all()
    with pytest.raises(dn.ConfigError, match="make 13 neurons; the run has 12"):
        Seeding((tmp_path / "a", tmp_path / "b"), spare=3).networks(12, seed=7)
    r = dnnevo("run", "sequence-2bit-paper", *small, "--set", "size=12", "--out", str(tmp_path / "h"), "--spare-neurons",
               "2", "--seed-from", str(tmp_path / "a"), "--seed-from", str(tmp_path / "b"))
    assert r.returncode == 0, r.stderr
    assert tomllib.loads((tmp_path / "h" / "config.toml").read_text())["run"]["spare_neurons"] == 2


def test_a_sweep_seeds_every_run_from_earlier_runs(tmp_path: Path) -> None:
    import json
    import tomllib

    small = ["--quick", "--set", "generations=1", "--set", "population=10"]
    for name in ("a", "b"):
        assert dnnevo("run", "sequence-1bit", *small, "--out", str(tmp_path / name)).returncode == 0
    r = dnnevo("sweep", "sequence-2bit-paper", *small, "--seeds", "0,1", "--out", str(tmp_path / "s"),
               "--eval-trials", "4", "--no-dt-check", "--seed-populations", "--cross-scale", "0.5",
               "--seed-from", str(tmp_path / "a"), "--seed-from", str(tmp_path / "b"))
    assert r.returncode == 0, r.stderr
    for seed in (0, 1):
        run = tomllib.loads((tmp_path / "s" / f"seed-{seed}" / "config.toml").read_text())["run"]
        assert run["seeded_with"] == "populations" and run["cross_scale"] == 0.5
    info = json.loads((tmp_path / "s" / "summary.json").read_text())
    assert json.dumps(info).count(str(tmp_path / "a")) >= 1


def test_nav1d_system_names_a_bad_count_and_a_bad_out_before_any_work(tmp_path: Path) -> None:
    parts = ["--classifier", "c", "--far", "f", "--near", "n"]
    r = dnnevo("nav1d-system", *parts, "--trials", "0", cwd=tmp_path)
    assert r.returncode == 2 and "--trials is 0; it must be >= 1" in r.stderr, r.stderr
    (tmp_path / "file").write_text("")
    r = dnnevo("nav1d-system", *parts, "--out", "file", cwd=tmp_path)
    assert r.returncode == 2 and "--out file is a file" in r.stderr, r.stderr
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "config.toml").write_text("")
    r = dnnevo("nav1d-system", *parts, "--out", "run", cwd=tmp_path)
    assert r.returncode == 2 and "is a run folder" in r.stderr, r.stderr


def test_a_sweep_folder_is_named_as_one_and_an_unknown_option_points_to_its_command(tmp_path: Path) -> None:
    for seed in (0, 1):
        (tmp_path / "sweep" / f"seed-{seed}").mkdir(parents=True)
    for command in ("show", "resume", "assess"):
        r = dnnevo(command, "sweep", cwd=tmp_path)
        assert r.returncode == 2 and "it holds the runs seed-0, seed-1 (a sweep's folder)" in r.stderr, r.stderr
    r = dnnevo("run", "sequence-1bit", "--bogus", cwd=tmp_path)
    assert r.returncode == 2 and "unrecognized arguments: --bogus (see 'dnnevo run --help')" in r.stderr
    listed = [line.split(maxsplit=1) for line in dnnevo("presets").stdout.splitlines()]
    assert ["sequence-2bit-incremental16", "another name for sequence-2bit"] in listed
