"""Landmark recognition's held-out worlds and bounds (issue 47): the worlds change what they say
and build, the bounds are fitted on trials other than the ones they are judged on, and the
example's code path writes a record that renders."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run_cli

import dnnevo
from dnnevo import presets
from dnnevo.evaluation import observer
from dnnevo.experiments import examples, results
from dnnevo.tasks import landmark, landmark_worlds
from dnnevo.tasks import landmark_transfer as transfer

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "examples"))

import landmark_transfer  # noqa: E402

# What each world says it changes, by the config's dotted names; nothing else may differ.
STATED = {
    "follower": {"sim.follower.speed", "sim.follower.wall_distance", "sim.follower.max_turn_rate"},
    "sonar": {f"sim.sonars.0.{k}" for k in ("cone_deg", "rays", "mount_angle_deg", "noise_sd",
                                            "specular_max_incidence_deg", "max_range")},
    "room": {f"landmark{n}.{k}" for n in (1, 2) for k in ("room", "start.max", "boxes.0.center")}
    | {"landmark2.boxes.1.center"},
    "weaving": {"sim.follower.angle_gain", "sim.follower.corner_distance"},
    "lobe": {f"sim.sonars.0.{k}" for k in ("cone_deg", "rays", "lobe_deg", "dropout")},
    "boxes": {"landmark1.boxes.0.size", "landmark2.boxes"},  # three crates for two: the list differs whole
}
EVERY = {name: w for worlds in landmark_worlds.SETS.values() for name, w in worlds.items()}


@pytest.mark.parametrize("name", sorted(EVERY))
def test_each_world_changes_its_stated_factors_and_builds(name: str) -> None:
    world = EVERY[name]
    assert set(landmark_worlds.factors(world)) == STATED[name]
    cfg = landmark_worlds.config(presets.get("landmark-robust"), world)
    params = landmark.params(cfg)  # the task builds (validates)
    # The run's training variation is gone: a held-out world is judged as it is.
    assert params["training"]["cone_deg"] == 0.0 and params["trials_per_landmark"] == 3


@pytest.mark.parametrize("name", sorted(EVERY))
def test_a_world_taken_apart_changes_each_of_its_factors_in_one_part(name: str) -> None:
    world = EVERY[name]
    parts = [landmark_worlds.factors(w) for w in landmark_worlds.single_factors(world)]
    assert all(parts), "a part that changes nothing"
    changed = [k for part in parts for k in part]
    assert len(changed) == len(set(changed)), "a factor in two parts"
    whole = landmark_worlds.factors(world)
    assert {k: v for part in parts for k, v in part.items()} == whole
    assert (len(parts) > 1) == bool(world.parts)


def test_the_worlds_go_beyond_what_training_varies() -> None:
    """Each factor the robust preset's training varies goes further in the world that changes it."""
    t = presets.get("landmark-robust").task_params["training"]
    f = {k: v for w in landmark_worlds.WORLDS.values() for k, v in landmark_worlds.factors(w).items()}
    speed = f["sim.follower.speed"]
    assert abs(speed[1] / speed[0] - 1) > 2 * t["follower_speed"]
    distance = f["sim.follower.wall_distance"]
    assert abs(distance[1] - distance[0]) > 2 * t["follower_distance"]
    cone = f["sim.sonars.0.cone_deg"]
    assert abs(cone[1] - cone[0]) > t["cone_deg"]
    # Training moves the landmark by at most 0.15 m in a 6 m x 5 m room; the room world's is bigger.
    assert f["landmark1.room"][1][0] - f["landmark1.room"][0][0] >= 2.0


def test_the_second_set_changes_nothing_the_wide_envelope_varies() -> None:
    """landmark-wide varies the follower's speed and distance, the sonar's cone and axis, the room
    and the landmark as a whole; the second set's worlds change other things (the box sizes of
    the boxes world change the landmarks' proportions, which scaling a landmark as a whole keeps),
    and the one varied setting they change, the cone, stays within training's range."""
    training = presets.get("landmark-wide").task_params["training"]
    assert training["room_scale"] > 0 and training["sonar_axis_deg"] > 0
    varied = {"sim.follower.speed", "sim.follower.wall_distance", "sim.sonars.0.mount_angle_deg",
              "landmark1.room", "landmark2.room"}
    for world in landmark_worlds.SECOND.values():
        assert not varied & set(landmark_worlds.factors(world)), world.name
    # The lobed sonar's cone is one that training draws (25 +- 15 deg): what differs is its lobe.
    default, cone = landmark_worlds.factors(landmark_worlds.SECOND["lobe"])["sim.sonars.0.cone_deg"]
    assert abs(cone - default) <= training["cone_deg"]
    assert landmark_worlds.world_set("weaving") == "second" and landmark_worlds.world_set("room") == "first"
    assert not set(landmark_worlds.WORLDS) & set(landmark_worlds.SECOND), "a name in two sets"


