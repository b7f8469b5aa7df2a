"""The Network API: construction, validation errors, runs, files and composition."""

from __future__ import annotations

import copy
import json
import pickle
import re
from pathlib import Path

import numpy as np
import pytest

import dnnevo
from dnnevo import FormatError, InvalidArgumentError, InvalidNetworkError


def make(n: int = 3, m: int = 2, seed: int = 0) -> dnnevo.Network:
    rng = np.random.default_rng(seed)
    return dnnevo.Network(
        tau=rng.uniform(0.5, 10, n),
        theta=rng.uniform(-5, 5, n),
        weights=rng.uniform(-5, 5, (n, n)),
        sensor_weights=rng.uniform(-5, 5, (n, m)),
    )


def test_properties_are_read_only_numpy_copies() -> None:
    net = make()
    assert (net.size, net.n_inputs) == (3, 2)
    assert net.weights.shape == (3, 3) and net.sensor_weights.shape == (3, 2)
    # Writing to one fails loudly rather than changing nothing; a copy of it is the user's.
    for name in ("tau", "theta", "weights", "sensor_weights", "state", "outputs"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(net, name)[0] = 123.0
    w = net.weights.copy()
    w[0, 0] = 123.0
    assert net.weights[0, 0] != 123.0
    assert np.array_equal(net.state, np.zeros(3))


def test_weights_convention_is_from_j_to_i() -> None:
    # Neuron 1 listens to neuron 0 only; neuron 0 is pinned high by its threshold.
    w = np.zeros((2, 2))
    w[1, 0] = 4.0
    net = dnnevo.Network([1.0, 1.0], [-20.0, 0.0], w, np.zeros((2, 0)))
    trace = net.run(np.zeros((50, 0)), dt=0.1, substeps=5)
    assert trace.states[-1, 1] == pytest.approx(4.0, rel=1e-3)


def test_run_trace_and_state() -> None:
    net = make()
    inputs = np.ones((4, 2))
    trace = net.run(inputs, dt=0.05, substeps=2)
    assert trace.states.shape == (4, 3) and trace.outputs.shape == (4, 3)
    assert np.array_equal(trace.inputs, inputs)
    np.testing.assert_allclose(trace.time, [0.1, 0.2, 0.3, 0.4])
    np.testing.assert_array_equal(net.state, trace.states[-1])
    np.testing.assert_allclose(trace.outputs, 1 / (1 + np.exp(-(trace.states - net.theta))))
    net.reset()
    assert not net.state.any()
    net.reset([1.0, 2.0, 3.0])
    np.testing.assert_array_equal(net.state, [1.0, 2.0, 3.0])


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"tau": [1.0, -1.0, 1.0]}, "tau[1] is -1"),
        ({"tau": [1.0, 0.0, 1.0]}, "tau[1] is 0"),
        ({"theta": [0.0, np.nan, 0.0]}, "theta[1] is NaN"),
        ({"weights": np.full((3, 3), np.inf)}, "weights[0][0] is inf"),
        ({"weights": np.zeros((3, 2))}, "weights has shape (3, 2); expected (N, N) = (3, 3)"),
        ({"weights": np.zeros(9)}, "weights has shape (9,); expected (N, N)"),
        ({"sensor_weights": np.zeros((2, 2))}, "sensor_weights has shape (2, 2)"),
        ({"theta": [0.0]}, "theta has 1 value; expected N = 3"),
        ({"state": [0.0, 0.0]}, "state has 2 values"),
        ({"tau": []}, "at least 1 neuron"),
        ({"tau": ["a", "b", "c"]}, "tau is not a numeric array"),
        ({"tau": np.ones((3, 1))}, "tau has shape (3, 1); expected (N,)"),
    ],
)
def test_bad_parameters_raise_invalid_network(kwargs: dict, fragment: str) -> None:
    params = {
        "tau": np.ones(3),
        "theta": np.zeros(3),
        "weights": np.zeros((3, 3)),
        "sensor_weights": np.zeros((3, 1)),
    }
    params.update(kwargs)
    with pytest.raises(InvalidNetworkError) as info:
        dnnevo.Network(**params)
    assert fragment in str(info.value)
    assert isinstance(info.value, ValueError) and isinstance(info.value, dnnevo.DnnevoError)


