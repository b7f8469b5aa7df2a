"""``dnnevo.analysis``: equilibria, cycles and sweeps against closed-form cases and NumPy finite
differences, and lesions that are exact."""

from __future__ import annotations

import dataclasses
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from dnnevo import tasks
import dnnevo
from dnnevo import _core, analysis
from dnnevo import presets
from dnnevo.errors import InvalidArgumentError


def logit(p: float) -> float:
    return math.log(p / (1 - p))


def bistable_interval(w: float) -> tuple[float, float]:
    """One neuron ``v = w f(v - theta)``: bistable exactly for theta between the extremes of
    ``h(x) = w f(x) - x``, at ``f (1 - f) = 1/w`` (w > 4)."""
    r = math.sqrt(1 - 4 / w)
    return tuple(w * p - logit(p) for p in ((1 - r) / 2, (1 + r) / 2))  # type: ignore[return-value]


def one(w: float, theta: float) -> dnnevo.Network:
    return dnnevo.Network(tau=[2.0], theta=[theta], weights=[[w]], sensor_weights=[[1.0]])


@pytest.mark.parametrize("w", [3.0, 5.0, 9.0])
def test_one_neuron_bistable_region(w: float) -> None:
    lo, hi = bistable_interval(w) if w > 4 else (math.inf, -math.inf)
    for theta in np.linspace(-3, 12, 31):
        if min(abs(theta - lo), abs(theta - hi)) < 1e-3:
            continue
        eq = analysis.equilibria(one(w, float(theta)))
        expect = lo < theta < hi
        assert sum(e.stable for e in eq) == (2 if expect else 1), (w, theta)
        assert len(eq) == (3 if expect else 1)


def test_folds_at_the_closed_form_inputs() -> None:
    w, theta = 9.0, 2.0
    lo, hi = bistable_interval(w)
    b = analysis.bifurcation(one(w, theta), 0, -10.0, 5.0, steps=31)
    assert [e.kind for e in b.events] == ["fold", "fold"]
    assert [e.value for e in b.events] == pytest.approx([theta - hi, theta - lo], abs=1e-6)


def centre_pair(a: float, b: float) -> dnnevo.Network:
    return dnnevo.Network(tau=[1.0, 1.0], theta=[(a + b) / 2, (a - b) / 2], weights=[[a, b], [-b, a]],
                          sensor_weights=[[1.0], [0.0]])


def test_centre_crossing_equilibrium_and_eigenvalues() -> None:
    a, b = 3.0, 2.0
    net = centre_pair(a, b)
    (e,) = [e for e in analysis.equilibria(net) if np.allclose(e.state, net.theta, atol=1e-9)]
    assert e.outputs == pytest.approx([0.5, 0.5])
    assert e.eigenvalues == pytest.approx([complex(-1 + a / 4, b / 4), complex(-1 + a / 4, -b / 4)])
    assert e.stability == "stable_focus" and e.time_scale == pytest.approx(1 / (1 - a / 4))


def test_results_are_the_cores_types_with_arrays_and_plain_dicts() -> None:
    net = centre_pair(5.5, 2.0)
    (e,) = analysis.equilibria(net)
    (c,) = analysis.limit_cycles(net)
    b = analysis.bifurcation(net, 0, -2.0, 2.0, steps=5, cycle_starts=2)
    assert (type(e), type(c), type(b)) == (_core.Equilibrium, _core.Cycle, _core.Bifurcation)
    assert analysis.STABILITIES == tuple(_core.STABILITIES) and e.stability in analysis.STABILITIES
    assert e.eigenvalues.dtype == np.complex128 and c.output_range.shape == (2, 2)
    d = json.loads(json.dumps(e.to_dict()))
    assert d["eigenvalues"] == [[z.real, z.imag] for z in e.eigenvalues] and d["stability"] == e.stability
    assert "orbit" in c.to_dict() and "orbit" not in c.to_dict(orbit=False)
    bd = b.to_dict()
    assert bd["index"] == 0 and bd["input"] == [0.0] and bd["values"] == b.values.tolist()
    assert all("orbit" not in cycle for row in bd["cycles"] for cycle in row) and bd["even"] == b.even
    assert [len(row) for row in b.equilibria] == [len(row) for row in bd["equilibria"]]
    assert all(type(x) is _core.CycleBranch for x in b.branches)


