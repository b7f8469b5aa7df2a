"""``--set KEY=VALUE`` (``dnnevo.config.apply_overrides``): a dotted key reaches into nested
tables and, by number, into lists; a built-in task's table that the config does not hold yet
starts from the task's own defaults, so one part of it changes and the rest is kept."""

from __future__ import annotations

import pytest

import dnnevo
from dnnevo.config import apply_overrides
from dnnevo.errors import ConfigError


def _params(config: dnnevo.EvolutionConfig) -> dict:
    return config.native.builtin().params()


def test_one_part_of_a_default_table_and_of_a_list_entry_changes_and_the_rest_is_kept() -> None:
    base = dnnevo.presets.get("landmark")
    assert "sim" not in base.task_params and "landmark1" not in base.task_params
    changed = apply_overrides(base, ["task_params.sim.sonars.0.lobe_deg=10",
                                     "task_params.sim.follower.angle_gain=0.3",
                                     "task_params.landmark1.boxes.0.size=[1.0, 0.6]"])
    before, after = _params(base), _params(changed)
    want_sim = {**before["sim"], "follower": {**before["sim"]["follower"], "angle_gain": 0.3},
                "sonars": [{**before["sim"]["sonars"][0], "lobe_deg": 10.0}]}
    want_box = {**before["landmark1"]["boxes"][0], "size": [1.0, 0.6]}
    assert after["sim"] == want_sim
    assert after["landmark1"] == {**before["landmark1"], "boxes": [want_box]}
    assert {k: v for k, v in after.items() if k not in ("sim", "landmark1")} == \
        {k: v for k, v in before.items() if k not in ("sim", "landmark1")}
    # The config file holds the whole table, without the unset optional parts TOML cannot write.
    again = dnnevo.EvolutionConfig.from_toml(changed.to_toml())
    assert _params(again) == after


def test_a_table_the_config_holds_is_changed_in_place() -> None:
    held = apply_overrides(dnnevo.presets.get("landmark-robust"), ["task_params.training.cone_deg=3"])
    assert held.task_params["training"] == {**dnnevo.presets.get("landmark-robust").task_params["training"],
                                            "cone_deg": 3}


def test_a_python_task_gets_a_new_nested_table() -> None:
    config = dnnevo.EvolutionConfig(task="python:light.Light", size=3, n_inputs=2)
    assert apply_overrides(config, ["task_params.arena.width=4"]).task_params == {"arena": {"width": 4}}


@pytest.mark.parametrize("key, message", [
    ("task_params.sim.sonars.1.lobe_deg", "task_params.sim.sonars is a list of 1, so its entries are 0 to 0"),
    ("task_params.sim.sonars.first.lobe_deg", "task_params.sim.sonars is a list of 1, so its entries are 0 to 0"),
    ("task_params.sim.dt.x", "task_params.sim.dt is 0.1, not a table"),
])
def test_a_path_that_does_not_fit_is_named(key: str, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        apply_overrides(dnnevo.presets.get("landmark"), [f"{key}=1"])


def test_a_list_missing_from_a_partial_table_starts_from_the_task_s_own() -> None:
    base = apply_overrides(dnnevo.presets.get("landmark"), ["task_params.sim={follower={speed=0.5}}"])
    assert base.task_params["sim"] == {"follower": {"speed": 0.5}}
    changed = apply_overrides(base, ["task_params.sim.sonars.0.lobe_deg=10"])
    sonar = _params(changed)["sim"]["sonars"][0]
    assert sonar == {**_params(base)["sim"]["sonars"][0], "lobe_deg": 10.0}
    assert _params(changed)["sim"]["follower"]["speed"] == 0.5


def test_an_earlier_bad_override_is_the_error_named() -> None:
    # The defaults come from the config as given, so a bad earlier value does not hide them, and
    # the task names it when it is built.
    both = apply_overrides(dnnevo.presets.get("landmark"),
                           ["task_params.trials_per_landmark=0", "task_params.sim.sonars.0.lobe_deg=10"])
    with pytest.raises(ConfigError, match="trials_per_landmark is 0"):
        _params(both)


@pytest.mark.parametrize("preset, key, message", [
    ("landmark", "task_params.landmark1.boxes.0.size.0.x", "task_params.landmark1.boxes.0.size.0 is 1.2, not a table"),
    ("sequence-1bit", "task_params.targets.0.x", "task_params.targets.0 is '0', not a table"),
    ("sequence-1bit", "task_params.nothing.0.x", "task_params.nothing is not a list the config or the task has"),
])
def test_a_path_through_a_plain_value_is_named_not_a_traceback(preset: str, key: str, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        apply_overrides(dnnevo.presets.get(preset), [f"{key}=1"])


@pytest.mark.parametrize("text", ["False", "True", "TRUE", "None", "null", "NaN"])
def test_a_value_meant_as_a_boolean_or_nothing_is_refused_not_kept_as_a_string(text: str) -> None:
    """``switch=False`` as the string "False" would be true in the task's ``if self.switch:``."""
    config = dnnevo.EvolutionConfig()
    with pytest.raises(ConfigError, match=rf"--set task_params.switch={text}: {text} is not a TOML value"):
        apply_overrides(config, [f"task_params.switch={text}"])
    assert apply_overrides(config, [f'task_params.switch="{text}"']).task_params["switch"] == text
    assert apply_overrides(config, ["task_params.switch=false"]).task_params["switch"] is False
    assert apply_overrides(config, ["task_params.name=Falsey"]).task_params["name"] == "Falsey"
    for nested in (f"[{text}]", f"{{a={text}}}", f"[1, {text}]"):
        with pytest.raises(ConfigError, match=rf"not a TOML value, since {text} is not one"):
            apply_overrides(config, [f"task_params.switch={nested}"])


def test_a_config_file_is_loaded_by_path_and_a_path_given_as_text_is_pointed_there(tmp_path) -> None:
    config = dnnevo.EvolutionConfig(population=30, task_params={"max_steps": 5})
    path = tmp_path / "config.toml"
    path.write_text(config.to_toml({"seed": 3}))
    assert dnnevo.EvolutionConfig.load(path) == dnnevo.EvolutionConfig.load(str(path)) == config
    with pytest.raises(ConfigError, match="looks like a file's path: EvolutionConfig.load"):
        dnnevo.EvolutionConfig.from_toml(str(path))
    with pytest.raises(ConfigError, match="from_toml takes TOML text, not a PosixPath"):
        dnnevo.EvolutionConfig.from_toml(path)  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="cannot read .*missing.toml: No such file"):
        dnnevo.EvolutionConfig.load(tmp_path / "missing.toml")
    path.write_text("population = " + "[" * 5000 + "]" * 5000)
    with pytest.raises(ConfigError, match=r"config.toml: tables or arrays nested too deeply"):
        dnnevo.EvolutionConfig.load(path)
    path.write_text("population = [")
    with pytest.raises(ConfigError, match=r"config.toml: not valid TOML"):
        dnnevo.EvolutionConfig.load(path)