@pytest.mark.parametrize(
    ("inputs", "kwargs", "fragment"),
    [
        (np.ones((5, 3)), {}, "inputs has shape (5, 3); expected (T, M) with M = 2"),
        (np.ones(5), {}, "inputs has shape (5,)"),
        (np.full((5, 2), np.nan), {}, "every input must be finite"),
        (np.ones((5, 2)), {"dt": -0.1}, "dt is -0.1"),
        (np.ones((5, 2)), {"dt": float("nan")}, "dt is NaN"),
        (np.ones((5, 2)), {"substeps": 0}, "substeps is 0"),
        (np.ones((5, 2)), {"substeps": -3}, "substeps is -3"),
        (np.ones((5, 2)), {"method": "rk5"}, 'method is "rk5"'),
    ],
)
def test_bad_run_arguments(inputs: np.ndarray, kwargs: dict, fragment: str) -> None:
    with pytest.raises(InvalidArgumentError) as info:
        make().run(inputs, **kwargs)
    assert fragment in str(info.value)


@pytest.mark.parametrize("substeps", [1.5, True, "2"])
def test_a_count_that_is_no_integer_is_a_type_error_naming_the_argument(substeps: object) -> None:
    with pytest.raises(TypeError, match=rf"^substeps is {re.escape(repr(substeps))}; it must be an integer in"):
        make().run(np.ones((5, 2)), substeps=substeps)
    assert make().run(np.ones((5, 2)), substeps=np.int64(2)).states.shape == (5, 3)


def test_a_step_too_long_for_a_time_constant_is_refused_not_integrated() -> None:
    """From dt / tau = 2 on (2.785 with RK4) a neuron's own decay grows at every step: the
    numbers would be a flicker, then overflow, not the network's dynamics."""
    net = dnnevo.Network([0.5, 0.04], [0.0, 0.0], np.zeros((2, 2)), np.ones((2, 1)))
    with pytest.raises(InvalidArgumentError, match=r"dt / tau is 2.5 for tau\[1\] = 0.04 \(dt 0.1\); "
                                                   r"from 2 on, Euler steps .* use dt < 0.08, or method rk4"):
        net.run(np.ones((100, 1)), dt=0.1)
    assert np.isfinite(net.run(np.ones((100, 1)), dt=0.1, method="rk4").states).all()
    with pytest.raises(InvalidArgumentError, match=r"from 2.785 on, RK4 steps"):
        net.run(np.ones((100, 1)), dt=0.12, method="rk4")
    with pytest.raises(InvalidArgumentError, match=r"network 1's tau\[1\] = 0.04"):
        dnnevo.Batch([dnnevo.Network.random(2, 1, seed=0), net], dt=0.1)
    with pytest.raises(InvalidArgumentError, match=r"network 1's tau\[1\]"):
        dnnevo.run_population([dnnevo.Network.random(2, 1, seed=0), net], np.ones((5, 1)), dt=0.1)


def test_an_overflow_at_a_short_step_is_not_blamed_on_the_step() -> None:
    # Two neurons always firing, each weighing 1e308 on both: the sum is past the largest f64.
    net = dnnevo.Network([1.0, 1.0], [-1e3, -1e3], np.full((2, 2), 1e308), np.zeros((2, 1)))
    with pytest.raises(InvalidArgumentError, match="diverged: .* dt / tau is 0.1 here, so the step is not the cause"):
        net.run(np.ones((3, 1)))


def test_file_round_trip_is_exact(tmp_path: Path) -> None:
    net = make(5, 2, seed=3)
    net.run(np.ones((7, 2)))
    path = tmp_path / "net.json"
    net.save(path, meta={"task": "demo", "seed": 3})
    back = dnnevo.Network.load(path)
    assert back == net
    for name in ("tau", "theta", "weights", "sensor_weights", "state"):
        assert np.array_equal(getattr(back, name), getattr(net, name))
    assert back.meta == {"task": "demo", "seed": 3}
    assert dnnevo.Network.from_dict(net.to_dict()) == net
    assert json.loads(path.read_text())["format"] == "dnnevo-network"
    assert [p.name for p in tmp_path.iterdir()] == ["net.json"]
    # Python's json module writes the same numbers back.
    assert dnnevo.Network.from_dict(json.loads(json.dumps(net.to_dict()))) == net