def measured_period(net: dnnevo.Network) -> float:
    """The period of neuron 0 by the network's own RK4, from upward crossings of its threshold."""
    net = net.copy()
    states = net.run(np.zeros((20000, 1)), dt=0.01, method="rk4").states[:, 0]
    level = net.theta[0]
    ups = np.flatnonzero((states[:-1] < level) & (states[1:] >= level))[5:]
    return float(np.diff(ups).mean() * 0.01)


def test_oscillator_cycle_period_and_stability() -> None:
    net = centre_pair(5.5, 2.0)
    (e,) = analysis.equilibria(net)
    assert e.stability == "unstable_focus"
    (c,) = analysis.limit_cycles(net)
    assert c.stable and 0 < c.max_multiplier < 1
    assert c.period == pytest.approx(measured_period(net), rel=2e-3)
    assert np.min(np.abs(c.multipliers - 1)) < 1e-4
    assert c.orbit.shape == (200, 2)


def fd_jacobian(net: dnnevo.Network, u: np.ndarray, v: np.ndarray, h: float = 1e-6) -> np.ndarray:
    cols = []
    for j in range(len(v)):
        d = np.zeros_like(v)
        d[j] = h
        cols.append((analysis.vector_field(net, u, v + d) - analysis.vector_field(net, u, v - d)) / (2 * h))
    return np.array(cols).T


@pytest.mark.parametrize("seed", range(6))
def test_equilibria_are_zeros_with_finite_difference_eigenvalues(seed: int) -> None:
    n = 3 + seed
    net = dnnevo.Network.random(n, 2, seed=seed)
    u = np.array([0.3, 1.0])
    eq = analysis.equilibria(net, u)
    assert eq
    for e in eq:
        assert np.max(np.abs(analysis.vector_field(net, u, e.state) * net.tau)) < 1e-9
        ev = np.linalg.eigvals(fd_jacobian(net, u, e.state))
        ev = ev[np.lexsort((-ev.imag, -ev.real))]
        assert ev == pytest.approx(e.eigenvalues, abs=1e-5)


def test_bad_arguments() -> None:
    net = one(8.0, 4.0)
    with pytest.raises(InvalidArgumentError, match="input has 2 values"):
        analysis.equilibria(net, [0.0, 1.0])
    with pytest.raises(InvalidArgumentError, match="starts is 0"):
        analysis.equilibria(net, starts=0)
    with pytest.raises(InvalidArgumentError, match="seed is -1"):
        analysis.limit_cycles(net, seed=-1)
    # The argument is named as Python calls it, and NumPy integers are integers.
    for index in (3, np.int64(3), 1.0, True):
        with pytest.raises(InvalidArgumentError, match=rf"^index is {re.escape(repr(index))}; this network has 1 sensor,"):
            analysis.bifurcation(net, index, 0.0, 1.0)
    assert len(analysis.bifurcation(net, np.int64(0), 0.0, 1.0, steps=3).values) == 3
    with pytest.raises(InvalidArgumentError, match="different"):
        analysis.bifurcation(net, 0, 1.0, 1.0)
    with pytest.raises(InvalidArgumentError, match="neuron is 1"):
        analysis.clamp(net, 1, 0.5)
    with pytest.raises(InvalidArgumentError, match="output is 1.5"):
        analysis.clamp(net, 0, 1.5)
    with pytest.raises(InvalidArgumentError, match="target is -1"):
        analysis.cut(net, 0, -1)


def euler_with_clamp(net: dnnevo.Network, inputs: np.ndarray, neuron: int, output: float, dt: float) -> np.ndarray:
    """The model integrated in NumPy with ``neuron``'s firing rate replaced by ``output``."""
    v = np.zeros(net.size)
    rows = []
    for u in inputs:
        f = 1 / (1 + np.exp(-(v - net.theta)))
        f[neuron] = output
        v = v + dt / net.tau * (-v + net.weights @ f + net.sensor_weights @ u)
        rows.append(1 / (1 + np.exp(-(v - net.theta))))
    return np.array(rows)