def test_a_world_for_another_task_is_refused() -> None:
    with pytest.raises(Exception, match="held-out worlds"):
        landmark_worlds.config(presets.get("sequence-1bit"), landmark_worlds.WORLDS["room"])


def test_logistic_regression_recovers_a_known_rule() -> None:
    rng = np.random.default_rng(4)
    x = rng.normal(size=(400, 3)) * [1.0, 5.0, 0.1] + [0.0, 2.0, 0.0]
    y = (x[:, 0] - 0.2 * x[:, 1] > -0.4).astype(int)  # a rule on two of the three columns
    model = observer.fit_logistic(x, y, ridge=1e-4)
    w = model.w / model.sd  # weights on the raw columns
    assert w[1] / w[0] == pytest.approx(-0.2, abs=0.03)
    assert abs(w[2] / w[0]) < 0.5
    fresh = rng.normal(size=(400, 3)) * [1.0, 5.0, 0.1] + [0.0, 2.0, 0.0]
    assert np.mean(model.predict(fresh) == (fresh[:, 0] - 0.2 * fresh[:, 1] > -0.4)) > 0.97


def test_the_threshold_rule_sees_only_its_fitting_trials(monkeypatch: pytest.MonkeyPatch) -> None:
    """The bounds fit on FIT_SEED's trials and judge on TEST_SEED's, the champions' test seed."""
    assert transfer.FIT_SEED != transfer.TEST_SEED
    seen: list[tuple[int, int]] = []
    sense = transfer.sonar_features

    def spy(config, net, per_landmark, seed, robot_like):  # type: ignore[no-untyped-def]
        seen.append((seed, per_landmark))
        return sense(config, net, per_landmark, seed, robot_like)

    fits: list[np.ndarray] = []
    fit = observer.fit_threshold

    def fit_spy(x, y, columns=None):  # type: ignore[no-untyped-def]
        fits.append(np.asarray(x))
        return fit(x, y, columns)

    monkeypatch.setattr(transfer, "sonar_features", spy)
    monkeypatch.setattr(observer, "fit_threshold", fit_spy)
    monkeypatch.setattr(transfer, "PLACES", transfer.PLACES[:1])
    cfg = presets.get("landmark")
    net = dnnevo.Network.random(cfg.size, cfg.n_inputs, seed=1)
    out = transfer.bounds(cfg, net, 3, 2)
    assert seen == [(transfer.FIT_SEED, 3), (transfer.TEST_SEED, 2)]
    assert len(fits) == 1 and len(fits[0]) == 6  # fitted on the 2 x 3 fitting trials alone
    assert out["training"]["n"] == 4


def test_the_sonar_features_are_of_the_champions_test_trials() -> None:
    """The bounds judge the very trials ``assess`` draws: trial t of a seed is the same sonar."""
    cfg = presets.get("landmark")
    net = dnnevo.Network.random(cfg.size, cfg.n_inputs, seed=2)
    x, y = transfer.sonar_features(cfg, net, 2, 9, False)
    assert y.tolist() == [0, 0, 1, 1]
    again = [observer.features(landmark.record(cfg, net, 2, seed=9, trial=3).input, transfer.NEAR)]
    assert np.array_equal(x[3], again[0])
    # ... and those recorded trials are the ones assess judges, trial by trial, in the same order.
    judged = landmark.assess(cfg, net, 2, seed=9)["trials"]
    recorded = [(lm, landmark.record(cfg, net, lm, seed=9, trial=t).classification)
                for t, lm in enumerate([1, 1, 2, 2])]
    assert [(lm, f) for lm, f in judged] == recorded


# What examples/landmark_transfer.py computed for this network before its judging moved into
# dnnevo.tasks.landmark_transfer (judge: 6 trials per landmark; bounds: fitted on 5, judged on 6).
BEFORE_JUDGE = {"training": 6, "training one answer": 12, "robot-like": 6, "robot-like one answer": 12,
                "follower": 6, "follower one answer": 12, "sonar": 6, "sonar one answer": 12,
                "room": 7, "room one answer": 11}