def test_copy_and_pickle() -> None:
    net = make()
    for other in (net.copy(), copy.copy(net), copy.deepcopy(net), pickle.loads(pickle.dumps(net))):
        assert other == net and other is not net


@pytest.mark.parametrize(
    ("mutate", "fragment"),
    [
        (lambda d: d.update(format="other"), 'expected "dnnevo-network"'),
        (lambda d: d.update(version=2), "version is 2"),
        (lambda d: d.pop("tau"), "missing field `tau`"),
        (lambda d: d.update(theta=[0.0]), "theta has 1 value;"),
        (lambda d: d.update(weights=[[0.0]]), "weights has 1 row;"),
        (lambda d: d.update(tau=[1.0, -1.0, 1.0]), "tau[1]"),
        (lambda d: d.update(theta=[0.0, "x", 0.0]), "theta[1]"),
        (lambda d: d.update(extra=1), "unknown field `extra`"),
        (lambda d: d.update(integrator={"method": "euler", "dt": 0, "substeps": 1}), "dt"),
    ],
)
def test_bad_documents_raise_format_error(mutate, fragment: str) -> None:  # noqa: ANN001
    d = make().to_dict()
    mutate(d)
    with pytest.raises(FormatError) as info:
        dnnevo.Network.from_dict(d)
    assert fragment in str(info.value)


def test_non_finite_in_dict_is_a_format_error() -> None:
    d = make().to_dict()
    d["theta"][0] = float("nan")
    with pytest.raises(FormatError, match=r"theta\[0\] is NaN"):
        dnnevo.Network.from_dict(d)
    d = make().to_dict()
    d["meta"] = {"labels": [object()]}
    with pytest.raises(FormatError, match=r"meta.labels\[0\] is of type object"):
        dnnevo.Network.from_dict(d)
    # NumPy arrays and scalars are accepted where lists and floats are.
    d = {k: np.asarray(v) if isinstance(v, list) else v for k, v in make().to_dict().items()}
    assert dnnevo.Network.from_dict(d) == make()


