"""The results tables are made from docs/results/ alone: collecting a reproduction's results,
rendering the tables between marker lines, ``render --check`` failing on a stale table, and the
repository's own tables being up to date."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from cli_helpers import run_cli, run_main
from dnnevo.errors import DnnevoError
from dnnevo.experiments import jobs, plan, results
from dnnevo.runs import first_difference

ROOT = Path(__file__).resolve().parent.parent
README = "# dnnevo\n\nBefore.\n\n<!-- results-table:begin -->\nold\n<!-- results-table:end -->\n\nAfter.\n"


def _results(*args: object) -> subprocess.CompletedProcess[str]:
    return run_main(results.main, "python -m dnnevo.experiments.results", *args)


@pytest.fixture(scope="module")
def reproduction(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A quick reproduction of the landmark family, seed 0."""
    out = tmp_path_factory.mktemp("repro") / "out"
    r = run_cli("reproduce", "--only", "landmark", "--seeds", "0", "--quick", "--eval-trials", "10",
                "--no-dt-check", "--in-process", "--out", out)
    assert r.returncode == 0, r.stderr
    return out


@pytest.fixture
def repo(tmp_path: Path, reproduction: Path) -> Path:
    """A repository whose docs/results holds the quick reproduction's results, its README and
    results page holding markers, and the reproduction's run folders gone."""
    source = tmp_path / "source"
    shutil.copytree(reproduction, source)
    repo = tmp_path / "repo"
    (repo / "docs" / "results").mkdir(parents=True)
    shutil.copy(ROOT / "docs" / "results" / "index.md", repo / "docs" / "results" / "index.md")
    (repo / "README.md").write_text(README, encoding="utf-8")
    r = _results("collect", source, repo / "docs" / "results", "--seeds", "0", "--commit", "abc1234")
    assert r.returncode == 0, r.stderr
    assert "collected 10 results" in r.stdout
    shutil.rmtree(source)  # the tables need no run folder
    return repo


def test_tables_are_made_from_the_results_alone(repo: Path, reproduction: Path) -> None:
    stored = repo / "docs" / "results"
    assert sorted(p.relative_to(stored).as_posix() for p in stored.rglob("*.json")) == [
        "landmark-robot/seed-0.json", "landmark-robust-robot/seed-0.json",
        "landmark-robust-second-worlds/seed-0.json", "landmark-robust-worlds/seed-0.json",
        "landmark-robust/seed-0.json", "landmark-wide-first-worlds/seed-0.json", "landmark-wide-worlds/seed-0.json",
        "landmark-wide/seed-0.json", "landmark-worlds/seed-0.json", "landmark/seed-0.json", "provenance.json",
        "reproduce.json"]
    provenance = json.loads((stored / "provenance.json").read_text())
    assert provenance["commit"] == "abc1234" and provenance["seeds"] == [0]
    assert provenance["environment"]["SIMD kernel"] and provenance["environment"]["dnnevo"].endswith("(git abc1234)")
    assert provenance["families"]["landmark"]["runs"] == provenance["families"]["landmark"]["planned"] == 10
    assert provenance["families"]["landmark"]["command"] == (
        "dnnevo reproduce --seeds 0 --only landmark --quick --eval-trials 10 --no-dt-check")

    r = _results("render", "--root", repo)
    assert r.returncode == 0, r.stderr
    readme = (repo / "README.md").read_text()
    assert readme.startswith("# dnnevo\n\nBefore.\n\n<!-- results-table:begin -->\n")
    assert readme.endswith("<!-- results-table:end -->\n\nAfter.\n") and "\nold\n" not in readme
    # The rows are the reproduction's own report's rows, made by the same code.
    own = (reproduction / "report.md").read_text()
    for e in (e for e in plan.EXPERIMENTS if e.family == "landmark"):
        row = next(line for line in own.splitlines() if line.startswith(f"| {e.name} | "))
        assert row in readme.splitlines()
    assert "| nav1d-far | §4.2: solved at generation 0 | not yet run | - |" in readme
    assert "| sequence-3bit | §5.4: 1 success, at generation 700 | not yet run |" in readme
    hand = plan.experiment("reactive-navigation-hand")
    assert f"| {hand.name} | {hand.paper} | not yet run | - | - |" in readme
    planned = len(plan.jobs([0], plan.PAPER_FAMILIES))  # the paper's families, seed 0
    assert "commit abc1234" in readme and f"10 of {planned} runs done" in readme and "Quick mode" in readme
    # The README holds the paper's families alone; the results page holds every family. The
    # ablation of the 2-bit route is part of the reference reproduction: its rows say "not yet
    # run". Other families beyond the paper's appear only once their runs are collected.
    assert not any(f"| {e.name} |" in readme for e in plan.EXPERIMENTS if e.family not in plan.PAPER_FAMILIES)
    page = (stored / "index.md").read_text()
    summary = page.split("<!-- results:summary:end -->")[0]
    ablation = [e for e in plan.EXPERIMENTS if e.family == "ablation"]
    assert ablation and all(f"| {e.name} | {e.paper} | not yet run |" in summary for e in ablation)
    assert not any(f"| {e.name} |" in summary for e in plan.EXPERIMENTS if e.family not in results.REFERENCE_FAMILIES)
    every = len(plan.jobs([0], results.REFERENCE_FAMILIES))
    assert f"10 of {every} runs done" in summary

    assert "<!-- results:landmark:begin -->\n\n### landmark\n\nPaper: §3" in page
    assert "| seed | right (95% interval) | confusion" in page
    assert "| seed | training: right (95% interval) | follower (held out): right (95% interval) |" in page
    assert ("### nav1d-far\n\nPaper: §4.2: solved at generation 0. Preset `nav1d-far`.\n\n"
            "Not yet run over seeds 0.") in page
    assert "| landmark | (whole family) | 10/10 |" in page and "| nav1d | (whole family) | not yet run |" in page
    assert "| ablation | (whole family) | not yet run |" in page
    assert "### ablation-2bit-no-spare\n\nPaper: not in the paper. Preset `sequence-2bit` with `size=10`." in page
    assert "| commit | abc1234 |" in page

    assert _results("render", "--root", repo, "--check").returncode == 0
    assert results.render(repo) == []  # rendering again changes nothing


