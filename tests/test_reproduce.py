"""``dnnevo reproduce``: the graph of runs, one job done safely twice, resuming a stopped run to
the bits of an uninterrupted one, the report, and the command end to end, in process and on a
local Dask cluster (with a worker killed mid-run)."""

from __future__ import annotations

import doctest
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from cli_helpers import assert_one_line_error, run_cli

import dnnevo
from dnnevo.experiments import jobs
from dnnevo.experiments import plan
from dnnevo.experiments import report
from dnnevo.experiments import results
from dnnevo.experiments import runsview
from dnnevo.experiments import scheduler
from dnnevo.errors import ConfigError
from dnnevo.runs import RunDir, RunFileError

QUICK = jobs.Settings(quick=True, eval_trials=10, dt_check=False)


def same_run(a: Path, b: Path) -> None:
    """Two run folders hold the same run: champion, checkpoint state and log (wall times aside)."""
    assert (a / "best.json").read_bytes() == (b / "best.json").read_bytes()
    assert _log(a) == _log(b)
    assert json.loads((a / "checkpoint.json").read_text())["state"] == json.loads((b / "checkpoint.json").read_text())["state"]


def _log(run: Path) -> list[list[str]]:
    """log.csv without its timing columns."""
    rows = [line.split(",") for line in (run / "log.csv").read_text().splitlines()]
    keep = [i for i, name in enumerate(rows[0]) if name not in ("evals_per_s", "elapsed_s")]
    return [[row[i] for i in keep] for row in rows]


def without_wall(result: dict[str, Any]) -> dict[str, Any]:
    out = {k: v for k, v in result.items() if k != "wall_s"}
    if "run" in out:
        out["run"] = {k: v for k, v in out["run"].items() if k != "wall_s"}
    return out


@pytest.mark.parametrize("module", [plan, runsview, scheduler])
def test_doctests(module: Any) -> None:
    assert doctest.testmod(module).failed == 0


def test_the_graph_puts_every_job_after_what_it_needs() -> None:
    order = plan.jobs([0, 1, 2], only=plan.FAMILIES)
    seen: set[str] = set()
    for job in order:
        assert set(job.needs) <= seen, job.id
        assert all(n.endswith(f"/seed-{job.seed}") for n in job.needs)
        seen.add(job.id)
    assert len(order) == 3 * len(plan.EXPERIMENTS)
    assert {j.experiment for j in plan.jobs([0], only=["landmark"])} == {
        "landmark", "landmark-robot", "landmark-worlds", "landmark-robust", "landmark-robust-robot",
        "landmark-robust-worlds", "landmark-robust-second-worlds", "landmark-wide", "landmark-wide-worlds",
        "landmark-wide-first-worlds"}
    with pytest.raises(ConfigError, match="families are"):
        plan.jobs([0], only=["vision"])
    # An experiment's name picks it alone, after the jobs it needs, with a family beside it.
    assert [j.id for j in plan.jobs([2], only=["nav1d-system", "classic"])] == [
        "nav1d-classifier/seed-2", "nav1d-far/seed-2", "nav1d-near/seed-2", "nav1d-system/seed-2",
        "legged-walker/seed-2", "categorical-perception/seed-2", "double-pole/seed-2"]
    with pytest.raises(ConfigError, match="did you mean 'sequence-2bit'"):
        plan.jobs([0], only=["sequence-2bt"])
    with pytest.raises(ConfigError, match="distinct"):
        plan.jobs([1, 1])


def test_settings_refuse_bad_values_and_name_them() -> None:
    with pytest.raises(ConfigError, match="eval_trials"):
        jobs.Settings(eval_trials=0)
    with pytest.raises(ConfigError, match="environments"):
        jobs.Settings(environments=-1)
    with pytest.raises(ConfigError, match="population"):
        jobs.Settings(overrides=("population=-3",)).config(plan.experiment("sequence-1bit"))


def test_a_job_done_twice_is_done_once(tmp_path: Path) -> None:
    job = plan.Job("sequence-1bit", 0, ())
    first = jobs.run_job(job, tmp_path, QUICK, 1)
    stamp = jobs.result_path(tmp_path, job).stat().st_mtime_ns
    assert jobs.run_job(job, tmp_path, QUICK, 1) == first
    assert jobs.result_path(tmp_path, job).stat().st_mtime_ns == stamp
    # Other settings do not take a finished job's result for theirs.
    with pytest.raises(RunFileError, match="eval_trials"):
        jobs.read_result(tmp_path, job, jobs.Settings(quick=True, eval_trials=11, dt_check=False))