def test_clamp_is_exact() -> None:
    net = dnnevo.Network.random(4, 2, seed=5)
    inputs = np.random.default_rng(0).uniform(0, 1, (300, 2))
    clamped = analysis.clamp(net, 2, 0.3)
    out = clamped.run(inputs, dt=0.1).outputs
    assert out[:, 2] == pytest.approx(0.3, abs=1e-15)
    want = euler_with_clamp(net, inputs, 2, 0.3, 0.1)
    others = [0, 1, 3]
    assert out[:, others] == pytest.approx(want[:, others], abs=1e-9)
    cut = analysis.cut(net, 1, 3)
    assert cut.weights[3, 1] == 0 and np.count_nonzero(cut.weights != net.weights) == 1


def test_a_lesion_mid_run_goes_on_from_the_network_s_state_and_takes_numpy_indices() -> None:
    net = dnnevo.Network.random(4, 2, seed=5)
    net.run(np.random.default_rng(1).uniform(0, 1, (50, 2)), dt=0.1)
    clamped, cut = analysis.clamp(net, np.int64(2), 0.3), analysis.cut(net, np.int32(1), np.int64(3))
    assert np.array_equal(cut.state, net.state)
    assert np.array_equal(clamped.state[[0, 1, 3]], net.state[[0, 1, 3]]) and clamped.state[2] == 0.0
    assert clamped.outputs[2] == pytest.approx(0.3, abs=1e-15)
    for bad in (np.bool_(True), 2.0, np.float64(1), 4, -1):
        with pytest.raises(InvalidArgumentError, match="it must be an integer in 0..3"):
            analysis.clamp(net, bad, 0.3)


def without_outgoing(net: dnnevo.Network, k: int) -> dnnevo.Network:
    w = net.weights.copy()
    w[:, k] = 0.0
    w[k, k] = net.weights[k, k]
    return dnnevo.Network(net.tau, net.theta, w, net.sensor_weights)


@pytest.mark.parametrize(("preset", "trials"), [("sequence-1bit", 30), ("nav1d-classifier", 30), ("landmark", 3)])
def test_lesioning_a_neuron_without_outgoing_weights_changes_no_score(preset: str, trials: int) -> None:
    config = presets.get(preset)
    seed = 11
    size, n_inputs = config.native.builtin().layout
    net = without_outgoing(dnnevo.Network.random(size, n_inputs, seed=7), size - 1)
    base = tasks.assess(config, net, trials, seed=seed)
    silent = tasks.assess(config, analysis.clamp(net, config.size - 1, 0.7), trials, seed=seed)
    assert silent.report == base.report
    # The control: clamping a neuron that drives the others (neuron 0's inputs) does change them.
    driver = int(np.argmax(np.abs(net.weights[0, :-1])))
    if driver == 0:
        driver = 1
    changed = tasks.assess(config, analysis.clamp(net, driver, 0.0 if net.outputs[driver] > 0.5 else 1.0),
                            trials, seed=seed)
    assert changed.report != base.report
    table = analysis.lesions(config, net, trials, seed=seed, cuts=2)
    assert [x.name.split(" at ")[0] for x in table.lesions][: config.size] == [f"clamp {i}" for i in range(config.size)]
    assert table.lesions[config.size - 1].drop == 0.0
    assert len(table.lesions) == config.size + 2


DATA = Path(__file__).resolve().parent / "data"


def test_every_change_in_the_equilibrium_count_of_a_champion_has_its_fold() -> None:
    """The champion of ``dnnevo run sequence-1bit --seed 0``: between reinforcement 0.06 and 0.07
    a pair of equilibria appears so close together that following one by bisection once jumped
    to its partner and the fold went unreported."""
    net = dnnevo.Network.load(DATA / "sequence-1bit-seed0-champion.json")
    b = analysis.bifurcation(net, 1, 0.0, 1.0, steps=101)
    counts = [len(row) for row in b.equilibria]
    assert counts[0] == 3 and counts[-1] == 1 and max(counts) == 5
    for s in range(len(counts) - 1):
        folds = [e for e in b.events if e.kind == "fold" and b.values[s] <= e.value <= b.values[s + 1]]
        assert 2 * len(folds) >= abs(counts[s + 1] - counts[s]), (b.values[s], counts[s], counts[s + 1])
    assert [round(e.value, 3) for e in b.events] == [0.061, 0.401, 0.601]