def test_render_only_named_files(repo: Path) -> None:
    readme, page = repo / "README.md", repo / "docs" / "results" / "index.md"
    r = _results("render", "--root", repo, page)
    assert r.returncode == 0 and r.stdout == f"wrote {page}\n", r.stderr
    assert readme.read_text() == README
    assert results.render(repo, check=True) == [readme]


def test_check_fails_on_an_edited_table_and_changes_nothing(repo: Path) -> None:
    assert results.render(repo) == [repo / "README.md", repo / "docs" / "results" / "index.md"]
    readme = repo / "README.md"
    edited = readme.read_text().replace("| landmark | §3: solved by generation 15 in simulation | 1/1 |",
                                        "| landmark | §3: solved by generation 15 in simulation | 9/9 |")
    assert edited != readme.read_text()
    readme.write_text(edited)
    r = _results("render", "--root", repo, "--check")
    assert r.returncode == 1 and r.stdout == ""
    assert r.stderr.strip().splitlines() == [f"{readme}: results tables differ from docs/results; run "
                                             "python -m dnnevo.experiments.results render"]
    assert readme.read_text() == edited
    assert results.render(repo) == [readme] and "| 1/1 |" in readme.read_text()


def test_without_results_every_experiment_is_not_yet_run(tmp_path: Path) -> None:
    (tmp_path / "README.md").write_text(README)
    assert results.render(tmp_path) == [tmp_path / "README.md"]
    text = (tmp_path / "README.md").read_text()
    assert "No results yet in docs/results/" in text
    paper = [e for e in plan.EXPERIMENTS if e.family in plan.PAPER_FAMILIES]
    assert sum(f"| {e.name} | {e.paper} | not yet run |" in text for e in paper) == len(paper)
    assert not any(f"| {e.name} |" in text for e in plan.EXPERIMENTS if e.family not in plan.PAPER_FAMILIES)