@pytest.mark.parametrize("damage", ["{", "[]", '{"job": "sequence-1bit/seed-0"}', "truncate"])
def test_a_damaged_result_is_named_not_trusted(tmp_path: Path, damage: str) -> None:
    job = plan.Job("sequence-1bit", 0, ())
    jobs.run_job(job, tmp_path, QUICK, 1)
    path = jobs.result_path(tmp_path, job)
    text = path.read_text()
    path.write_text(text[: len(text) // 2] if damage == "truncate" else damage)
    with pytest.raises(RunFileError, match=re.escape(str(path))):
        jobs.read_result(tmp_path, job, QUICK)


def test_a_tampered_result_is_refused(tmp_path: Path) -> None:
    job = plan.Job("sequence-1bit", 0, ())
    jobs.run_job(job, tmp_path, QUICK, 1)
    path = jobs.result_path(tmp_path, job)
    data = json.loads(path.read_text())
    data["run"]["final"]["rates"][0]["k"] = 10**6
    path.write_text(json.dumps(data))
    with pytest.raises(RunFileError, match="not a valid job result"):
        jobs.read_result(tmp_path, job, QUICK)


@pytest.mark.parametrize(("experiment", "needs", "edit"), [
    ("landmark-robot", ("landmark",), lambda d: d["assessment"].pop("confusion")),
    ("landmark-robot", ("landmark",), lambda d: d["assessment"].update(confusion=[[1, 2]])),
    ("landmark-worlds", ("landmark",), lambda d: d["worlds"]["sonar"].update(right=21)),
    ("landmark-worlds", ("landmark",), lambda d: d["worlds"]["training"].update({"observer, other worlds": 3})),
    ("landmark-worlds", ("landmark",), lambda d: d["worlds"].pop("room")),
    ("landmark-worlds", ("landmark",), lambda d: d.update(test_seed=7)),
    ("landmark-worlds", ("landmark",), lambda d: d.update(trials=11)),
    ("nav1d-system", ("nav1d-classifier", "nav1d-far", "nav1d-near"), lambda d: d.pop("wall_s")),
    ("nav1d-system", ("nav1d-classifier", "nav1d-far", "nav1d-near"), lambda d: d.update(wall_s="abc")),
    ("nav1d-system", ("nav1d-classifier", "nav1d-far", "nav1d-near"),
     lambda d: d.update(goal_rate_by_trial={})),
    ("nav1d-system", ("nav1d-classifier", "nav1d-far", "nav1d-near"), lambda d: d.update(goal_interval=[0.1])),
    ("reactive-navigation-hand", (), lambda d: d["worlds"]["u-trap"]["with"].update(arrived=11)),
    ("reactive-navigation-hand", (), lambda d: d["worlds"]["u-trap"]["with"].update(arrived=-1)),
    ("reactive-navigation-hand", (), lambda d: d["worlds"]["u-trap"]["with"].update(arrived=3.0)),
    ("reactive-navigation-hand", (), lambda d: d["worlds"]["u-trap"]["with"].update(arrived=True)),
    ("reactive-navigation-hand", (), lambda d: d["worlds"]["u-trap"]["without"].update(starts=9)),
    ("reactive-navigation-hand", (), lambda d: d["worlds"]["open-room"].pop("without")),
    ("reactive-navigation-hand", (), lambda d: d["worlds"]["open-room"].update(sometimes={})),
    ("reactive-navigation-hand", (), lambda d: d["worlds"].pop("cul-de-sac")),
    ("reactive-navigation-hand", (), lambda d: d.update(worlds=[])),
    ("reactive-navigation-hand", (), lambda d: d.update(starts=20)),
    ("reactive-navigation-hand", (), lambda d: d.update(seed=d["seed"] + 1)),
    ("reactive-navigation-hand", (), lambda d: d.update(steps="1200")),
    ("reactive-navigation-hand", (), lambda d: d.update(steps=600)),  # trials of another length
])
def test_a_result_of_the_wrong_shape_is_named(tmp_path: Path, experiment: str, needs: tuple[str, ...],
                                              edit: Any) -> None:
    for name in needs:
        jobs.run_job(plan.Job(name, 0, ()), tmp_path, QUICK, 1)
    job = plan.Job(experiment, 0, tuple(f"{n}/seed-0" for n in needs))
    data = jobs.run_job(job, tmp_path, QUICK, 1)
    edit(data)
    jobs.result_path(tmp_path, job).write_text(json.dumps(data))
    with pytest.raises(RunFileError, match="not a valid job result"):
        jobs.read_result(tmp_path, job, QUICK)


def test_the_held_out_worlds_job_judges_each_world_is_checked_and_renders(tmp_path: Path) -> None:
    from dnnevo.experiments.scheduler import Outcome, Task
    from dnnevo.tasks import landmark_transfer

    landmark = plan.Job("landmark", 0, ())
    worlds = plan.Job("landmark-worlds", 0, ("landmark/seed-0",))
    done = jobs.run_job(landmark, tmp_path, QUICK, 1)
    t0 = time.perf_counter()
    found = jobs.run_job(worlds, tmp_path, QUICK, 1)
    assert time.perf_counter() - t0 < 10  # quick reproductions stay quick
    assert jobs.read_result(tmp_path, worlds, QUICK) == found
    # A result judged in worlds that have changed since is done again.
    real = landmark_transfer.worlds_digest
    with pytest.MonkeyPatch.context() as m:
        m.setattr(landmark_transfer, "worlds_digest", lambda s: "0" * 64 if s == "first" else real(s))
        assert jobs.read_result(tmp_path, worlds, QUICK) is None
    # The library's figures for the champion, on the example's trials (10 per landmark here).
    run = RunDir(tmp_path / landmark.id)
    config, table = run.read_config()
    net = run.read_best(config, table)
    places = [landmark_transfer.place(p) for p in jobs.world_places()]
    right = landmark_transfer.judge(config, net, 10, places)
    bounds = landmark_transfer.bounds(config, net, 10, 10, places)
    assert found["trials"] == found["fit_trials"] == 10 and found["test_seed"] == landmark_transfer.TEST_SEED
    for p in jobs.world_places():
        assert found["worlds"][p] == {"right": right[p], "one answer": right[f"{p} one answer"], **bounds[p]}
    # A damaged field is one line naming it.
    path = jobs.result_path(tmp_path, worlds)
    path.write_text(json.dumps({**found, "worlds": {**found["worlds"], "room": {**found["worlds"]["room"],
                                                                                  "observer": -1}}}))
    with pytest.raises(RunFileError, match=r"worlds\.room\.observer is -1") as e:
        jobs.read_result(tmp_path, worlds, QUICK)
    assert "\n" not in str(e.value)
    # It renders: the summary counts seeds meeting the goal everywhere, the table world by world.
    path.write_text(json.dumps(found))
    order = [landmark, worlds]
    outcomes = {j.id: Outcome(Task(j.id, j.needs, jobs.run_job), "done", r) for j, r in zip(order, [done, found])}
    row = report.summary_row(plan.experiment("landmark-worlds"), order, outcomes)
    assert row[1].endswith("the held-out worlds are not in the paper") and row[2] == "1/1"
    assert re.fullmatch(r"seeds right in >85% with the interval's lower end >80% in every held-out world: "
                        r"[01]/1 \(.*\)", row[4])
    block = report.seed_table(plan.experiment("landmark-worlds"), order, outcomes)
    assert block is not None and block.rows[0][1:5] == ("training: right (95% interval)",
                                                        "follower (held out): right (95% interval)",
                                                        "sonar (held out): right (95% interval)",
                                                        "room (held out): right (95% interval)")
    n = 2 * 10
    assert block.rows[1][2].startswith(f"{found['worlds']['follower']['right']}/{n} (")
    assert "10 trials per landmark per world, seed 47002" in block.rows[1][7]
    # A test in the second set of worlds judges there, and its table names them.
    shutil.copytree(tmp_path / landmark.id, tmp_path / "landmark-robust" / "seed-0")
    second = plan.Job("landmark-robust-second-worlds", 0, ("landmark-robust/seed-0",))
    found = jobs.run_job(second, tmp_path, QUICK, 1)
    assert tuple(found["worlds"]) == jobs.world_places("second") == ("training", "weaving", "lobe", "boxes")
    assert found["worlds"]["training"]["right"] == jobs.read_result(tmp_path, worlds, QUICK)["worlds"]["training"]["right"]
    with pytest.raises(ValueError, match="expected the places training, follower, sonar, room"):
        jobs.world_counts(found)
    order = [landmark, second]
    outcomes = {j.id: Outcome(Task(j.id, j.needs, jobs.run_job), "done", r) for j, r in zip(order, [done, found])}
    block = report.seed_table(plan.experiment(second.experiment), order, outcomes)
    assert block is not None and block.rows[0][2] == "weaving (held out): right (95% interval)"


def test_a_result_is_not_trusted_when_its_runs_changed(tmp_path: Path) -> None:
    landmark, robot = plan.Job("landmark", 0, ()), plan.Job("landmark-robot", 0, ("landmark/seed-0",))
    first = jobs.run_job(landmark, tmp_path, QUICK, 1)
    robot_first = jobs.run_job(robot, tmp_path, QUICK, 1)
    # A deleted run folder: its result and the test of its champion no longer count, and the run
    # is made afresh, to the same bits.
    shutil.rmtree(tmp_path / landmark.id)
    assert jobs.read_result(tmp_path, landmark, QUICK) is None
    assert jobs.read_result(tmp_path, robot, QUICK) is None
    assert without_wall(jobs.run_job(landmark, tmp_path, QUICK, 1)) == without_wall(first)
    # Its champion is the same bits again, so the test of it counts again, as it was.
    again = jobs.read_result(tmp_path, robot, QUICK)
    assert again is not None and without_wall(again) == without_wall(robot_first)
    # A run extended by hand is no longer the reproduction's run: named, not silently used.
    dnnevo.resume(tmp_path / landmark.id, generations=8, progress=False)
    assert jobs.read_result(tmp_path, landmark, QUICK) is None
    with pytest.raises(RunFileError, match="generations is 8"):
        jobs.run_job(landmark, tmp_path, QUICK, 1)


def test_a_stopped_run_resumes_to_the_bits_of_an_unstopped_one(tmp_path: Path) -> None:
    settings = jobs.Settings(quick=True, eval_trials=10, dt_check=False, overrides=("generations=12",))
    job = plan.Job("sequence-2bit-alternating", 4, ())
    whole = jobs.run_job(job, tmp_path / "whole", settings, 1)
    # The same job stopped after generation 5: its folder has a checkpoint and no result.
    config = settings.config(job.spec)
    out = tmp_path / "parts" / job.id
    dnnevo.evolve(config.task, config, seed=4, out=out, progress=False, callback=lambda stats, ga: ga.generation >= 5)
    assert jobs.read_result(tmp_path / "parts", job, settings) is None
    resumed = jobs.run_job(job, tmp_path / "parts", settings, 2)
    assert without_wall(resumed) == without_wall(whole)
    same_run(tmp_path / "whole" / job.id, out)


@pytest.mark.slow
def test_a_composed_run_uses_the_runs_it_needs(tmp_path: Path) -> None:
    order = plan.jobs([0], only=["sequence"])[:3]
    for job in order:
        jobs.run_job(job, tmp_path, QUICK, 1)
    table = (tmp_path / "sequence-2bit-paper" / "seed-0" / "config.toml").read_text()
    assert "sequence-1bit/seed-0" in table and "sequence-2bit-alternating/seed-0" in table
    # The 16-neuron incremental route composes whole populations and 6 spare neurons.
    job = next(j for j in plan.jobs([0], only=["sequence"]) if j.experiment == "sequence-2bit")
    jobs.run_job(job, tmp_path, QUICK, 1)
    table = (tmp_path / job.id / "config.toml").read_text()
    assert 'seeded_with = "populations"' in table and "spare_neurons = 6" in table


def test_the_report_says_the_same_in_markdown_and_html(tmp_path: Path) -> None:
    from dnnevo.experiments.scheduler import Outcome, Task

    order = [j for j in plan.jobs([0, 1], only=["landmark"]) if j.experiment in ("landmark", "landmark-robot")]
    tasks = {j.id: Task(j.id, j.needs, jobs.run_job) for j in order}
    outcomes = {j.id: Outcome(tasks[j.id], "done", jobs.run_job(j, tmp_path, QUICK, 1)) for j in order[:3]}
    outcomes[order[3].id] = Outcome(tasks[order[3].id], "failed", message="a worker died")
    env = report.environment(workers="none", threads=1, wall_s=1.0)
    blocks = report.build(tmp_path, order, outcomes, settings=QUICK, environment=env, command="dnnevo reproduce")
    md, page = report.markdown(blocks), report.to_html(blocks, tmp_path)
    assert "| landmark | §3: solved by generation 15 in simulation | 2/2 |" in md
    assert "| landmark-robot | §3: the real robot right in 17 of 20 trials (10/10 and 7/10) | 1/2 |" in md
    assert "a worker died" in md and "a worker died" in page
    images = re.findall(r'<img [^>]*src="([^"]+)"', page)
    assert images and all(src.startswith("data:image/png;base64,") for src in images)
    assert len(images) == md.count("![")
    assert env["SIMD kernel"].split()[0] == dnnevo.build_info()["kernel"]


@pytest.mark.slow
def test_reproduce_in_process_resumes_and_refuses_other_settings(tmp_path: Path) -> None:
    out = tmp_path / "repro"
    args = ["reproduce", "--only", "nav1d", "--seeds", "0", "--quick", "--eval-trials", "10",
            "--no-dt-check", "--in-process", "--out", out]
    r = run_cli(*args)
    assert r.returncode == 0, r.stderr
    n = len(plan.jobs([0], only=["nav1d"]))
    assert f"{n} runs in" in r.stdout and "(0 already done)" in r.stdout
    for name in report.REPORT_FILES:
        assert (out / name).stat().st_size > 1000
    md = (out / "report.md").read_text()
    assert "| nav1d-single | §4.2: failed (not quantified) | 1/1 |" in md
    assert "nav1d-system" in md and "| landmark |" not in md.split("## Environment")[0]
    assert "![" in md
    # Every run done: the report is made again, here without its figures.
    again = run_cli(*args, "--no-figures")
    assert again.returncode == 0 and f"({n} already done)" in again.stdout, again.stderr
    md = (out / "report.md").read_text()
    assert "![" not in md and "--no-dt-check --no-figures" in md
    assert "| nav1d-single | §4.2: failed (not quantified) | 1/1 |" in md
    other = run_cli(*[a if a != "10" else "11" for a in args])
    assert_one_line_error(other, "eval_trials", "= 10, not 11")


def test_without_only_the_paper_is_reproduced_and_the_classic_tasks_are_a_family() -> None:
    assert {j.spec.family for j in plan.jobs([0])} == set(plan.PAPER_FAMILIES)
    classic = plan.jobs([0], only=["classic"])
    assert {j.experiment for j in classic} == {"legged-walker", "categorical-perception", "double-pole"}
    assert all(QUICK.config(j.spec).task.startswith("python:dnnevo.classic.") for j in classic)


def _flat(d: dict[str, Any], head: str = "") -> dict[str, Any]:
    """A config dict with its tables' keys written ``table.key``."""
    out: dict[str, Any] = {}
    for k, v in d.items():
        out.update(_flat(v, f"{head}{k}.") if isinstance(v, dict) else {f"{head}{k}": v})
    return out


def test_the_ablation_removes_one_departure_of_the_working_2bit_route_at_a_time() -> None:
    base = plan.experiment("sequence-2bit")
    ablation = [e for e in plan.EXPERIMENTS if e.family == "ablation"]
    assert "ablation" in plan.FAMILIES and "ablation" not in plan.PAPER_FAMILIES
    want = _flat(jobs.Settings().config(base).to_dict())
    seeding = ("seed_populations", "spare_neurons")
    changes = {}
    for e in ablation:
        assert (e.kind, e.preset, e.needs) == (plan.EVOLVE, base.preset, base.needs)
        assert e.note.startswith("the working route, sequence-2bit, without ") and e.paper == "not in the paper"
        config = _flat(jobs.Settings().config(e).to_dict())
        assert config.keys() == want.keys()
        changes[e.name] = {**{k: v for k, v in config.items() if v != want[k]},
                           **{k: getattr(e, k) for k in seeding if getattr(e, k) != getattr(base, k)}}
    assert changes == {
        "ablation-2bit-no-spare": {"size": 10, "spare_neurons": 0},
        "ablation-2bit-clamp-trial": {"task_params.clamp": "trial"},
        "ablation-2bit-proportional": {"selection": "proportional"},
        "ablation-2bit-no-elites": {"elitism": 0},
        "ablation-2bit-validation-32": {"task_params.validation_trials": 32},
        "ablation-2bit-champions": {"seed_populations": False},
        "ablation-2bit-smallest": {"selection": "proportional", "task_params.validation_trials": 32},
    }
    assert (base.seed_populations, base.spare_neurons, want["task_params.clamp"]) == (True, 6, "evaluation")


def test_the_precision_family_runs_its_experiments_again_in_f32_and_nothing_else() -> None:
    single = [e for e in plan.EXPERIMENTS if e.family == "precision"]
    assert "precision" in plan.FAMILIES and "precision" not in results.REFERENCE_FAMILIES
    evolved = [e for e in single if e.kind == plan.EVOLVE]
    assert [e.name for e in evolved] == [f"{n}-f32" for n in ("landmark", "nav1d-classifier", "nav1d-far",
                                                              "nav1d-near", "sequence-1bit", "sequence-3bit")]
    for e in evolved:
        f64 = plan.experiment(e.name.removesuffix("-f32"))
        config, reference = (_flat(jobs.Settings().config(x).to_dict()) for x in (e, f64))
        assert {k: v for k, v in config.items() if v != reference[k]} == {"precision": "f32"}, e.name
        assert (e.needs, f64.needs, reference["precision"]) == ((), (), "f64")
    system = plan.experiment("nav1d-system-f32")
    assert system.kind == plan.SYSTEM
    assert system.needs == tuple(f"{n}-f32" for n in plan.experiment("nav1d-system").needs)


@pytest.mark.slow
def test_the_precision_family_runs_in_f32_and_its_system_composes_f32_parts(tmp_path: Path) -> None:
    out = tmp_path / "f32"
    r = run_cli("reproduce", "--only", "precision", "--seeds", "0", "--quick", "--in-process", "--no-figures",
                "--out", out)
    assert r.returncode == 0, r.stderr
    order = plan.jobs([0], only=["precision"])
    for job in order:
        if job.spec.kind == plan.EVOLVE:
            assert 'precision = "f32"' in (out / job.id / "config.toml").read_text(), job.id
        assert f"| {job.experiment} | not in the paper | 1/1 |" in r.stdout
    system = json.loads((out / "nav1d-system-f32/seed-0.json").read_text())
    assert system["inputs"].keys() == {f"{n}/seed-0/best.json" for n in plan.experiment("nav1d-system-f32").needs}


@pytest.mark.slow
def test_the_ablation_runs_the_sequence_runs_it_composes_or_uses_them_and_collects_its_own(tmp_path: Path) -> None:
    """``--only ablation`` plans the same seed's 1-bit and alternating jobs (of the sequence family)
    before its own, runs them in a folder without them and uses them in one with them. Shortened
    by --set: the quick variants' 128 validation trials per target take a minute or more."""
    order = plan.jobs([0], only=["ablation"])
    parents = order[:2]
    assert [j.id for j in parents] == ["sequence-1bit/seed-0", "sequence-2bit-alternating/seed-0"]
    assert all(j.spec.family == "ablation" and j.needs == tuple(p.id for p in parents) for j in order[2:])
    variants = len(order) - 2
    assert variants == 7
    out = tmp_path / "repro"
    args = ["reproduce", "--only", "ablation", "--seeds", "0", "--quick", "--set", "generations=2",
            "--set", "task_params.validation_trials=4", "--eval-trials", "10", "--no-dt-check", "--in-process",
            "--no-figures", "--out", out]
    r = run_cli(*args)
    assert r.returncode == 0, r.stderr
    assert f"{len(order)} runs in" in r.stdout and "(0 already done)" in r.stdout
    for job in order[2:]:
        run = (out / job.id / "config.toml").read_text()
        assert "sequence-1bit/seed-0" in run and "sequence-2bit-alternating/seed-0" in run
        e = job.spec
        assert f'seeded_with = "{"populations" if e.seed_populations else "champions"}"' in run
        assert ("spare_neurons = 6" in run) == (e.spare_neurons == 6)
    md = (out / "report.md").read_text()
    assert all(f"| {j.experiment} | " in md for j in order)
    # Another command in this folder finds every job done, the parents too, whichever family's
    # command made them: it uses them as they are, without work (one more command would make
    # the report again, for no more than this).
    settings = jobs.Settings(**json.loads((out / "reproduce.json").read_text())["settings"])
    stamps = {j.id: jobs.result_path(out, j).stat().st_mtime_ns for j in parents}
    assert all(jobs.read_result(out, j, settings) is not None for j in order)
    for job in parents:
        jobs.run_job(job, out, settings, 1)
    assert {j.id: jobs.result_path(out, j).stat().st_mtime_ns for j in parents} == stamps
    # Collected as a family, the ablation takes its own runs; the parents belong to the sequence
    # family's collection. Its rows are rendered from them.
    stored = tmp_path / "repo" / "docs" / "results"
    copied = results.collect(out, stored, families=["ablation"], seeds=[0], commit="abc1234")
    assert copied == [j.id for j in order[2:]]
    family = json.loads((stored / results.PROVENANCE_FILE).read_text())["families"]
    assert list(family) == ["ablation"] and family["ablation"]["runs"] == family["ablation"]["planned"] == variants
    page = stored.parent / "sequence.md"
    page.write_text("<!-- results:summary:ablation:begin -->\n<!-- results:summary:ablation:end -->\n")
    assert results.render(stored.parent.parent) == [page]
    text = page.read_text()
    assert all(f"| {j.experiment} | not in the paper | 1/1 |" in text for j in order[2:])
    assert "| sequence-1bit |" not in text and f"{variants} of {variants} runs done" in text


@pytest.mark.slow
def test_experiments_added_since_a_reproduction_began_join_it(tmp_path: Path) -> None:
    out = tmp_path / "repro"
    args = ["reproduce", "--only", "classic", "--seeds", "0", "--quick", "--eval-trials", "10",
            "--no-dt-check", "--in-process", "--no-figures", "--out", out]
    assert run_cli(*args).returncode == 0
    manifest = out / "reproduce.json"
    full = json.loads(manifest.read_text())
    # Only the configs of the experiments the command ran are recorded ...
    assert sorted(full["configs"]) == sorted(e.name for e in plan.EXPERIMENTS if e.family == "classic")
    # ... and checked: another family's recorded config, even one that differs, refuses nothing.
    other = {**full, "configs": {**full["configs"], "sequence-1bit": {"population": 7}}}
    manifest.write_text(json.dumps(other))
    again = run_cli(*args)
    assert again.returncode == 0 and "(3 already done)" in again.stdout, again.stderr
    assert json.loads(manifest.read_text()) == other
    # A folder begun before an experiment existed has no config for it: it is added.
    shutil.rmtree(out / "double-pole")
    manifest.write_text(json.dumps({**full, "configs": {k: v for k, v in full["configs"].items()
                                                          if k != "double-pole"}}))
    again = run_cli(*args)
    assert again.returncode == 0 and "(2 already done)" in again.stdout, again.stderr
    assert json.loads(manifest.read_text()) == full
    # An experiment with runs in the folder but no recorded config is no addition: refused.
    manifest.write_text(json.dumps({**full, "configs": {}}))
    before = manifest.read_bytes()
    assert_one_line_error(run_cli(*args), "has no config for", "holds its runs")
    assert manifest.read_bytes() == before
    # A recorded experiment whose config differs is refused, and the folder is left as it was.
    walker = {**full["configs"]["legged-walker"], "population": 7}
    manifest.write_text(json.dumps({**full, "configs": {**full["configs"], "legged-walker": walker}}))
    before = manifest.read_bytes()
    assert_one_line_error(run_cli(*args), "configs.legged-walker.population")
    assert manifest.read_bytes() == before


#: The command, checkpointing every generation, with Ctrl-C's default handler (a test's
#: background process may start with SIGINT ignored).
FREQUENT = ("import signal, sys, dnnevo; signal.signal(signal.SIGINT, signal.default_int_handler); "
            "sys.modules['dnnevo.evolution.evolve'].CHECKPOINT_SECONDS = 0.0; "
            "from dnnevo.cli.command import main; sys.exit(main(sys.argv[1:]))")


@pytest.mark.slow
def test_ctrl_c_stops_a_reproduction_that_then_continues_to_the_same_results(tmp_path: Path) -> None:
    args = ["reproduce", "--only", "landmark", "--seeds", "0", "--quick", "--set", "generations=60",
            "--eval-trials", "10", "--no-dt-check", "--in-process", "--threads-per-worker", "1", "--no-figures"]
    stopped = tmp_path / "stopped"
    proc = subprocess.Popen([sys.executable, "-c", FREQUENT, *args, "--out", str(stopped)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    checkpoint = stopped / "landmark" / "seed-0" / "checkpoint.json"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not _at_generation(checkpoint, 3):
        time.sleep(0.02)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (out, err)
    assert "run the same command again to continue" in err and "Traceback" not in err
    settings = jobs.Settings(quick=True, eval_trials=10, dt_check=False, overrides=("generations=60",))
    assert jobs.read_result(stopped, plan.Job("landmark", 0, ()), settings) is None
    again = run_cli(*args, "--out", stopped)
    assert again.returncode == 0 and "(0 already done)" in again.stdout, again.stderr
    # The stopped run and the tests of its champion, run by run without the command's report (the
    # family's other runs began after the stop, as any run does).
    whole = tmp_path / "whole"
    for job in plan.jobs([0], only=["landmark"]):
        if job.experiment in ("landmark", "landmark-robot", "landmark-worlds"):
            jobs.run_job(job, whole, settings, 1)
            a, b = (json.loads(jobs.result_path(root, job).read_text()) for root in (stopped, whole))
            assert without_wall(a) == without_wall(b), job.id
    same_run(stopped / "landmark" / "seed-0", whole / "landmark" / "seed-0")


def test_reproduce_names_bad_input_in_one_line(tmp_path: Path) -> None:
    assert_one_line_error(run_cli("reproduce", "--only", "vision", "--out", tmp_path), "families are")
    assert_one_line_error(run_cli("reproduce", "--seeds", "0-100000000", "--out", tmp_path), "seeds go from 0 to")
    assert_one_line_error(run_cli("reproduce", "--seeds", "3,3", "--out", tmp_path), "listed twice")
    assert_one_line_error(run_cli("reproduce", "--workers", "2", "--scheduler", "tcp://h:1", "--out",
                                  tmp_path / "c"), "--workers sizes the local cluster")
    assert not (tmp_path / "c").exists()
    assert_one_line_error(run_cli("reproduce", "--set", "population=0", "--in-process", "--out", tmp_path / "a"),
                          "population")
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "notes.txt").write_text("mine")
    assert_one_line_error(run_cli("reproduce", "--in-process", "--out", tmp_path / "b"), "reproduce.json")


def dask() -> Any:
    """Dask's distributed, or a skip for the test that needs it."""
    return pytest.importorskip("distributed")


@pytest.mark.slow
def test_the_whole_quick_reproduction_on_a_local_cluster_matches_in_process(tmp_path: Path) -> None:
    dask()
    # Every family, the classic benchmarks (tasks written in Python) too, but the ablation and the
    # precision family: their runs are other families' with one setting changed (tests of their own
    # run them), and here they would double this test's time.
    families = [f for f in plan.FAMILIES if f not in ("ablation", plan.PRECISION_FAMILY)]
    args = ["reproduce", "--seeds", "0", "--quick", "--eval-trials", "10", "--no-dt-check",
            "--only", ",".join(families)]
    r = run_cli(*args, "--workers", "2", "--out", tmp_path / "dask")
    assert r.returncode == 0, r.stderr
    assert "a local Dask cluster of 2 workers" in r.stdout
    experiments = [e for e in plan.EXPERIMENTS if e.family in families]
    n = len(experiments)
    assert f"[{n}/{n}] done" in r.stderr  # not a terminal: one line per run
    # The same bits in this process, run by run, for one experiment of each kind (an evolution
    # seeded from another run's champion, tests of evolved champions, an integrated system, a
    # hand-designed controller, a task written in Python) and the runs they need: all of them
    # would double this test's time.
    names = {"nav1d-single-incremental", "landmark-robot", "landmark-worlds", "reactive-navigation-hand",
             "nav1d-system", "double-pole"}
    for e in reversed(plan.EXPERIMENTS):  # with the runs they need, and the runs those need
        if e.name in names:
            names.update(e.needs)
    compared = [job for job in plan.jobs([0], only=families) if job.experiment in names]
    assert {job.spec.kind for job in compared} == {e.kind for e in experiments}
    for job in compared:
        jobs.run_job(job, tmp_path / "here", QUICK, 1)
        here, there = (json.loads(jobs.result_path(tmp_path / d, job).read_text()) for d in ("here", "dask"))
        assert without_wall(here) == without_wall(there), job.id
    md = (tmp_path / "dask" / "report.md").read_text()
    for e in experiments:
        assert f"| {e.name} | {e.paper} | 1/1 |" in md
    for figure in ("fig1-traces.png", "world.png", "fig2-paths.png", "fig3-classifier.png", "fig4-trials.png",
                   "fig5-switch.png", "fig2-system.png"):
        assert figure in md, figure


@pytest.mark.slow
def test_a_running_scheduler_takes_the_runs(tmp_path: Path) -> None:
    with dask().LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        r = run_cli("reproduce", "--only", "landmark", "--seeds", "0", "--quick", "--eval-trials", "10",
                    "--no-dt-check", "--no-figures", "--scheduler", cluster.scheduler_address, "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    assert f"on {cluster.scheduler_address}" in r.stdout
    robot = plan.Job("landmark-robot", 0, ("landmark/seed-0",))
    on_cluster = jobs.read_result(tmp_path, robot, QUICK)
    # The same bits as in this process.
    jobs.run_job(plan.Job("landmark", 0, ()), tmp_path / "here", QUICK, 1)
    here = jobs.run_job(robot, tmp_path / "here", QUICK, 1)
    assert on_cluster is not None and without_wall(on_cluster) == without_wall(here)


@pytest.mark.slow
def test_a_killed_worker_s_run_resumes_to_the_same_bits(tmp_path: Path) -> None:
    dask()
    settings = jobs.Settings(quick=True, eval_trials=10, dt_check=False,
                             overrides=("population=200", "generations=100"))
    job = plan.Job("sequence-1bit", 0, ())
    checkpoint = tmp_path / "dask" / job.id / "checkpoint.json"
    with scheduler.dask_client(workers=1, scheduler=None) as client:
        pids = list(client.run(os.getpid).values())
        # A checkpoint every generation on this worker (every 10 s otherwise), so it dies mid-run.
        client.run(exec, "import sys, dnnevo; sys.modules['dnnevo.evolution.evolve'].CHECKPOINT_SECONDS = 0.0")
        future = client.submit(jobs.run_job, job, str(tmp_path / "dask"), settings, 1, pure=False)
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not _at_generation(checkpoint, 3):
            time.sleep(0.01)
        for pid in pids:
            os.kill(pid, signal.SIGKILL)
        killed_at = len(json.loads(checkpoint.read_text())["history"])
        assert 3 <= killed_at < 100, killed_at
        result = future.result(timeout=300)
    whole = jobs.run_job(job, tmp_path / "here", settings, 1)
    assert without_wall(result) == without_wall(whole)
    same_run(tmp_path / "here" / job.id, tmp_path / "dask" / job.id)


def _at_generation(checkpoint: Path, generation: int) -> bool:
    try:
        return len(json.loads(checkpoint.read_text())["history"]) >= generation
    except (OSError, ValueError, KeyError):
        return False


# A reproduction that kills itself (SIGKILL) while it writes NAME's temporary file, half of it
# written: what a kill at the worst moment of the report's write leaves behind.
KILLED_IN_WRITE = """
import os, signal, sys
from dnnevo.cli.command import main
from dnnevo.runs import files
real = files.write_atomic_with
def write_atomic_with(path, write, **kwargs):
    def half_then_die(tmp):
        with open(tmp, "w") as f:
            f.write("# half a rep")
        os.kill(os.getpid(), signal.SIGKILL)
    return real(path, half_then_die if path.name == sys.argv[1] else write, **kwargs)
files.write_atomic_with = write_atomic_with
main(sys.argv[2:])
"""


def _whole_report(name: str, text: bytes) -> bool:
    """A report file written to its end (its wall times change from run to run)."""
    return text.startswith(b"# dnnevo") and b"| experiment |" in text if name.endswith(".md") else \
        text.startswith(b"<!DOCTYPE html>") and text.endswith(b"</html>\n")


@pytest.mark.slow
def test_a_kill_inside_the_report_s_write_leaves_the_old_report_and_the_next_run_tidies(tmp_path: Path) -> None:
    name = report.REPORT_FILES[-1]  # killed in the last write: the files before it are new
    args = ["reproduce", "--only", "classic", "--seeds", "0", "--quick", "--eval-trials", "10",
            "--no-dt-check", "--in-process", "--no-figures", "--out", str(tmp_path)]
    assert run_cli(*args).returncode == 0
    old = {n: f"an older {n}\n".encode() for n in report.REPORT_FILES}
    for n, text in old.items():
        (tmp_path / n).write_bytes(text)
    killed = subprocess.run([sys.executable, "-c", KILLED_IN_WRITE, name, *args], capture_output=True)
    assert killed.returncode == -signal.SIGKILL
    # The file being written is still the old one, whole; a file written before it is new, whole.
    written_before = report.REPORT_FILES[:report.REPORT_FILES.index(name)]
    for n in report.REPORT_FILES:
        text = (tmp_path / n).read_bytes()
        assert _whole_report(n, text) if n in written_before else text == old[n], n
    assert [p.name for p in tmp_path.glob(f".{name}.*")] != []  # the half-written temporary file
    # The same command finishes the report, and leaves no temporary file behind.
    assert run_cli(*args).returncode == 0
    assert all(_whole_report(n, (tmp_path / n).read_bytes()) for n in report.REPORT_FILES)
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == [".dnnevo.lock"]


def test_the_hand_designed_job_counts_what_the_navigation_function_does(tmp_path: Path) -> None:
    """The paper's own reactive navigation is a job: the shipped network on the fresh starts of
    the job's seed, in every world, with and without the detectors, counted as
    :func:`dnnevo.robots.navigation.hand_designed` counts them."""
    from dnnevo.experiments import sweep
    from dnnevo.robots import navigation

    assert (jobs.Settings().starts(), jobs.Settings(quick=True).starts()) == (jobs.HAND_STARTS, jobs.HAND_QUICK_STARTS)
    assert jobs.Settings(quick=True, eval_trials=7).starts() == 7 == jobs.Settings(eval_trials=7).starts()
    names = [e.name for e in plan.EXPERIMENTS if e.family == "robots"]
    assert names.index("reactive-navigation-hand") < names.index("reactive-navigation")
    job = next(j for j in plan.jobs([2], only=["robots"]) if j.spec.kind == plan.HAND_DESIGNED)
    assert job.id == "reactive-navigation-hand/seed-2" and job.needs == ()
    result = jobs.run_job(job, tmp_path, QUICK, 1)
    seed = sweep.eval_seed(2, QUICK.eval_seed)
    assert (result["seed"], result["starts"], result["steps"]) == (seed, 10, 1200)
    for world in navigation.WORLDS:
        for condition, detectors in (("with", True), ("without", False)):
            direct = navigation.hand_designed(world, 10, seed=seed, detectors=detectors)
            assert result["worlds"][world][condition] == {"arrived": direct["arrived"], "starts": 10}, world
    assert jobs.read_result(tmp_path, job, QUICK) == result
    # Its inputs are the shipped network and worlds: a result made with others is done again.
    stale = {**result, "inputs": {**result["inputs"], "dnnevo/robots/data/navigator.json": "0" * 64}}
    jobs.result_path(tmp_path, job).write_text(json.dumps(stale))
    assert jobs.read_result(tmp_path, job, QUICK) is None


def test_the_quick_robots_reproduction_has_the_papers_reactive_navigation_row(tmp_path: Path) -> None:
    r = run_cli("reproduce", "--only", "robots", "--seeds", "0", "--quick", "--no-dt-check", "--in-process",
                "--no-figures", "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    md = (tmp_path / "report.md").read_text()
    e = plan.experiment("reactive-navigation-hand")
    row = next(line for line in md.splitlines() if line.startswith(f"| {e.name} | {e.paper} | 1/1 | - | "))
    assert "goal reached with / without detectors: open-room " in row and "/20 (" in row  # quick: 20 starts
    assert "| seed | open-room: goal reached with / without detectors" in md
    assert md.index("| reactive-navigation-hand |") < md.index("| reactive-navigation |")
    result = json.loads(jobs.result_path(tmp_path, plan.Job(e.name, 0, ())).read_text())
    assert result["starts"] == jobs.HAND_QUICK_STARTS and result["kind"] == plan.HAND_DESIGNED