def test_corrupt_and_truncated_files(tmp_path: Path) -> None:
    path = tmp_path / "net.json"
    make().save(path)
    text = path.read_text()
    for bad in (text[: len(text) // 2], "", "\x00\x01garbage", "[]", "null"):
        path.write_text(bad)
        with pytest.raises(FormatError):
            dnnevo.Network.load(path)
    with pytest.raises(FileNotFoundError):
        dnnevo.Network.load(tmp_path / "missing.json")


def test_compose_keeps_each_part_when_cross_weights_are_zero() -> None:
    a, b = make(3, 2, seed=1), make(4, 2, seed=2)
    ab = dnnevo.compose(a, b)
    assert ab.size == 7
    np.testing.assert_array_equal(ab.weights[:3, 3:], 0.0)
    np.testing.assert_array_equal(ab.weights[3:, :3], 0.0)
    inputs = np.random.default_rng(0).uniform(-1, 1, (40, 2))
    ta, tb, tab = a.run(inputs, substeps=3), b.run(inputs, substeps=3), ab.run(inputs, substeps=3)
    # Same operations in the same order: identical, not just close.
    np.testing.assert_array_equal(tab.states[:, :3], ta.states)
    np.testing.assert_array_equal(tab.states[:, 3:], tb.states)
    with pytest.raises(InvalidNetworkError, match="same M"):
        dnnevo.compose(a, make(2, 1))


def test_population_matches_single_bit_for_bit() -> None:
    nets = [make(4, 2, seed=s) for s in range(13)]
    inputs = np.random.default_rng(1).uniform(-1, 1, (13, 30, 2))
    states = dnnevo.run_population(nets, inputs, substeps=2, method="rk4")
    assert states.shape == (13, 30, 4)
    for p, net in enumerate(nets):
        own = net.copy().run(inputs[p], substeps=2, method="rk4").states
        np.testing.assert_array_equal(states[p], own)
    final = dnnevo.run_population(nets, inputs[0], record=False)
    assert final.shape == (13, 4)
    # No steps, as Network.run: nothing recorded, the states as they were.
    assert dnnevo.run_population(nets, inputs[:, :0]).shape == (13, 0, 4)
    assert net.copy().run(inputs[0, :0]).states.shape == (0, 4)
    np.testing.assert_array_equal(dnnevo.run_population(nets, inputs[0, :0], record=False),
                                  [n.state for n in nets])


def test_population_from_stacked_arrays() -> None:
    nets = [make(3, 1, seed=s) for s in range(5)]
    stacked = {
        name: np.stack([getattr(n, name) for n in nets])
        for name in ("tau", "theta", "weights", "sensor_weights")
    }
    inputs = np.ones((10, 1))
    np.testing.assert_array_equal(
        dnnevo.run_population(stacked, inputs), dnnevo.run_population(nets, inputs)
    )
    stacked["tau"][2, 1] = -1.0
    with pytest.raises(InvalidNetworkError, match=r"network 2: tau\[1\]"):
        dnnevo.run_population(stacked, inputs)


@pytest.mark.parametrize(
    ("networks", "inputs", "error", "fragment"),
    [
        ([], np.ones((3, 1)), InvalidArgumentError, "at least 1 network"),
        ([1, 2], np.ones((3, 1)), InvalidArgumentError, "networks[0] is of type int"),
        (None, np.ones((3, 1)), InvalidArgumentError, "sequence of Network"),
        ("mixed", np.ones((3, 1)), InvalidArgumentError, "network 1 has N = 2"),
        ("ok", np.ones((3, 2)), InvalidArgumentError, "expected (T, M) or (P, T, M)"),
        ("ok", np.ones((4, 3, 1)), InvalidArgumentError, "with P = 2"),
        ({"tau": np.ones((2, 3))}, np.ones((3, 1)), InvalidNetworkError, 'no "theta"'),
    ],
)
def test_bad_population_arguments(networks, inputs, error, fragment) -> None:  # noqa: ANN001
    if networks == "mixed":
        networks = [make(3, 1), make(2, 1)]
    elif networks == "ok":
        networks = [make(3, 1), make(3, 1)]
    with pytest.raises(error) as info:
        dnnevo.run_population(networks, inputs)
    assert fragment in str(info.value)


def test_save_gives_an_integrator_that_load_keeps(tmp_path: Path) -> None:
    path = tmp_path / "i.json"
    net = make()
    assert net.integrator is None
    rk4 = {"method": "rk4", "dt": 0.05, "substeps": 10}
    net.save(path, integrator=rk4)
    back = dnnevo.Network.load(path)
    assert back.integrator == rk4 and json.loads(path.read_text())["integrator"] == rk4
    assert net.integrator is None, "save leaves the network itself as it was"
    inputs = np.ones((3, net.n_inputs))
    assert np.array_equal(back.run(inputs, **back.integrator).states, make().run(inputs, **rk4).states)
    back.save(path)  # a loaded network writes its own integrator back
    assert dnnevo.Network.load(path).integrator == rk4


@pytest.mark.parametrize("integrator, message", [
    ({"method": "rk4", "dt": 0.1}, "missing field `substeps`"),
    ({"method": "rk4", "dt": 0.1, "substeps": 1, "steps": 2}, "unknown field `steps`"),
    ({"method": "heun", "dt": 0.1, "substeps": 1}, "unknown variant `heun`"),
    ({"method": "euler", "dt": -1.0, "substeps": 1}, "dt is -1"),
    ({"method": "euler", "dt": 0.1, "substeps": 0}, "substeps"),
    ([("method", "euler")], "integrator must be a dict"),
])
def test_save_refuses_an_integrator_that_load_would_refuse(tmp_path: Path, integrator: object, message: str) -> None:
    path = tmp_path / "i.json"
    with pytest.raises(InvalidArgumentError, match=re.escape(message)):
        make().save(path, integrator=integrator)  # type: ignore[arg-type]
    assert not path.exists()


def test_save_refuses_meta_that_load_would_refuse(tmp_path: Path) -> None:
    path = tmp_path / "m.json"
    for meta, message in [({"seed": -1}, "meta.seed is -1"), ({"input_labels": [1]}, "meta.input_labels is [1]"),
                          ({"task": None}, "meta.task is null")]:
        with pytest.raises(InvalidArgumentError, match=re.escape(message)):
            make().save(path, meta=meta)
        assert not path.exists()
    make().save(path, meta={"seed": 2.0, "notes": [None, {"x": 1}]})  # the schema's integer; free keys
    assert dnnevo.Network.load(path).meta["notes"] == [None, {"x": 1}]


def test_random_takes_ranges_as_config_toml_and_the_config_hold_them() -> None:
    from dnnevo import ConfigError, EvolutionConfig

    as_tuples = dnnevo.Network.random(3, 1, seed=4, ranges={"tau": (1.0, 2.0)})
    assert dnnevo.Network.random(3, 1, seed=4, ranges={"tau": [1.0, 2.0]}) == as_tuples
    assert ((as_tuples.tau >= 1.0) & (as_tuples.tau <= 2.0)).all()
    config = EvolutionConfig()
    assert dnnevo.Network.random(3, 1, seed=4, ranges=config.ranges) == dnnevo.Network.random(3, 1, seed=4)
    with pytest.raises(ConfigError, match=r'ranges\["tau"\] must be a pair \[low, high\]; it is \[1.0, 2.0, 3.0\]'):
        dnnevo.Network.random(3, 1, seed=4, ranges={"tau": [1.0, 2.0, 3.0]})
    with pytest.raises(ConfigError, match="ranges must be a dict"):
        dnnevo.Network.random(3, 1, seed=4, ranges=[1.0, 2.0])


@pytest.mark.parametrize("dt, shown", [("x", "'x'"), (True, "True"), (np.True_, "np.True_"), (None, "None"),
                                       (np.ones(3), "an array of dtype float64 and shape (3,)")])
@pytest.mark.parametrize("call", ["run", "run_population", "Batch"])
def test_a_time_step_that_is_no_number_is_a_type_error_naming_dt(call: str, dt: object, shown: str) -> None:
    """pyo3 said only "must be real number, not str"; a bool was taken as 1.0."""
    net = make(3, 1)
    calls = {"run": lambda: net.run(np.ones((3, 1)), dt=dt),
             "run_population": lambda: dnnevo.run_population([net], np.ones((3, 1)), dt=dt),
             "Batch": lambda: dnnevo.Batch([net], dt=dt)}
    with pytest.raises(TypeError) as e:
        calls[call]()
    assert str(e.value) == f"dt is {shown}; expected a number"
    # Any number Python takes as a float is one.
    assert net.copy().run(np.ones((2, 1)), dt=np.float32(0.5)).time[-1] == 1.0


def test_an_argument_is_quoted_on_one_line() -> None:
    """An array where a number belongs is named by its dtype and shape, not a repr of many lines."""
    with pytest.raises(dnnevo.InvalidArgumentError,
                       match=r"^size is an array of dtype float64 and shape \(30, 30\); it must be an integer"):
        dnnevo.Network.random(np.ones((30, 30)), 1, seed=0)
    with pytest.raises(TypeError, match=r"^seed is 'x{79}\.\.\.; expected an integer$"):
        dnnevo.Network.random(3, 1, seed="x" * 200)


def test_a_genome_makes_its_network_and_a_population_its_stacked_arrays() -> None:
    """An optimiser of one's own: Network.from_genome inverts genome(), and stack_genomes gives
    the arrays run_population, Batch and rollout take, scoring the bits of the networks."""
    from dnnevo.closedloop import FarSeeker, rollout

    nets = [make(3, 1, seed=s) for s in range(5)]
    genomes = np.stack([n.genome() for n in nets])
    assert genomes.shape == (5, 3 * (2 + 1 + 3))
    again = [dnnevo.Network.from_genome(g, size=3, n_inputs=1) for g in genomes]
    for a, b in zip(again, nets, strict=True):
        for name in ("tau", "theta", "weights", "sensor_weights"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    stacked = dnnevo.stack_genomes(genomes, size=3, n_inputs=1)
    for rows in (None, 4):  # every episode at once, and queued in 4 rows
        by_arrays = rollout(stacked, FarSeeker(), episodes=2, max_steps=40, rows=rows)
        by_networks = rollout(nets, FarSeeker(), episodes=2, max_steps=40, rows=rows)
        np.testing.assert_array_equal(by_arrays.returns, by_networks.returns)
    with pytest.raises(InvalidArgumentError, match=r"genomes has shape \(5, 17\); expected \(P, G\) with "
                                                   r"G = N x \(2 \+ M \+ N\) = 18"):
        dnnevo.stack_genomes(genomes[:, :-1], size=3, n_inputs=1)
    with pytest.raises(InvalidArgumentError, match="genome has 17 genes"):
        dnnevo.Network.from_genome(genomes[0, :-1], size=3, n_inputs=1)
    bad = genomes.copy()
    bad[2, 0] = -1.0
    with pytest.raises(InvalidNetworkError, match="tau"):
        dnnevo.run_population(dnnevo.stack_genomes(bad, size=3, n_inputs=1), np.ones((2, 1)))
    with pytest.raises(InvalidNetworkError, match=r"gene 0 \(neuron 0, tau\[0\]\) is -1"):
        dnnevo.Network.from_genome(bad[2], size=3, n_inputs=1)


def _beer_euler(taus, biases, gains, w, y, inputs, dt):
    """A plain port of Beer's CTRNN::EulerStep (w[j][i] from j to i): the states after each step."""
    out = []
    for row in inputs:
        rates = 1.0 / (1.0 + np.exp(-(gains * (y + biases))))
        y = y + dt / taus * (row + w.T @ rates - y)
        out.append(y)
    return np.array(out)


def test_a_network_in_beer_s_conventions_gives_beer_s_firing_rates() -> None:
    from dnnevo.beer import from_beer

    rng = np.random.default_rng(3)
    n = 4
    taus, biases = rng.uniform(0.5, 5, n), rng.uniform(-5, 5, n)
    gains, w, y0 = rng.uniform(-2, 3, n), rng.uniform(-8, 8, (n, n)), rng.uniform(-1, 1, n)
    inputs = rng.uniform(-1, 1, (300, n))
    beer = _beer_euler(taus, biases, gains, w, y0, inputs, 0.01)
    trace = from_beer(taus, biases, gains, w, states=y0).run(inputs, dt=0.01)
    np.testing.assert_allclose(trace.outputs, 1.0 / (1.0 + np.exp(-(gains * (beer + biases)))), rtol=0, atol=1e-13)
    np.testing.assert_allclose(trace.states, gains * beer, rtol=0, atol=1e-12)
    with pytest.raises(InvalidNetworkError, match=r"weights has shape \(3, 4\); expected \(N, N\) = \(4, 4\)"):
        from_beer(taus, biases, gains, w[:3])
    with pytest.raises(InvalidNetworkError, match=r"gains has shape \(3,\); expected \(N,\)"):
        from_beer(taus, biases, gains[:3], w)


def test_beer_s_parameter_names_point_to_the_conversion() -> None:
    """A setting, a range or a network-file field named as in Beer's code says what dnnevo has."""
    import json

    from dnnevo.config import apply_overrides

    for item in ("ranges.bias=[-16,16]", "gains=1"):
        with pytest.raises(dnnevo.ConfigError, match=r"dnnevo has no biases or gains: theta = -bias"):
            apply_overrides(dnnevo.EvolutionConfig(), [item])
    doc = json.loads(make(2, 1).to_json())
    doc["biases"] = [0.0, 0.0]
    with pytest.raises(dnnevo.FormatError, match=r"unknown field `biases`: this format has thresholds, theta = -bias"):
        dnnevo.Network.from_json(json.dumps(doc))


def test_more_refusals_from_a_review_name_the_argument() -> None:
    """A number too large for a float is no type error; a network of 0 neurons is named by its
    argument; ragged genomes, a class for an environment, a malformed stacked tau and a result
    for a history are named, not left to NumPy or Python."""
    from dnnevo.closedloop import FarSeeker, rollout

    net = make(2, 1)
    with pytest.raises(InvalidArgumentError, match=r"^dt is 1148\d+\.\.\.; it must be a finite number$"):
        net.run(np.ones((2, 1)), dt=2**2000)
    for call in (lambda: dnnevo.Network.from_genome([], size=0, n_inputs=0),
                 lambda: dnnevo.Network.random(0, 1, seed=0)):
        with pytest.raises(InvalidArgumentError, match="^size is 0; a network needs at least 1 neuron$"):
            call()
    with pytest.raises(InvalidArgumentError, match=r"genomes must be an array \(P, G\) of numbers"):
        dnnevo.stack_genomes([[1.0] * 17, [1.0] * 18], size=3, n_inputs=1)
    with pytest.raises(dnnevo.TaskError, match=r"env is the class FarSeeker; give an environment made from it"):
        rollout([make(3, 1)], FarSeeker, max_steps=3)
    stacked = dnnevo.stack_genomes(np.stack([make(3, 1, seed=s).genome() for s in range(2)]), size=3, n_inputs=1)
    with pytest.raises(dnnevo.InvalidNetworkError):
        rollout({**stacked, "tau": 1.0}, FarSeeker(), max_steps=3, rows=3)
    from types import MappingProxyType
    assert rollout(MappingProxyType(stacked), FarSeeker(), max_steps=3).returns.shape == (2, 1)
    with pytest.raises(InvalidNetworkError, match="^sensor_weights is None; expected an array of numbers$"):
        dnnevo.Network(tau=[1.0], theta=[0.0], weights=[[0.0]], sensor_weights=None)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="history is a Network; expected a mapping of columns"):
        dnnevo.plot.plot_fitness(net)  # type: ignore[arg-type]


def test_stacked_arrays_may_be_any_mapping_and_beer_s_arguments_are_named() -> None:
    """From a second review: run_population and Batch take any mapping of stacked arrays (a dict
    alone before), with state None as absent; from_beer names Beer's argument and index; a bool
    in a 0-d array is no time step, and compose names its cross_scale."""
    from types import MappingProxyType

    from dnnevo.beer import from_beer

    nets = [make(3, 1, seed=s) for s in range(3)]
    stacked = dnnevo.stack_genomes(np.stack([n.genome() for n in nets]), size=3, n_inputs=1)
    x = np.ones((2, 1))
    want = dnnevo.run_population(nets, x)
    np.testing.assert_array_equal(dnnevo.run_population(MappingProxyType(stacked), x), want)
    np.testing.assert_array_equal(dnnevo.run_population({**stacked, "state": None}, x), want)
    assert dnnevo.Batch(MappingProxyType(stacked)).rows == 3
    with pytest.raises(InvalidArgumentError, match="genomes is None"):
        dnnevo.stack_genomes(None, size=3, n_inputs=1)  # type: ignore[arg-type]
    good = ([1.0, 1.0], [0.0, 0.0], [1.0, 1.0], [[0.0, 1.0], [2.0, 0.0]])
    for at, value, message in [(1, [np.nan, 0.0], r"biases\[0\] is nan"),
                               (3, [[0.0, np.nan], [0.0, 0.0]], r"weights\[0\]\[1\] is nan"),
                               (2, [True, False], "gains is an array of dtype bool"),
                               (3, None, "weights is None")]:
        args = list(good)
        args[at] = value
        with pytest.raises(InvalidNetworkError, match=message):
            from_beer(*args)
    with pytest.raises(TypeError, match=r"^dt is array\(True\); expected a number$"):
        nets[0].run(x, dt=np.array(True))
    with pytest.raises(TypeError, match="^cross_scale is 'x'; expected a number$"):
        dnnevo.compose(nets[0], nets[1], cross_scale="x")  # type: ignore[arg-type]