def test_bad_markers_and_mixed_reproductions_are_named(tmp_path: Path, repo: Path) -> None:
    page = tmp_path / "docs" / "page.md"
    page.parent.mkdir()
    page.write_text("<!-- results:vision:begin -->\n<!-- results:vision:end -->\n")
    with pytest.raises(DnnevoError, match="unknown results marker 'vision'"):
        results.render(tmp_path)
    page.write_text("<!-- results:landmark:begin -->\n")
    with pytest.raises(DnnevoError, match="page.md: <!-- results:landmark:begin --> has no <!-- results:landmark:end"):
        results.render(tmp_path)
    page.write_text("<!-- results:summary:nav1d:begin -->\n<!-- results:summary:nav1d:end -->\n"
                    "<!-- results:machine:begin -->\n<!-- results:machine:end -->\n")
    assert results.render(tmp_path) == [page] and "| nav1d-far |" in page.read_text()
    assert "| landmark |" not in page.read_text().split("results:machine")[0]

    stored = repo / "docs" / "results"
    original = (stored / "reproduce.json").read_text()
    settings = json.loads(original)
    settings["settings"]["eval_trials"] = 11
    (stored / "reproduce.json").write_text(json.dumps(settings))
    r = _results("render", "--root", repo)
    assert r.returncode == 2 and "made with other settings" in r.stderr and len(r.stderr.splitlines()) == 1
    (stored / "reproduce.json").write_text(original)
    good = (stored / "landmark" / "seed-0.json").read_text()
    broken = json.loads(good)
    del broken["run"]["final"]
    (stored / "landmark" / "seed-0.json").write_text(json.dumps(broken))
    with pytest.raises(DnnevoError, match=r"landmark/seed-0.json: not a valid job result \(KeyError"):
        results.load(stored)
    (stored / "landmark" / "seed-0.json").write_text(good)
    (stored / "landmark-old").mkdir()
    (stored / "landmark-old" / "seed-0.json").write_text("{}")
    with pytest.raises(DnnevoError, match="landmark-old is no experiment of the plan"):
        results.load(stored)


def test_collect_refuses_another_reproductions_folder(tmp_path: Path, reproduction: Path) -> None:
    dest = tmp_path / "results"
    dest.mkdir()
    (dest / "reproduce.json").write_text("{}\n")
    r = _results("collect", reproduction, dest, "--seeds", "0")
    assert r.returncode == 2 and "another reproduction's settings" in r.stderr
    assert not (dest / "landmark").exists()


def test_collect_takes_in_experiments_added_since_and_refuses_a_changed_one(tmp_path: Path,
                                                                            reproduction: Path) -> None:
    """A family collected from a later reproduction, whose settings file has the configs of
    experiments added to dnnevo since, joins the results; one whose config of an experiment
    already collected differs is refused."""
    dest = tmp_path / "results"
    source = tmp_path / "source"
    shutil.copytree(reproduction, source)
    manifest = json.loads((source / "reproduce.json").read_text())
    older = {**manifest, "configs": {k: v for k, v in manifest["configs"].items() if k != "landmark-robust"}}
    dest.mkdir()
    (dest / "reproduce.json").write_text(json.dumps(older, indent=1) + "\n")
    r = _results("collect", source, dest, "--seeds", "0", "--only", "landmark", "--commit", "abc1234")
    assert r.returncode == 0, r.stderr
    assert json.loads((dest / "reproduce.json").read_text()) == manifest
    changed = {**manifest, "configs": {**manifest["configs"], "landmark": {**manifest["configs"]["landmark"],
                                                                          "population": 3}}}
    (dest / "reproduce.json").write_text(json.dumps(changed, indent=1) + "\n")
    before = (dest / "reproduce.json").read_bytes()
    r = _results("collect", source, dest, "--seeds", "0", "--only", "landmark", "--commit", "abc1234")
    assert r.returncode == 2 and "another reproduction's settings" in r.stderr
    assert (dest / "reproduce.json").read_bytes() == before


