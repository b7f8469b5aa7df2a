"""dnnevo's integrators against the independent NumPy reference in tests/reference.py.

Every comparison asks for agreement to within 1e-12 (relative and absolute): the two codes sum in
different orders, so they differ in the last bits, but they implement the same arithmetic.
Runs are kept short enough (a few hundred steps) that rounding differences cannot grow visibly.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import reference as ref

import dnnevo


TOL = dict(rtol=1e-12, atol=1e-12)
SIZES = [1, 2, 5, 10, 30]
N_INPUTS = [0, 1, 3]
METHODS = ["euler", "rk4"]
SUBSTEPS = [1, 5]
T = 40  # input rows per run
P = dnnevo.LANES + 3  # networks per population: more than one block, with a ragged remainder


# ---------------------------------------------------------------------------------------------
# helpers


def random_arrays(rng, n, m, *, state=True):
    """Parameters drawn uniformly over the ranges of docs/paper.md, plus a random start state."""
    return dict(
        tau=rng.uniform(0.5, 10.0, n),
        theta=rng.uniform(-16.0, 16.0, n),
        weights=rng.uniform(-16.0, 16.0, (n, n)),
        sensor_weights=rng.uniform(-16.0, 16.0, (n, m)),
        state=rng.uniform(-5.0, 5.0, n) if state else None,
    )


def params_of(net):
    return dict(tau=net.tau, theta=net.theta, weights=net.weights,
                sensor_weights=net.sensor_weights, state=net.state)


def make_inputs(rng, t, m):
    """A mix of square pulses and noise in [0, 1]: inputs switch on and off during the run."""
    if m == 0:
        return np.zeros((t, 0))
    pulses = (np.arange(t)[:, None] // (3 + np.arange(m)[None, :] * 2)) % 2
    return np.where(rng.random((t, m)) < 0.3, rng.random((t, m)), pulses.astype(float))


def ref_run(p, inputs, **kw):
    return ref.run(p["tau"], p["theta"], p["weights"], p["sensor_weights"], inputs,
                   p.get("state"), **kw)


def stack(params):
    """Stacks a list of parameter dicts into batched arrays with a leading axis P."""
    return {k: np.stack([p[k] for p in params]) for k in params[0]}


# ---------------------------------------------------------------------------------------------
# single networks


@pytest.mark.parametrize("method,substeps", list(itertools.product(METHODS, SUBSTEPS)))
@pytest.mark.parametrize("m", N_INPUTS)
@pytest.mark.parametrize("n", SIZES)
def test_run_random_network(n, m, method, substeps):
    seed = 1000 * n + 10 * m + substeps
    net = dnnevo.Network.random(n, m, seed=seed)
    assert (net.size, net.n_inputs) == (n, m)
    p = params_of(net)
    inputs = make_inputs(np.random.default_rng(seed), T, m)
    kw = dict(dt=0.1, substeps=substeps, method=method)

    trace = net.run(inputs, **kw)
    expected = ref_run(p, inputs, **kw)

    assert trace.states.shape == (T, n)
    assert trace.outputs.shape == (T, n)
    np.testing.assert_allclose(trace.states, expected, **TOL)
    np.testing.assert_allclose(trace.outputs, ref.sigmoid(expected - p["theta"]), **TOL)
    np.testing.assert_array_equal(np.asarray(trace.inputs), inputs)
    np.testing.assert_allclose(trace.time, 0.1 * substeps * np.arange(1, T + 1), **TOL)
    np.testing.assert_array_equal(net.state, trace.states[-1])


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("n,m", [(1, 0), (2, 1), (5, 3), (10, 1), (30, 3)])
def test_run_given_arrays_and_state(n, m, method):
    rng = np.random.default_rng(7 * n + m)
    p = random_arrays(rng, n, m)
    net = dnnevo.Network(**p)
    for key in ("tau", "theta", "weights", "sensor_weights", "state"):
        np.testing.assert_array_equal(getattr(net, key), p[key], err_msg=key)
    inputs = make_inputs(rng, T, m)
    for dt, substeps in [(0.1, 1), (0.05, 5), (0.3, 2)]:
        kw = dict(dt=dt, substeps=substeps, method=method)
        fresh = dnnevo.Network(**p)
        np.testing.assert_allclose(fresh.run(inputs, **kw).states, ref_run(p, inputs, **kw),
                                   **TOL)


def test_weights_convention():
    """weights[i][j] is the weight from neuron j to neuron i (one hand-computed Euler step)."""
    tau, theta = np.array([1.0, 2.0]), np.array([0.0, 0.0])
    weights = np.array([[0.0, 4.0], [0.0, 0.0]])  # only neuron 1 -> neuron 0
    sensor = np.array([[0.0], [2.0]])  # only sensor 0 -> neuron 1
    net = dnnevo.Network(tau, theta, weights, sensor, state=np.array([0.0, 1.0]))
    states = net.run(np.array([[1.0]]), dt=0.1).states
    f1 = 1.0 / (1.0 + np.exp(-1.0))
    v0 = 0.1 / 1.0 * (0.0 + 4.0 * f1)
    v1 = 1.0 + 0.1 / 2.0 * (-1.0 + 0.0 + 2.0 * 1.0)
    np.testing.assert_allclose(states[0], [v0, v1], **TOL)


def test_state_carries_over_and_reset():
    """Two runs in a row equal one run over the joined inputs; reset() starts again."""
    rng = np.random.default_rng(3)
    p = random_arrays(rng, 5, 2, state=False)
    inputs = make_inputs(rng, 30, 2)
    for method in METHODS:
        net = dnnevo.Network(**{k: v for k, v in p.items() if v is not None})
        a = net.run(inputs[:12], method=method, substeps=3).states
        b = net.run(inputs[12:], method=method, substeps=3).states
        whole = ref_run(p, inputs, method=method, substeps=3)
        np.testing.assert_allclose(np.concatenate([a, b]), whole, **TOL)
        net.reset()
        np.testing.assert_array_equal(net.state, np.zeros(5))
        np.testing.assert_allclose(net.run(inputs, method=method, substeps=3).states, whole,
                                   **TOL)


# ---------------------------------------------------------------------------------------------
# populations


@pytest.mark.parametrize("method,substeps", list(itertools.product(METHODS, SUBSTEPS)))
@pytest.mark.parametrize("m", N_INPUTS)
@pytest.mark.parametrize("n", SIZES)
def test_run_population(n, m, method, substeps):
    seed = 100_000 + 1000 * n + 10 * m + substeps
    rng = np.random.default_rng(seed)
    # Half from Network.random, half from arrays with a non-zero start state.
    nets = [dnnevo.Network.random(n, m, seed=seed + k) for k in range(P // 2)]
    nets += [dnnevo.Network(**random_arrays(rng, n, m)) for _ in range(P - P // 2)]
    params = [params_of(net) for net in nets]
    batch = stack(params)
    kw = dict(dt=0.1, substeps=substeps, method=method)

    shared = make_inputs(rng, T, m)
    expected = ref_run(batch, shared, **kw)
    assert expected.shape == (P, T, n)
    got = dnnevo.run_population(nets, shared, **kw)
    assert got.shape == (P, T, n)
    np.testing.assert_allclose(got, expected, **TOL)
    final = dnnevo.run_population(nets, shared, record=False, **kw)
    assert final.shape == (P, n)
    np.testing.assert_allclose(final, expected[:, -1], **TOL)

    # The same population given as a dict of stacked arrays.
    np.testing.assert_allclose(dnnevo.run_population(batch, shared, **kw), expected, **TOL)

    per_net = np.stack([make_inputs(rng, T, m) for _ in range(P)])
    expected = ref_run(batch, per_net, **kw)
    np.testing.assert_allclose(dnnevo.run_population(nets, per_net, **kw), expected, **TOL)
    np.testing.assert_allclose(dnnevo.run_population(nets, per_net, record=False, **kw),
                               expected[:, -1], **TOL)


def test_population_matches_single_runs():
    """A network gives the same states alone and inside a population."""
    rng = np.random.default_rng(11)
    nets = [dnnevo.Network(**random_arrays(rng, 4, 2)) for _ in range(9)]
    inputs = np.stack([make_inputs(rng, 25, 2) for _ in range(9)])
    for method in METHODS:
        pop = dnnevo.run_population(nets, inputs, method=method, substeps=2)
        for k, net in enumerate(nets):
            p = params_of(net)
            single = dnnevo.Network(**p).run(inputs[k], method=method, substeps=2).states
            np.testing.assert_allclose(pop[k], single, **TOL)
            np.testing.assert_allclose(pop[k], ref_run(p, inputs[k], method=method, substeps=2),
                                       **TOL)


# ---------------------------------------------------------------------------------------------
# property test


def _vec(draw, n, lo, hi):
    return draw(hnp.arrays(np.float64, n, elements=st.floats(lo, hi)))


@st.composite
def cases(draw):
    n = draw(st.integers(1, 4))
    m = draw(st.integers(0, 2))
    pop = draw(st.integers(1, 3))
    t = draw(st.integers(1, 12))
    nets = []
    for _ in range(pop):
        nets.append(dict(
            tau=_vec(draw, n, 0.5, 10.0),
            theta=_vec(draw, n, -16.0, 16.0),
            weights=_vec(draw, (n, n), -16.0, 16.0),
            sensor_weights=_vec(draw, (n, m), -16.0, 16.0),
            state=_vec(draw, n, -20.0, 20.0),
        ))
    inputs = _vec(draw, (pop, t, m), -2.0, 2.0)
    kw = dict(
        dt=draw(st.sampled_from([0.01, 0.05, 0.1, 0.25, 0.5])),
        substeps=draw(st.integers(1, 3)),
        method=draw(st.sampled_from(METHODS)),
    )
    return nets, inputs, kw


@settings(max_examples=60, deadline=None)
@given(cases())
def test_property_matches_reference(case):
    params, inputs, kw = case
    expected = [ref_run(p, inputs[k], **kw) for k, p in enumerate(params)]
    for k, p in enumerate(params):
        trace = dnnevo.Network(**p).run(inputs[k], **kw)
        np.testing.assert_allclose(trace.states, expected[k], **TOL)
    nets = [dnnevo.Network(**p) for p in params]
    np.testing.assert_allclose(dnnevo.run_population(nets, inputs, **kw), np.stack(expected),
                               **TOL)
    np.testing.assert_allclose(dnnevo.run_population(nets, inputs[0], **kw),
                               ref_run(stack(params), inputs[0], **kw), **TOL)


# ---------------------------------------------------------------------------------------------
# the reference itself


def test_reference_converges_at_the_expected_orders():
    """Halving dt shrinks Euler's error about 2x and RK4's about 16x: the reference is sound."""
    rng = np.random.default_rng(5)
    p = random_arrays(rng, 4, 1)
    inputs = np.ones((1, 1))
    exact = ref_run(p, inputs, dt=1 / 1024, substeps=1024, method="rk4")[-1]

    def error(method, k):
        return np.max(np.abs(ref_run(p, inputs, dt=1 / k, substeps=k, method=method)[-1] - exact))

    assert 1.6 < error("euler", 64) / error("euler", 128) < 2.4
    assert 12 < error("rk4", 16) / error("rk4", 32) < 20