def test_replay_reproduces_a_recorded_trial_and_settles_to_names_attractors() -> None:
    config = presets.get("sequence-1bit")
    net = dnnevo.Network.load(DATA / "sequence-1bit-seed0-champion.json")
    (out0, in0), (out1, in1) = analysis.recorded_trials(config, net, seed=0)
    states = analysis.replay(config, net, in1)
    assert 1 / (1 + np.exp(-(states - net.theta))) == pytest.approx(out1, abs=1e-12)
    # A run in f32 is replayed in f32: its states are float32 values, its rates the recorded ones.
    single = dataclasses.replace(config, precision="f32")
    _, (out32, in32) = analysis.recorded_trials(single, net, seed=0)
    states32 = analysis.replay(single, net, in32)
    assert np.array_equal(states32.astype(np.float32), states32)
    assert 1 / (1 + np.exp(-(states32 - net.theta))) == pytest.approx(out32, abs=1e-6)
    stable = [e for e in analysis.equilibria(net, [0.0, 0.0]) if e.stable]
    assert len(stable) == 2
    # Each attractor's own state settles to it; a state far from both settles somewhere valid.
    assert analysis.settles_to(net, [e.state for e in stable], stable).tolist() == [0, 1]
    which = analysis.settles_to(net, states[::50], stable)
    assert set(which.tolist()) <= {0, 1}
    assert analysis.settles_to(net, [stable[0].state], stable[1:]).tolist() == [-1]
    with pytest.raises(InvalidArgumentError, match=rf"states have shape \(1, 3\); expected finite values with the last axis N = {net.size}"):
        analysis.settles_to(net, np.zeros((1, 3)), stable)
    with pytest.raises(InvalidArgumentError, match="duration is -1; expected a time > 0"):
        analysis.settles_to(net, [stable[0].state], stable, duration=-1)


def test_a_sweep_with_cycles_brackets_them_by_its_hopf_points() -> None:
    net = centre_pair(4.5, 4.0)
    b = analysis.bifurcation(net, 0, -4.0, 4.0, steps=33, cycle_starts=2)
    hopf = [e.value for e in b.events if e.kind == "hopf"]
    assert len(hopf) == 2
    inside = [len(c) for v, c in zip(b.values, b.cycles, strict=True) if hopf[0] + 0.3 < v < hopf[1] - 0.3]
    outside = [len(c) for v, c in zip(b.values, b.cycles, strict=True) if v < hopf[0] - 0.3 or v > hopf[1] + 0.3]
    assert inside and set(inside) == {1} and outside and set(outside) == {0}
    c = b.cycles[16][0]  # input 0: the centre-crossing oscillator
    assert c.stable and c.output_range.shape == (2, 2) and c.output_range[0, 0] < 0.5 < c.output_range[0, 1]
    assert b.to_dict()["cycles"][16][0]["period"] == c.period
    assert analysis.bifurcation(net, 0, -1.0, 1.0, steps=3).cycles == [[], [], []]


def hopf_at_one(a: float = 5.0, b: float = 4.0) -> dnnevo.Network:
    """The oscillator ``[[a, b], [-b, a]]`` with its Hopf point placed at input 1 in closed form:
    at ``v = theta + (x, x)`` with ``f(x) (1 - f(x)) = 1/a`` the Jacobian is ``[[0, b/a], [-b/a,
    0]]``, and these sensor weights make that state the equilibrium at input 1."""
    p = (1 + math.sqrt(1 - 4 / a)) / 2
    x, g = logit(p), p - 0.5
    return dnnevo.Network(tau=[1.0, 1.0], theta=[(a + b) / 2, (a - b) / 2], weights=[[a, b], [-b, a]],
                          sensor_weights=[[x - (a + b) * g], [x - (a - b) * g]])