def test_a_family_collected_again_at_another_commit_names_both(tmp_path: Path, reproduction: Path) -> None:
    """A reproduction continued at a later commit (or in another session, on another machine) is
    collected again: the runs it adds are counted with the earlier ones, the family keeps the
    commit and the machine of its earlier runs beside the new ones, and the elapsed times add up.
    Collecting the same results again changes nothing."""
    dest = tmp_path / "results"
    r = _results("collect", reproduction, dest, "--seeds", "0", "--only", "landmark", "--commit", "abc1234")
    assert r.returncode == 0, r.stderr
    first = json.loads((dest / "provenance.json").read_text())["families"]["landmark"]
    # The earlier session had not finished the robot-like test.
    (dest / "landmark-robot" / "seed-0.json").unlink()
    provenance = json.loads((dest / "provenance.json").read_text())
    provenance["families"]["landmark"].update(runs=5, elapsed_s=100, machines=["Earlier CPU, SIMD kernel avx2"])
    (dest / "provenance.json").write_text(json.dumps(provenance))
    for commit in ("def5678", "fed9999"):
        r = _results("collect", reproduction, dest, "--seeds", "0", "--only", "landmark", "--commit", commit)
        assert r.returncode == 0, r.stderr
    provenance = json.loads((dest / "provenance.json").read_text())
    family = provenance["families"]["landmark"]
    assert family["commit"] == provenance["commit"] == "abc1234, def5678"
    assert family["runs"] == first["runs"] == 10
    assert family["elapsed_s"] >= 100  # the earlier time, and the new run's (under a second here)
    assert family["machines"][0] == "Earlier CPU, SIMD kernel avx2" and len(family["machines"]) == 2


def test_a_result_that_differs_from_the_one_collected_is_refused(tmp_path: Path, reproduction: Path) -> None:
    """Runs are deterministic: a result collected before and made again must agree but for its
    wall times; when it does not, collect names the job and the field and writes nothing."""
    dest = tmp_path / "results"
    r = _results("collect", reproduction, dest, "--seeds", "0", "--only", "landmark", "--commit", "abc1234")
    assert r.returncode == 0, r.stderr
    kept = dest / "landmark" / "seed-0.json"
    result = json.loads(kept.read_text())
    result["wall_s"] += 1000.0  # wall times may differ
    # A result collected before a setting existed lacks it in its config: it is the same run.
    assert result["config"].pop("precision") == "f64"
    kept.write_text(json.dumps(result))
    r = _results("collect", reproduction, dest, "--seeds", "0", "--only", "landmark", "--commit", "def5678")
    assert r.returncode == 0, r.stderr
    result["config"]["precision"] = "f32"  # not its default: another run
    kept.write_text(json.dumps(result))
    r = _results("collect", reproduction, dest, "--seeds", "0", "--only", "landmark", "--commit", "def5678")
    assert r.returncode != 0 and "config.precision" in r.stderr
    del result["config"]["precision"]
    result["run"]["best_fitness"] = 0.123
    kept.write_text(json.dumps(result))
    before = {p: p.read_bytes() for p in dest.rglob("*.json")}
    r = _results("collect", reproduction, dest, "--seeds", "0", "--only", "landmark", "--commit", "def5678")
    assert r.returncode != 0
    assert "landmark/seed-0: the result in" in r.stderr and "run.best_fitness" in r.stderr
    assert {p: p.read_bytes() for p in dest.rglob("*.json")} == before


@pytest.mark.slow
def test_a_family_beyond_the_papers_is_collected_and_rendered(tmp_path: Path, repo: Path) -> None:
    """The classic benchmarks, collected beside the paper's families, get their rows on the
    results page, not in the README."""
    source = tmp_path / "classic"
    r = run_cli("reproduce", "--only", "classic", "--seeds", "0", "--quick", "--eval-trials", "10",
                "--no-dt-check", "--in-process", "--out", source)
    assert r.returncode == 0, r.stderr
    r = _results("collect", source, repo / "docs" / "results", "--seeds", "0", "--only", "classic",
                 "--commit", "abc1234")
    assert r.returncode == 0, r.stderr
    assert repo / "README.md" in results.render(repo)
    readme, page = (repo / "README.md").read_text(), (repo / "docs" / "results" / "index.md").read_text()
    for e in (e for e in plan.EXPERIMENTS if e.family == "classic"):
        assert f"| {e.name} | {e.paper} | 1/1 |" in page, e.name
        assert f"| {e.name} |" not in readme, e.name
    assert "| landmark | " in readme