BEFORE_BOUNDS = {
    "training": {"threshold": 11, "observer": 12, "n": 12, "rule": "mean > 0.218 says landmark 2"},
    "robot-like": {"threshold": 11, "observer": 11, "n": 12, "rule": "mean > 0.2 says landmark 2"},
    "follower": {"threshold": 12, "observer": 12, "n": 12, "rule": "mean > 0.262 says landmark 2",
                 "observer, other worlds": 11},
    "sonar": {"threshold": 12, "observer": 12, "n": 12, "rule": "mean > 0.235 says landmark 2",
              "observer, other worlds": 11},
    "room": {"threshold": 10, "observer": 12, "n": 12, "rule": "mean > 0.145 says landmark 2",
             "observer, other worlds": 6},
}


def test_the_library_answers_as_the_example_did() -> None:
    """The example's record stays what it was: the judging it now calls gives its earlier answer."""
    cfg = presets.get("landmark-robust")
    net = dnnevo.Network.random(cfg.size, cfg.n_inputs, seed=5)
    first = [transfer.place(n) for n in ["training", "robot-like", *transfer.held_out("first")]]
    assert transfer.judge(cfg, net, 6, first) == BEFORE_JUDGE
    assert transfer.bounds(cfg, net, 5, 6, first) == BEFORE_BOUNDS
    # Every place, the second set's worlds too, answers as each set does on its own.
    everywhere = transfer.judge(cfg, net, 6)
    assert {k: everywhere[k] for k in BEFORE_JUDGE} == BEFORE_JUDGE
    assert set(everywhere) == {f"{p.name}{one}" for p in transfer.PLACES for one in ("", " one answer")}
    # A subset of places answers as the whole does, place by place.
    some = [transfer.place(n) for n in ["training", *transfer.held_out()]]
    assert transfer.bounds(cfg, net, 5, 6, some) == {p.name: BEFORE_BOUNDS[p.name] for p in some}
    assert transfer.judge(cfg, net, 6, some[1:2]) == {"follower": 6, "follower one answer": 12}