def test_a_cycle_branch_ends_at_the_closed_form_hopf_point(tmp_path: Path) -> None:
    b = analysis.bifurcation(hopf_at_one(), 0, 0.0, 2.0, steps=24, cycle_starts=2)
    assert len(b.branches) == 1
    branch = b.branches[0]
    assert branch.start is None and branch.end is not None
    assert branch.end.kind == "hopf" and branch.end.value == pytest.approx(1.0, abs=1e-6)
    assert all(row == [0] * len(c) for row, c in zip(b.cycle_branch, b.cycles, strict=True))
    assert all(len(c) == 1 for v, c in zip(b.values, b.cycles, strict=True) if v < 0.9)
    d = json.loads(json.dumps(b.to_dict()))
    assert d["branches"][0]["end"]["kind"] == "hopf" and d["cycle_branch"][0] == [0]
    back = analysis.bifurcation(hopf_at_one(), 0, 2.0, 0.0, steps=24, cycle_starts=2)
    assert back.branches[0].end is None and back.branches[0].start is not None
    assert back.branches[0].start.value == pytest.approx(1.0, abs=1e-6)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from dnnevo.analysis import plot_bifurcation

    fig, ax = plt.subplots()
    assert plot_bifurcation(b, ax) is ax
    labels = ax.get_legend_handles_labels()[1]
    assert "cycle branch 0 (min, max)" in labels and "cycle ends at a Hopf point" in labels
    fig.savefig(tmp_path / "bif.png")
    plt.close(fig)


def uncoupled_pair() -> dnnevo.Network:
    """Two uncoupled self-exciting neurons (w = 8, theta = 4), the input driving neuron 0: 9
    equilibria between neuron 0's folds, 3 outside."""
    return dnnevo.Network(tau=[1.0, 1.0], theta=[4.0, 4.0], weights=[[8.0, 0.0], [0.0, 8.0]],
                          sensor_weights=[[1.0], [0.0]])


def test_an_even_count_is_searched_again_by_the_cores_rule() -> None:
    net = uncoupled_pair()
    assert analysis.RETRY_STARTS == _core.RETRY_STARTS == 8192
    assert len(analysis.equilibria(net, [0.0], starts=2, retry_starts=0)) == 2
    assert len(analysis.equilibria(net, [0.0], starts=2)) == 9
    assert len(analysis.attractors(net, [0.0]).equilibria) == 9
    lo, hi = bistable_interval(8.0)
    b = analysis.bifurcation(net, 0, -4.0, 4.0, steps=41, starts=2)
    assert b.retried and b.retried[0] == -4.0 and not b.even
    assert [len(r) for r in b.equilibria] == [9 if 4 - hi < v < 4 - lo else 3 for v in b.values]
    weak = analysis.bifurcation(net, 0, -4.0, 4.0, steps=41, starts=2, retry_starts=3)
    assert weak.even and set(weak.even) <= set(weak.retried)
    assert weak.to_dict()["even"] == weak.even
    from dnnevo.cli.analyze import summary

    lines = summary([analysis.attractors(net, [0.0])], weak, None, "input 0")
    assert any("count stays even" in line for line in lines), lines
    assert any("searched again with 8192 starts" in line for line in lines), lines
    with pytest.raises(InvalidArgumentError, match="retry_starts"):
        analysis.equilibria(net, [0.0], retry_starts=-1)


def test_folds_at_one_value_are_told_apart_in_the_report() -> None:
    """The seed-0 3-bit champion's reinforcement sweep has two folds at 0.4374 (two pairs: 11, 9
    then 7 equilibria); the report must not read as one fold printed twice."""
    net = dnnevo.Network.load(DATA / "sequence-3bit-seed0-champion.json")
    b = analysis.bifurcation(net, 1, 0.0, 1.0, steps=101)
    from dnnevo.cli.analyze import event_texts

    texts = event_texts(b.events)
    assert len(set(texts)) == len(texts), texts
    near = [t for t in texts if t.startswith(("fold at 0.43735 ", "fold at 0.43743 "))]
    assert len(near) == 2 and all("neuron" in t for t in near), near