@pytest.mark.slow
def test_the_papers_reactive_navigation_is_rendered_from_its_results_or_said_not_yet_run(tmp_path: Path,
                                                                                        repo: Path) -> None:
    """The hand-designed reactive navigator's results, collected with the robots family, make
    its row and its per-seed table; a results folder without them says it is not yet run, and a
    damaged one is named."""
    source = tmp_path / "robots"
    r = run_cli("reproduce", "--only", "robots", "--seeds", "0", "--quick", "--eval-trials", "10",
                "--no-dt-check", "--in-process", "--out", source)
    assert r.returncode == 0, r.stderr
    stored = repo / "docs" / "results"
    r = _results("collect", source, stored, "--seeds", "0", "--only", "robots", "--commit", "abc1234")
    assert r.returncode == 0, r.stderr
    hand = plan.experiment("reactive-navigation-hand")
    results.render(repo)
    readme, page = (repo / "README.md").read_text(), (stored / "index.md").read_text()
    row = next(line for line in readme.splitlines() if line.startswith(f"| {hand.name} | {hand.paper} | 1/1 |"))
    assert "goal reached with / without detectors: open-room 10/10 (" in row and "cul-de-sac " in row
    assert "| seed | open-room: goal reached with / without detectors (95% intervals) |" in page
    assert "| 0 | " in page.split(f"### {hand.name}")[1].split("###")[0]
    assert results.render(repo, check=True) == []
    # Damaged counts are named when read, not rendered.
    path = stored / hand.name / "seed-0.json"
    good = path.read_text()
    broken = json.loads(good)
    broken["worlds"]["u-trap"]["with"]["arrived"] = 11
    path.write_text(json.dumps(broken))
    with pytest.raises(DnnevoError, match=r"reactive-navigation-hand/seed-0.json: not a valid job result \(ValueError"):
        results.load(stored)
    # Results of the family without the new experiment's: its row is not yet run, the others stand.
    shutil.rmtree(stored / hand.name)
    results.render(repo)
    readme, page = (repo / "README.md").read_text(), (stored / "index.md").read_text()
    assert f"| {hand.name} | {hand.paper} | not yet run | - | - |" in readme
    assert "| predator-avoidance | " in readme and "| reactive-navigation | not in the paper" in readme
    assert f"### {hand.name}\n\n" in page and "Not yet run over seeds 0." in page.split(f"### {hand.name}")[1]
    assert results.render(repo, check=True) == []


def test_a_refused_collect_writes_nothing(tmp_path: Path, reproduction: Path) -> None:
    """A damaged result refuses the whole collect before any result is copied."""
    source = tmp_path / "source"
    shutil.copytree(reproduction, source)
    (source / "landmark-robot" / "seed-0.json").write_text("{")
    dest = tmp_path / "results"
    r = _results("collect", source, dest, "--seeds", "0", "--only", "landmark", "--commit", "abc1234")
    assert r.returncode == 2 and "landmark-robot" in r.stderr, r.stderr
    assert not dest.exists()


def test_the_committed_tables_are_made_from_docs_results() -> None:
    """README.md and the docs say what docs/results holds: run
    ``python -m dnnevo.experiments.results render`` after collecting results."""
    if not (ROOT / results.RESULTS_DIR / results.SETTINGS_FILE).exists():
        pytest.skip("docs/results holds no reproduction yet")
    stale = results.render(ROOT, check=True)
    names = ", ".join(str(f.relative_to(ROOT)) for f in stale)
    assert not stale, f"tables differ from docs/results in {names}: run python -m dnnevo.experiments.results render"


