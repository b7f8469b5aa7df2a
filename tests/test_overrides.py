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