def test_the_report_names_the_stable_equilibria_its_basins_count_in() -> None:
    """``dnnevo analyze`` calls the first condition's stable equilibria A, B, ...: it marks them
    where it prints them and says what they are on the line that counts the trials' basins."""
    from dnnevo.cli.analyze import summary

    net = dnnevo.Network(tau=[1.0], theta=[4.0], weights=[[8.0]], sensor_weights=[[1.0]])
    found = [analysis.attractors(net, [0.0], "off"), analysis.attractors(net, [3.0], "on")]
    sweep = analysis.bifurcation(net, 0, -4.0, 4.0, steps=41)
    lines = summary(found, sweep, None, "input 0", (1, np.array([0, 0, 0, 1, -1])), output=0)
    assert lines[:6] == [
        "input off [0]: 3 equilibria (2 stable: A, B), 0 attracting cycles",
        "  A stable node     outputs [0.02], time scale 1.2",
        "    unstable node   outputs [0.50], time scale 1",
        "  B stable node     outputs [0.98], time scale 1.2",
        "input on [3]: 1 equilibria (1 stable), 0 attracting cycles",  # only the first is lettered
        "    stable node     outputs [1.00], time scale 1.01",
    ]
    assert lines[-2:] == [
        "recorded trials: with input off held from each step on, the state would settle in A 60%, B 20%, none 20%",
        "    A, B: the stable equilibria of input off, marked above (output neuron 0 at 0.02 in A, 0.98 in B); "
        "none: no stable equilibrium reached (a cycle, or one not found)",
    ]


def test_dir_lists_only_the_public_names() -> None:
    """``dir(dnnevo.analysis)`` is its public API: ``__all__``, which lists every public name of
    its modules, and nothing else (no dunders, submodules or imported helpers)."""
    import importlib

    assert dir(analysis) == sorted(analysis.__all__)
    assert all(hasattr(analysis, name) and not name.startswith("_") for name in analysis.__all__)
    for module in ("dynamics", "lesions", "trials", "figures"):
        names = importlib.import_module(f"dnnevo.analysis.{module}").__all__
        assert set(names) <= set(analysis.__all__), (module, set(names) - set(analysis.__all__))


def test_a_sweep_neither_walks_past_a_fold_nor_misses_a_hopf_point_beside_a_node() -> None:
    # A hysteresis loop inside one sweep interval: linking the lower branch to the upper one by a
    # walk past the fold hid both folds; a finer sweep finds the same two.
    loop = dnnevo.Network.random(3, 1, seed=26)
    folds = [round(e.value, 4) for e in analysis.bifurcation(loop, 0, 0.84, 0.90, steps=2).events]
    assert folds == [round(e.value, 4) for e in analysis.bifurcation(loop, 0, 0.84, 0.90, steps=7).events]
    assert folds == [0.8618, 0.8705]
    # An unstable node at one value, a stable focus between, a stable node at the next: the
    # count of unstable eigenvalues changes with det's sign, so a complex pair crossed.
    node = dnnevo.Network.random(2, 1, seed=89)
    for steps in (3, 5):
        events = analysis.bifurcation(node, 0, 0.24, 0.30, steps=steps).events
        assert [(e.kind, round(e.value, 4)) for e in events] == [("hopf", 0.269)]


def test_a_real_setting_that_is_no_number_is_a_type_error_naming_it() -> None:
    """pyo3 said "must be real number" without the name, and took a bool as a number."""
    from dnnevo.analysis import bifurcation, equilibria, limit_cycles

    net = dnnevo.Network.random(3, 1, seed=0)
    for call, message in [(lambda: limit_cycles(net, [0.0], tolerance=True), "tolerance is True"),
                          (lambda: limit_cycles(net, [0.0], window="x"), "window is 'x'"),
                          (lambda: equilibria(net, [0.0], distinct=None), "distinct is None"),
                          (lambda: bifurcation(net, 0, True, 2.0), "start is True")]:
        with pytest.raises(TypeError, match=f"^{message}; expected a number$"):
            call()


def test_the_basins_figure_draws_no_input_in_the_outputs_colour() -> None:
    """With four or more inputs, matplotlib's own cycle would draw the fourth in the output's red."""
    from matplotlib.colors import to_rgba

    from dnnevo.analysis.figures import plot_basins

    steps = 12
    inputs = {f"input {k}": np.full(steps, 0.1 * k) for k in range(10)}
    ax = plot_basins(np.zeros((steps, 2)), inputs, np.zeros(steps, dtype=int), labels=["A"], neuron=1)
    lines = {line.get_label(): to_rgba(line.get_color()) for line in ax.get_lines()}
    output = lines.pop("output of neuron 1")
    assert len(lines) == 10 and output not in lines.values()
    assert len(set(list(lines.values())[:9])) == 9