def test_collect_needs_the_commit_when_the_report_names_none(tmp_path: Path, reproduction: Path) -> None:
    """``pip install .`` from a clone leaves the report without a commit: ``--commit`` names it."""
    source = tmp_path / "source"
    shutil.copytree(reproduction, source)
    md = source / "report.md"
    md.write_text("\n".join(line if not line.startswith("| dnnevo |") else "| dnnevo | 0.1.0 (git not a git checkout) |"
                            for line in md.read_text().splitlines()) + "\n")
    r = _results("collect", source, tmp_path / "results", "--seeds", "0")
    assert r.returncode == 2 and "names no commit" in r.stderr and "pass --commit" in r.stderr
    assert not list((tmp_path / "results").rglob("*.json"))
    r = _results("collect", source, tmp_path / "results", "--seeds", "0", "--commit", "ca5f9b8")
    assert r.returncode == 0, r.stderr
    provenance = json.loads((tmp_path / "results" / "provenance.json").read_text())
    assert provenance["environment"]["dnnevo"] == "0.1.0 (git ca5f9b8)" and provenance["commit"] == "ca5f9b8"


def test_an_examples_results_file_is_checked_when_read(tmp_path: Path) -> None:
    from dnnevo.experiments import examples
    from dnnevo.runs import RunFileError

    path = tmp_path / "demo.json"
    examples.write(path, command="python examples/demo.py", columns=["seed", "score"], rows=[[0, 0.5]],
                   summary=["1 seed"])
    assert examples.read(path)["rows"] == [["0", "0.5"]]
    good = json.loads(path.read_text())
    for broken, message in [("{", "not valid JSON"), ("[]", "format is not"),
                            (json.dumps({**good, "rows": [["0"]]}), "rows of as many cells"),
                            (json.dumps({**good, "summary": [1]}), "all text"),
                            (json.dumps({**good, "made": "abc"}), "what made them")]:
        path.write_text(broken)
        with pytest.raises(RunFileError, match=message):
            examples.read(path)
    with pytest.raises(RunFileError, match="make it with the example's --record"):
        examples.read(tmp_path / "missing.json")


def test_an_examples_table_is_rendered_from_its_record_and_checked(repo: Path) -> None:
    from dnnevo.experiments import examples

    page = repo / "docs" / "classic.md"
    page.write_text("# Demo\n\n<!-- results:example:demo:begin -->\nold\n<!-- results:example:demo:end -->\n")
    record = repo / "docs" / "results" / "examples" / "demo.json"
    examples.write(record, command="python examples/demo.py --seeds 2", columns=["seed", "score"],
                   rows=[[0, "0.5"], [1, "0.7"]], summary=["2 seeds"])
    assert _results("render", "--root", repo, "--check").returncode == 1
    assert _results("render", "--root", repo).returncode == 0
    text = page.read_text()
    assert "`python examples/demo.py --seeds 2`:\n\n| seed | score |\n|---|---|\n| 0 | 0.5 |\n| 1 | 0.7 |" in text
    assert "\n2 seeds\n" in text and "old" not in text
    assert _results("render", "--root", repo, "--check").returncode == 0
    record.unlink()
    r = _results("render", "--root", repo, "--check")
    assert r.returncode == 2 and "demo.json does not exist; make it with the example's --record" in r.stderr


def test_the_precision_table_sets_each_f32_experiment_beside_its_f64_one_on_shared_seeds() -> None:
    from dnnevo.experiments import precision
    from dnnevo.experiments.scheduler import Outcome, Task

    stored = {s: json.loads((ROOT / f"docs/results/sequence-1bit/seed-{s}.json").read_text()) for s in range(6)}
    order = plan.jobs(range(8), ("precision", "sequence", "nav1d", "landmark"))

    def table(single: dict[int, dict]) -> dict[str, tuple[str, ...]]:
        found = {**{f"sequence-1bit/seed-{s}": r for s, r in stored.items()},
                 **{f"sequence-1bit-f32/seed-{s}": r for s, r in single.items()}}
        outcomes = {j.id: Outcome(Task(j.id, j.needs, print), "done", found[j.id]) if j.id in found
                    else Outcome(Task(j.id, j.needs, print), results.NOT_RUN) for j in order}
        return {row[0]: row for row in precision.rows(order, outcomes)}

    # The same results on seeds 0-3: the same counts, on the 4 seeds both have.
    row = table({s: stored[s] for s in range(4)})["sequence-1bit / sequence-1bit-f32"]
    assert row[1:] == ("4", "4/4 (51.0%-100%)", "4/4 (51.0%-100%)", "4/4 (51.0%-100%)", "4/4 (51.0%-100%)",
                       "1.00 / 1.00")
    assert table({})["landmark / landmark-f32"][1:] == ("none yet", "-", "-", "-", "-", "-")
    # Four of six f32 seeds never met the rule: 6/6 against 2/6, Fisher's p = 0.061.
    never = {s: {**r, "run": {**r["run"], "first_success": None, "succeeded": False}} for s, r in stored.items()}
    row = table({s: never[s] if s < 4 else stored[s] for s in stored})["sequence-1bit / sequence-1bit-f32"]
    assert row[2:4] == ("6/6 (61.0%-100%)", "2/6 (9.7%-70.0%)") and row[-1] == "0.06 / 1.00"


