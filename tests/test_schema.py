"""docs/network.schema.json against example documents and against what dnnevo reads and writes."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import numpy as np
import pytest
from jsonschema import Draft202012Validator

try:
    import dnnevo
except ImportError:  # the schema checks still run; test_reference.py fails loudly instead
    dnnevo = None

needs_dnnevo = pytest.mark.skipif(dnnevo is None, reason="dnnevo is not importable")

DOCS = Path(__file__).resolve().parent.parent / "docs"
SCHEMA = json.loads((DOCS / "network.schema.json").read_text())
VALIDATOR = Draft202012Validator(SCHEMA)


def is_valid(doc) -> bool:
    return VALIDATOR.is_valid(doc)


MINIMAL = {
    "format": "dnnevo-network",
    "version": 1,
    "tau": [1.0],
    "theta": [0.0],
    "weights": [[0.0]],
    "sensor_weights": [[]],
}

FULL = {
    "format": "dnnevo-network",
    "version": 1,
    "tau": [0.30000000000000004, 7.0],
    "theta": [-16.0, 1e-300],
    "weights": [[0.0, 1.0], [-1.5, 5e-324]],
    "sensor_weights": [[0.5, 0.0, 1.0], [0.0, -2.0, 3.0]],
    "state": [0.1, -0.0],
    "integrator": {"method": "rk4", "dt": 0.05, "substeps": 10},
    "meta": {"task": "sequence-1bit", "seed": 3, "generation": 10, "fitness": 0.5,
             "dnnevo_version": "0.1.0", "input_labels": ["trigger", "reinforcement"],
             "output_labels": ["out"], "precision": "f64", "anything": {"else": [1, None]}},
}


def docs_example():
    """The first ```json block of docs/network-format.md."""
    text = (DOCS / "network-format.md").read_text()
    block = re.search(r"```json\n(.*?)```", text, re.S)
    assert block, "docs/network-format.md has no json example"
    return json.loads(block.group(1))


def edited(base, **changes):
    """A deep copy of `base` with top-level fields replaced; a value of `...` deletes the field."""
    doc = copy.deepcopy(base)
    for key, value in changes.items():
        if value is ...:
            del doc[key]
        else:
            doc[key] = value
    return doc


VALID = {
    "minimal": MINIMAL,
    "full": FULL,
    "no-sensors-two-neurons": edited(MINIMAL, tau=[1, 2], theta=[0, 0],
                                     weights=[[0, 1], [1, 0]], sensor_weights=[[], []]),
    "euler-integrator": edited(MINIMAL, integrator={"method": "euler", "dt": 0.1, "substeps": 1}),
    "empty-meta": edited(MINIMAL, meta={}),
}

# Documents that both the schema and dnnevo's reader reject, with a word the error must name.
INVALID = {
    "wrong-format": (edited(MINIMAL, format="other"), "format"),
    "version-2": (edited(MINIMAL, version=2), "version"),
    "no-format": (edited(MINIMAL, format=...), "format"),
    "no-tau": (edited(MINIMAL, tau=...), "tau"),
    "no-theta": (edited(MINIMAL, theta=...), "theta"),
    "no-weights": (edited(MINIMAL, weights=...), "weights"),
    "no-sensor-weights": (edited(MINIMAL, sensor_weights=...), "sensor_weights"),
    "unknown-field": (edited(MINIMAL, sensor_weight=[[]]), "sensor_weight"),
    "empty-tau": (edited(MINIMAL, tau=[], theta=[], weights=[], sensor_weights=[]), "tau"),
    "zero-tau": (edited(MINIMAL, tau=[0.0]), "tau[0]"),
    "negative-tau": (edited(FULL, tau=[1.0, -0.5]), "tau[1]"),
    "string-theta": (edited(MINIMAL, theta=["x"]), "theta[0]"),
    "null-weight": (edited(MINIMAL, weights=[[None]]), "weights[0][0]"),
    "flat-weights": (edited(MINIMAL, weights=[0.0]), "weights[0]"),
    "empty-state": (edited(MINIMAL, state=[]), "state"),
    "state-not-array": (edited(MINIMAL, state=0.0), "state"),
    "bad-method": (edited(MINIMAL, integrator={"method": "rk2", "dt": 0.1, "substeps": 1}),
                   "integrator"),
    "zero-dt": (edited(MINIMAL, integrator={"method": "euler", "dt": 0.0, "substeps": 1}),
                "dt"),
    "zero-substeps": (edited(MINIMAL, integrator={"method": "euler", "dt": 0.1, "substeps": 0}),
                      "substeps"),
    "no-dt": (edited(MINIMAL, integrator={"method": "euler", "substeps": 1}), "dt"),
    "integrator-extra": (edited(MINIMAL, integrator={"method": "euler", "dt": 0.1,
                                                     "substeps": 1, "order": 1}), "order"),
    "meta-not-object": (edited(MINIMAL, meta=[1]), "meta"),
}

# Valid to the schema, which cannot compare lengths, but rejected by the reader.
SHAPE_ERRORS = {
    "theta-too-short": (edited(FULL, theta=[0.0]), "theta"),
    "weights-too-few-rows": (edited(FULL, weights=[[0.0, 1.0]]), "weights"),
    "ragged-weights": (edited(FULL, weights=[[0.0, 1.0], [1.0]]), "weights[1]"),
    "ragged-sensor-weights": (edited(FULL, sensor_weights=[[0.5], [0.0, 1.0]]),
                              "sensor_weights[1]"),
    "state-too-long": (edited(FULL, state=[0.0, 0.0, 0.0]), "state"),
}


# ---------------------------------------------------------------------------------------------
# the schema alone


def test_schema_is_valid_draft_2020_12():
    assert SCHEMA["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    Draft202012Validator.check_schema(SCHEMA)


@pytest.mark.parametrize("name", sorted(VALID))
def test_valid_documents(name):
    VALIDATOR.validate(VALID[name])


def test_docs_example_is_valid():
    VALIDATOR.validate(docs_example())


@pytest.mark.parametrize("name", sorted(INVALID))
def test_invalid_documents(name):
    assert not is_valid(INVALID[name][0])


def test_schema_rejects_non_finite_and_bad_meta_conventions():
    assert not is_valid(edited(MINIMAL, theta=[float("inf")]))
    assert not is_valid(edited(MINIMAL, meta={"seed": "three"}))
    assert not is_valid(edited(MINIMAL, meta={"input_labels": "trigger"}))


@pytest.mark.parametrize("name", sorted(SHAPE_ERRORS))
def test_shape_errors_pass_the_schema(name):
    # Documented limit of JSON Schema: lengths are checked by the reader (see below).
    assert is_valid(SHAPE_ERRORS[name][0])


# ---------------------------------------------------------------------------------------------
# the schema against dnnevo's reader and writer


@needs_dnnevo
@pytest.mark.parametrize("name", sorted(VALID))
def test_reader_accepts_valid_documents(name):
    doc = VALID[name]
    net = dnnevo.Network.from_dict(doc)
    assert net.size == len(doc["tau"])
    assert net.n_inputs == len(doc["sensor_weights"][0])
    back = net.to_dict()
    VALIDATOR.validate(back)
    for key in ("tau", "theta", "weights", "sensor_weights"):
        assert back[key] == doc[key], key
    assert back["state"] == doc.get("state", [0.0] * net.size)
    assert back.get("integrator") == doc.get("integrator")
    assert back.get("meta", {}) == doc.get("meta", {})


@needs_dnnevo
def test_reader_accepts_docs_example():
    net = dnnevo.Network.from_dict(docs_example())
    assert (net.size, net.n_inputs) == (2, 1)
    assert net.weights[0, 1] == 4.0  # from neuron 1 to neuron 0, as the docs say


@needs_dnnevo
@pytest.mark.parametrize("name", sorted(INVALID) + sorted(SHAPE_ERRORS))
def test_reader_rejects_naming_the_field(name):
    doc, field = {**INVALID, **SHAPE_ERRORS}[name]
    with pytest.raises(dnnevo.FormatError) as info:
        dnnevo.Network.from_dict(doc)
    assert field in str(info.value), str(info.value)


@needs_dnnevo
@pytest.mark.parametrize("n,m", [(1, 0), (3, 1), (8, 2), (30, 3)])
def test_written_documents_validate(tmp_path, n, m):
    net = dnnevo.Network.random(n, m, seed=n + m)
    net.reset(np.linspace(-1.0, 1.0, n))
    VALIDATOR.validate(net.to_dict())
    VALIDATOR.validate(json.loads(net.to_json()))

    path = tmp_path / "net.json"
    meta = {"task": "test", "seed": 7, "generation": 3, "fitness": 0.25,
            "input_labels": [f"in{k}" for k in range(m)], "output_labels": ["out"]}
    net.save(path, meta=meta)
    assert [p.name for p in tmp_path.iterdir()] == ["net.json"], "no temporary file left"
    doc = json.loads(path.read_text())
    VALIDATOR.validate(doc)
    assert doc["meta"] == meta
    assert np.array_equal(np.array(doc["weights"]).reshape(n, n), net.weights)


@needs_dnnevo
def test_file_round_trip_is_exact(tmp_path):
    doc = copy.deepcopy(FULL)
    doc["tau"] = [0.1 + 0.2, 7.0 / 3.0]
    doc["state"] = [1.0 / 7.0, -1e-310]
    net = dnnevo.Network.from_dict(doc)
    first, second = tmp_path / "a.json", tmp_path / "b.json"
    net.save(first)
    again = dnnevo.Network.load(first)
    for key in ("tau", "theta", "weights", "sensor_weights", "state"):
        a, b = getattr(net, key), getattr(again, key)
        assert a.tobytes() == b.tobytes(), key
    again.save(second)
    assert first.read_bytes() == second.read_bytes()
    VALIDATOR.validate(json.loads(first.read_text()))
    assert json.loads(first.read_text())["integrator"] == FULL["integrator"]


@needs_dnnevo
def test_load_errors_name_the_file_and_the_field(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(edited(FULL, tau=[1.0, -0.5])))
    with pytest.raises(dnnevo.FormatError, match=r"tau\[1\]") as info:
        dnnevo.Network.load(path)
    assert "bad.json" in str(info.value)
    with pytest.raises(FileNotFoundError):
        dnnevo.Network.load(tmp_path / "missing.json")
