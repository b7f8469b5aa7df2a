"""The binding takes a run's settings once, as an object, builds each task once, and returns typed
records: what crosses between Python and Rust, and what it refuses."""

from __future__ import annotations

import dataclasses
import math
import pickle

import numpy as np
import pytest

import dnnevo
import dnnevo.analysis
from dnnevo import _core, presets
from dnnevo.errors import ConfigError, InvalidArgumentError
from dnnevo.tasks import landmark, nav1d, sequence


def test_a_config_is_parsed_once_and_builds_its_task_once() -> None:
    config = presets.get("nav1d-far")
    assert isinstance(config.native, _core.RunConfig)
    assert config.native.task == "nav1d"
    task = config.native.builtin()
    assert isinstance(task, _core.Nav1dTask) and config.native.builtin() is task
    assert task.layout == (config.size, config.n_inputs)
    # A changed config is a new object with its own task.
    finer = dataclasses.replace(config, integrator=dataclasses.replace(config.integrator, dt=0.05))
    assert finer.native.builtin() is not task


def test_the_core_refuses_a_bad_setting_naming_its_field() -> None:
    with pytest.raises(ConfigError, match=r"integrator\.dt is -1"):
        _core.RunConfig('{"integrator": {"method": "euler", "dt": -1.0, "substeps": 1}}')
    with pytest.raises(ConfigError, match="unknown task \"maze\"; known tasks: sequence, nav1d, landmark"):
        _core.RunConfig('{"task": "maze"}').builtin()


def test_a_config_and_its_native_form_survive_pickling() -> None:
    config = presets.get("sequence-1bit")
    back = pickle.loads(pickle.dumps(config))
    assert back == config and back.native.to_json() == config.native.to_json()
    assert pickle.loads(pickle.dumps(config.native)).to_json() == config.native.to_json()


def test_params_fill_every_default_from_the_core() -> None:
    config = presets.get("nav1d-far")
    assert "classifier" not in config.task_params
    settings = nav1d.params(config)
    assert settings["classifier"] == 2 and settings["half_length"] == 20.0
    assert landmark.params(presets.get("landmark"))["classifier"] == 0
    assert sequence.target_list(dnnevo.EvolutionConfig()) == ["0", "1"]


def test_a_condition_is_typed_and_checked() -> None:
    c = nav1d.Condition("far", "left", 0.0, 10.0)
    assert (c.environment, c.goal, c.start, c.landmark) == ("far", "left", 0.0, 10.0)
    assert c == nav1d.Condition(environment="far", goal="left", start=0.0, landmark=10.0)
    assert c != nav1d.Condition("near", "left", 0.0, 10.0)
    assert pickle.loads(pickle.dumps(c)) == c
    assert len({c, nav1d.Condition("far", "left", -0.0, 10.0)}) == 1  # hashable, -0.0 == 0.0
    with pytest.raises(InvalidArgumentError, match="start is NaN; it must be a finite number"):
        nav1d.Condition("far", "left", math.nan, 10.0)
    with pytest.raises(InvalidArgumentError, match='goal is "up"; expected "left" or "right"'):
        nav1d.Condition("far", "up", 0.0, 10.0)


def test_records_are_typed_arrays() -> None:
    config = presets.get("sequence-1bit")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    rec = sequence.run_trial(config, net, "1", sequence.timings(config, 0, 0, 0))
    assert isinstance(rec, _core.SequenceRecord)
    assert rec.outputs.shape == (len(rec.output), config.size) and rec.targets.dtype == np.int64
    assert rec.trigger_correct.dtype == bool and len(rec.r) == len(rec.targets)

    config = presets.get("nav1d-classifier")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    chain = nav1d.fresh_chains(config, 1, 2, 0)[0]
    rec = nav1d.record(config, net, chain)
    assert isinstance(rec, _core.Nav1dRecord) and rec.conditions == chain
    assert rec.outputs.shape == (len(rec.x), config.size) and rec.trial.dtype == np.int64
    assert rec.moving.dtype == bool and len(rec.reached) == len(rec.classification) == 2

    config = presets.get("landmark")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    rec = landmark.record(config, net, 2, seed=1, trial=1)
    assert isinstance(rec, _core.LandmarkRecord) and rec.landmark == 2
    steps = len(rec.input)
    assert rec.poses.shape == (steps, 3) and rec.echoes.shape == (steps, 2)
    assert rec.outputs.shape == (steps, config.size)
    assert rec.classification == rec.outputs[-1, 0]
    silent = np.isnan(rec.echoes[:, 0])
    assert np.array_equal(silent, np.isnan(rec.echoes[:, 1]))


def test_records_and_analysis_results_are_read_only() -> None:
    """The records and analysis results are frozen objects, and so are their arrays: writing into
    one raises instead of changing a result its to_dict() would not show."""
    config = presets.get("sequence-1bit")
    net = dnnevo.Network.random(config.size, config.n_inputs, seed=3)
    seq = sequence.run_trial(config, net, "1", sequence.timings(config, 0, 0, 0))
    config = presets.get("nav1d-classifier")
    nav = nav1d.record(config, dnnevo.Network.random(config.size, config.n_inputs, seed=3),
                       nav1d.fresh_chains(config, 1, 2, 0)[0])
    config = presets.get("landmark")
    land = landmark.record(config, dnnevo.Network.random(config.size, config.n_inputs, seed=3), 2,
                           seed=1, trial=1)
    [equilibrium, *_] = dnnevo.analysis.equilibria(dnnevo.Network.random(3, 1, seed=0), [0.0])
    arrays = [seq.outputs, seq.targets, seq.trigger_correct, seq.r, nav.outputs, nav.trial, nav.moving,
              nav.x, land.input, land.poses, land.echoes, equilibrium.state, equilibrium.eigenvalues]
    for array in arrays:
        assert not array.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            array[0] = array[0]


def test_task_params_changed_in_place_are_refused_not_ignored() -> None:
    config = presets.get("sequence-1bit")
    config.task_params["targets"] = ["01", "10"]
    with pytest.raises(ConfigError, match="task_params was changed in place"):
        sequence.target_list(config)
    fresh = dataclasses.replace(config, task_params=dict(config.task_params))
    assert sequence.target_list(fresh) == ["01", "10"]