def test_a_manifest_written_before_a_later_setting_still_matches_todays_configs(tmp_path: Path) -> None:
    """The reference reproduce.json predates ``precision``: a reproduction of today's code with
    the same settings continues in its folder, and its results may be collected beside it."""
    from dnnevo.experiments import jobs
    from dnnevo.runs import check_settings
    from dnnevo.runs.settings import manifest_with_later_defaults

    stored = json.loads((ROOT / "docs/results/reproduce.json").read_text())
    # The configs recorded before the setting existed (the f32 family's came after it).
    stored["configs"] = {k: c for k, c in stored["configs"].items() if "precision" not in c}
    assert "sequence-1bit" in stored["configs"]
    today = json.loads(json.dumps(jobs.Settings(**stored["settings"]).to_dict()))  # as read from a file
    today["configs"] = {k: v for k, v in today["configs"].items() if k in stored["configs"]}
    manifest = tmp_path / "reproduce.json"
    manifest.write_text(json.dumps(stored))
    check_settings(manifest, today, what="reproduction", force=False)
    joined = results._joined(stored, today)
    assert joined is not None and joined["configs"] == stored["configs"]  # what it held, unchanged
    f32 = {**today, "configs": {k: {**v, "precision": "f32"} for k, v in today["configs"].items()}}
    assert results._joined(stored, f32) is None
    with pytest.raises(Exception, match="precision = 'f64', not 'f32'"):
        check_settings(manifest, f32, what="reproduction", force=False)
    assert manifest_with_later_defaults({"x": 1}) == {"x": 1}


def test_the_robot_like_rows_count_the_transfer_goal_as_the_stored_results_give_it() -> None:
    """The summary row of a robot-like test counts the seeds above 85% with the Wilson
    interval's lower end above 80% (issue 47's goal), besides the 95% rule; counted here again
    from the committed results with the textbook Wilson formula."""
    stored = Path(__file__).parent.parent / "docs" / "results"
    readme = (Path(__file__).parent.parent / "README.md").read_text()
    for name in ("landmark-robot", "landmark-robust-robot"):
        files = sorted((stored / name).glob("seed-*.json"))
        if not files:
            continue
        beat = 0
        for f in files:
            overall = json.loads(f.read_text())["assessment"]["rates"][-1]
            k, n, z = overall["k"], overall["n"], 1.959963984540054
            p = k / n
            lower = (p + z * z / (2 * n) - z * (p * (1 - p) / n + z * z / (4 * n * n)) ** 0.5) / (1 + z * z / n)
            beat += p > 0.85 and lower > 0.80
        (row,) = [line for line in readme.splitlines() if line.startswith(f"| {name} |")]
        assert f"lower end >80%: {beat}/{len(files)} " in row, row


def test_a_worlds_digest_is_compared_only_when_both_results_hold_one() -> None:
    """A held-out result collected before results held their worlds' digest is the same job as
    one judged since; two results that both hold one must agree on it."""
    digest = jobs.WORLDS_INPUT + "first"
    old = {"inputs": {"landmark/seed-0/best.json": "ab"}, "wall_s": 1.0}
    new = {"inputs": {"landmark/seed-0/best.json": "ab", digest: "d1"}, "wall_s": 2.0}
    assert first_difference(*results._comparable_pair(old, new)) is None
    other = {"inputs": {**new["inputs"], digest: "d2"}, "wall_s": 3.0}
    assert first_difference(*results._comparable_pair(new, other)) is not None