def test_a_tiny_run_makes_a_record_that_renders(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    runs = tmp_path / "tiny"
    r = run_cli("run", "landmark", "--quick", "--out", runs / "seed-0", "--seed", "0", "--set", "generations=1",
                "--set", "population=10", "--threads", "1")
    assert r.returncode == 0, r.stderr
    record = tmp_path / "results" / "examples" / "landmark-transfer.json"
    argv = [str(runs), "--trials", "3", "--fit-trials", "4", "--record", str(record)]
    landmark_transfer.main(argv)
    doc = examples.read(record)
    assert doc["command"] == examples.command("examples/landmark_transfer.py", argv[:-2])
    assert [row[0] for row in doc["rows"]] == ["training", "robot-like", "follower (held out)",
                                               "sonar (held out)", "room (held out)"]
    assert all(row[1] == "tiny" and row[2] in ("0/1", "1/1") for row in doc["rows"])
    page = tmp_path / "page.md"
    page.write_text("<!-- results:example:landmark-transfer:begin -->\nSTALE TABLE\n"
                    "<!-- results:example:landmark-transfer:end -->\n")
    assert results.render(tmp_path, results_dir=tmp_path / "results", files=[page]) == [page]
    assert "| room (held out) | tiny |" in page.read_text() and "STALE TABLE" not in page.read_text()
    assert "tiny seed-0: training" in capsys.readouterr().out
    # --factors: one row per factor of the follower and sonar worlds, and the room world whole.
    factors = tmp_path / "results" / "examples" / "landmark-factors.json"
    landmark_transfer.main([str(runs), "--trials", "3", "--fit-trials", "4", "--factors", "--record", str(factors)])
    rows = examples.read(factors)["rows"]
    assert [row[0] for row in rows] == ["follower: speed", "follower: wall distance", "follower: turn rate",
                                        "sonar: beam", "sonar: axis", "sonar: range noise", "sonar: specular misses",
                                        "sonar: range", "room"]
    assert "champions failing each factor: follower: speed " in examples.read(factors)["summary"][1]


def test_help_names_an_example_and_a_missing_folder_is_named(capsys: pytest.CaptureFixture[str],
                                                              tmp_path: Path) -> None:
    with pytest.raises(SystemExit):
        landmark_transfer.main(["--help"])
    assert "examples/landmark_transfer.py /root/dnnevo-reference/landmark" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        landmark_transfer.main([str(tmp_path / "nowhere")])
    assert "nowhere is not a folder; pass the champions' folders" in capsys.readouterr().err


def test_a_held_out_world_keeps_the_run_s_own_settings() -> None:
    """A run read its answer from neuron 3 after 30 s: in the training place it is judged as
    ``assess`` judges it with its own config, and a held-out world keeps those settings."""
    base = presets.get("landmark")
    own = dataclasses.replace(base, task_params={"classifier": 3, "trial_seconds": 30.0, "trials_per_landmark": 5})
    net = dnnevo.Network.random(own.size, own.n_inputs, seed=11)
    mine = landmark.assess(own, net, 4, transfer.TEST_SEED)["confusion"]
    assert transfer.judge(own, net, 4, ["training"])["training"] == mine[0][0] + mine[1][1]
    params = landmark.params(landmark_worlds.config(own, "weaving"))
    assert (params["classifier"], params["trial_seconds"], params["trials_per_landmark"]) == (3, 30.0, 3)
    assert params["sim"]["follower"]["angle_gain"] == 0.3
    # A sonar of the run's own keeps what the world does not change.
    ranged = dataclasses.replace(base, task_params={"sim": {"sonars": [{"max_range": 5.0, "rays": 9}]}})
    sonar = landmark.params(landmark_worlds.config(ranged, "lobe"))["sim"]["sonars"][0]
    assert (sonar["max_range"], sonar["rays"], sonar["lobe_deg"]) == (5.0, 11, 10.0)
    # A world that changes the boxes keeps the run's own room and start region.
    room = {"room": [7.0, 5.0], "start": {"min": [0.4, 0.4], "max": [6.6, 4.6]},
            "boxes": [{"center": [3.5, 2.5], "size": [1.2, 0.6]}]}
    roomy = dataclasses.replace(base, task_params={"landmark1": room})
    world = landmark.params(landmark_worlds.config(roomy, "boxes"))["landmark1"]
    assert world["room"] == [7.0, 5.0] and world["boxes"][0]["size"] == [1.2, 0.3]


def test_names_and_counts_are_checked() -> None:
    cfg = presets.get("landmark")
    net = dnnevo.Network.random(cfg.size, cfg.n_inputs, seed=1)
    with pytest.raises(dnnevo.InvalidArgumentError, match="no place is called 'folower'"):
        transfer.judge(cfg, net, 2, ["folower"])
    with pytest.raises(dnnevo.InvalidArgumentError, match="world_set is 'secnd'"):
        transfer.worlds_digest("secnd")
    with pytest.raises(dnnevo.InvalidArgumentError, match="fit is 0"):
        transfer.bounds(cfg, net, 0, 5, ["training"])
    with pytest.raises(dnnevo.InvalidArgumentError, match="no held-out world is called 'rooom'"):
        landmark_worlds.single_factors("rooom")
    assert [w.name for w in landmark_worlds.single_factors("lobe")] == ["lobe: beam pattern", "lobe: dropouts"]


def test_the_example_labels_same_named_folders_apart_and_refuses_other_tasks(tmp_path: Path) -> None:
    assert landmark_transfer.labels([Path("a/landmark"), Path("b/landmark"), Path("c/x")]) == [
        "a/landmark", "b/landmark", "x"]
    r = run_cli("run", "sequence-1bit", "--quick", "--out", tmp_path / "seq", "--threads", "1")
    assert r.returncode == 0, r.stderr
    with pytest.raises(SystemExit, match="^error: the run's task is 'sequence'; held-out worlds are for the "
                                         "'landmark' task$"):
        landmark_transfer.main([str(tmp_path / "seq")])


def test_the_envelope_s_ends_change_one_setting_each_as_a_training_trial_does() -> None:
    wide = presets.get("landmark-wide")
    training = landmark.params(wide)["training"]
    edges = landmark_worlds.envelope_edges(wide)
    assert len(edges) == 8
    changed = {}
    for world in edges:
        diff = landmark_worlds.factors(world)  # against the paper's training world
        assert len(diff) == 1, (world.name, diff)
        (key, (was, now)), = diff.items()
        changed[world.name] = (key, now - was if key != "sim.follower.speed" else now / was)
    assert changed["follower speed x0.8"] == ("sim.follower.speed", pytest.approx(1 - training["follower_speed"]))
    assert changed["wall distance +0.15 m"] == ("sim.follower.wall_distance",
                                                pytest.approx(training["follower_distance"]))
    assert changed["sonar cone -15 deg"] == ("sim.sonars.0.cone_deg", -training["cone_deg"])
    assert changed["sonar axis +15 deg"] == ("sim.sonars.0.mount_angle_deg", training["sonar_axis_deg"])
    # Judged as it is: the run's training variation is gone.
    assert landmark.params(landmark_worlds.config(wide, edges[0]))["training"]["cone_deg"] == 0.0


def test_the_envelope_example_records_each_end_and_refuses_a_run_without_an_envelope(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import landmark_envelope

    runs = tmp_path / "robust"
    r = run_cli("run", "landmark-robust", "--quick", "--out", runs / "seed-0", "--seed", "0", "--set",
                "generations=1", "--set", "population=12", "--threads", "1")
    assert r.returncode == 0, r.stderr
    record = tmp_path / "results" / "examples" / "landmark-envelope.json"
    argv = [str(runs), "--trials", "3", "--record", str(record)]
    landmark_envelope.main(argv)
    doc = examples.read(record)
    assert doc["command"] == examples.command("examples/landmark_envelope.py", argv[:-2])
    assert [row[1] for row in doc["rows"]] == [w.name for w in landmark_worlds.envelope_edges(
        presets.get("landmark-robust", quick=True))]
    assert doc["summary"][1].startswith("robust: ") and "validation rate" in doc["summary"][1]
    plain = tmp_path / "plain"
    r = run_cli("run", "landmark", "--quick", "--out", plain, "--set", "generations=1", "--set", "population=10")
    assert r.returncode == 0, r.stderr
    with pytest.raises(SystemExit, match="vary none of the follower's speed"):
        landmark_envelope.main([str(plain), "--trials", "2"])
    # --bounds: one row per end with its three rules, and the same refusal without an envelope.
    bounds = tmp_path / "bounds.json"
    landmark_envelope.main([str(runs), "--bounds", "--trials", "4", "--record", str(bounds)])
    doc = examples.read(bounds)
    assert doc["columns"] == landmark_envelope.BOUNDS_COLUMNS
    assert [row[1] for row in doc["rows"]] == [w.name for w in landmark_worlds.envelope_edges(
        presets.get("landmark-robust", quick=True))]
    assert all(0.0 <= float(x) <= 100.0 for row in doc["rows"] for x in row[2:])
    assert doc["summary"][1].startswith("robust: the goal is met by one linear observer at ")
    with pytest.raises(SystemExit, match="varies none of the follower's speed"):
        landmark_envelope.main([str(plain), "--bounds", "--trials", "2"])


def test_one_rule_for_every_place_is_judged_in_each_against_the_place_s_own() -> None:
    """pooled_bounds: a place's own observer, one linear observer and one nearest-neighbour rule
    for all places together, each counted on the place's own test trials."""
    config = presets.get("landmark-wide", quick=True)
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=0)
    places = [transfer.Place(w.name, w) for w in landmark_worlds.envelope_edges(config)[:2]]
    found = transfer.pooled_bounds(config, net, 6, 5, places)
    assert list(found) == [p.name for p in places]
    for b in found.values():
        assert b["n"] == 10 and all(0 <= b[k] <= 10 for k in ("own", "one linear", "one linear, profile",
                                                               "one nearest"))


def test_the_nearest_neighbour_rule_is_the_brute_force_one_and_a_profile_needs_its_bins() -> None:
    rng = np.random.default_rng(3)
    x, y = rng.normal(size=(300, 6)), rng.integers(0, 2, 300)
    test = rng.normal(size=(observer.NEAREST_CHUNK + 17, 6))
    rule = observer.fit_nearest(x, y)
    z, zt = (x - rule.mu) / rule.sd, (test - rule.mu) / rule.sd
    brute = y[((zt[:, None, :] - z[None, :, :]) ** 2).sum(-1).argmin(1)]
    assert np.array_equal(rule.predict(test), brute)
    # Exact ties go to the first of the equally near fitted rows.
    grid = observer.fit_nearest([[0.0], [1.0], [2.0], [3.0], [4.0]], [0, 1, 0, 1, 0])
    assert grid.predict([[0.5], [1.5], [2.5], [3.5]]).tolist() == [0, 1, 0, 1]
    assert observer.profile(np.linspace(0, 1, observer.PROFILE_BINS), 0.5).shape == (64,)
    with pytest.raises(ValueError, match="at least 24 steps"):
        observer.profile(np.arange(10.0), 1.0)
