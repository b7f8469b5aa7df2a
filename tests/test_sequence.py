"""The sequence-learning task against the independent NumPy reference in sequence_reference.py.

One trial (R values and the output trace), the trial timings, the batched fitness of
``dnnevo.evaluate("sequence", ...)`` and the shape of ``dnnevo.tasks.sequence.assess``.
"""

from __future__ import annotations


import numpy as np
import pytest

import sequence_reference as ref

import dnnevo
import dnnevo.tasks.sequence as seq


TOL = 1e-9


def config(**task_params):
    """The sequence-1bit preset, with ``size`` and the integrator as keyword arguments and
    anything else overriding its task_params."""
    base = dnnevo.presets.get("sequence-1bit")
    d = base.to_dict()
    for key in ("size", "integrator"):
        if key in task_params:
            d[key] = task_params.pop(key)
    d["task_params"] = {**d["task_params"], **task_params}
    return dnnevo.EvolutionConfig.from_dict(d)


def protocol(cfg):
    """The reference's keyword arguments for a config."""
    p = cfg.task_params
    return dict(trigger_steps=p.get("trigger_steps", 10),
                reinforcement_steps=p.get("reinforcement_steps", 10),
                dt=cfg.integrator.dt, substeps=cfg.integrator.substeps)


def net_params(net):
    return net.tau, net.theta, net.weights, net.sensor_weights


def expected_inputs(timing, r, trigger_steps, reinforcement_steps):
    """The trigger and reinforcement input of every time step of a full trial."""
    trigger, reinforcement = [], []
    for phase, k, steps in ref.phases(timing, trigger_steps, reinforcement_steps):
        trigger += [1.0 if phase == ref.TRIGGER else 0.0] * steps
        reinforcement += [r[k] if phase == ref.REINFORCE else 0.0] * steps
    return np.array(trigger), np.array(reinforcement)


def check_trial(cfg, net, pattern, timing):
    rec = seq.run_trial(cfg, net, pattern, timing)
    kw = protocol(cfg)
    r, output = ref.run_trial(*net_params(net), pattern, timing, **kw)
    assert rec.r.shape == (len(timing),)
    np.testing.assert_allclose(rec.r, r, rtol=0, atol=TOL)
    assert rec.output.shape == output.shape
    np.testing.assert_allclose(rec.output, output, rtol=0, atol=TOL)
    # The inputs the network saw, and the per-trigger summaries of the trace.
    trigger, reinforcement = expected_inputs(timing, rec.r, kw["trigger_steps"],
                                             kw["reinforcement_steps"])
    np.testing.assert_array_equal(rec.trigger, trigger)
    np.testing.assert_array_equal(rec.reinforcement, reinforcement)
    windows = rec.output[trigger == 1.0].reshape(len(timing), kw["trigger_steps"])
    np.testing.assert_allclose(rec.mean_output, windows.mean(axis=1), rtol=0, atol=1e-12)
    bits = np.array([int(pattern[k % len(pattern)]) for k in range(len(timing))])
    np.testing.assert_array_equal(rec.targets, bits)
    want_correct = np.where(bits == 1, rec.mean_output > 0.5, rec.mean_output < 0.5)
    np.testing.assert_array_equal(rec.trigger_correct, want_correct)
    assert rec.outputs.shape == (len(output), net.size)
    np.testing.assert_array_equal(rec.outputs[:, 0], rec.output)
    return rec


@pytest.mark.parametrize("size", [5, 10])
@pytest.mark.parametrize("pattern", ["0", "1", "01", "10", "011"])
def test_trial_matches_reference(size, pattern):
    cfg = config(size=size)
    for s in range(2):
        net = dnnevo.Network.random(size, 2, seed=100 * size + 7 * s + len(pattern))
        timing = seq.timings(cfg, s, 3 + s, len(pattern))
        rec = check_trial(cfg, net, pattern, timing)
        assert rec.target == pattern


def test_trial_matches_reference_with_other_settings():
    cfg = config(trigger_steps=4, reinforcement_steps=3, delay=[0, 5], gap=[2, 2], triggers=7,
                 integrator={"method": "euler", "dt": 0.05, "substeps": 20})
    for s in range(3):
        timing = seq.timings(cfg, 11, s, 0)
        assert len(timing) == 7
        assert all(0 <= d <= 5 and g == 2 for d, g in timing)
        check_trial(cfg, dnnevo.Network.random(5, 2, seed=40 + s), "011", timing)


def test_trials_are_not_trivial():
    """The random networks of these tests earn a spread of R, not a constant."""
    cfg = config()
    rs = np.concatenate([
        seq.run_trial(cfg, dnnevo.Network.random(5, 2, seed=s), "01", seq.timings(cfg, 0, 0, 0)).r
        for s in range(8)
    ])
    assert np.ptp(rs) > 0.3
    assert ((rs > 0.01) & (rs < 0.99)).any()


def test_batched_reference_equals_single_reference():
    nets = [dnnevo.Network.random(5, 2, seed=s) for s in range(6)]
    timing = [(12, 30), (0, 10), (40, 0)]
    batch = ref.run_trials(ref.stack_networks(nets), "10", timing)
    full = ref.run_trials(ref.stack_networks(nets), "10", timing, full=True)
    np.testing.assert_array_equal(batch, full)
    for i, net in enumerate(nets):
        r, _ = ref.run_trial(*net_params(net), "10", timing)
        np.testing.assert_allclose(batch[i], r, rtol=0, atol=1e-12)


def test_decode_genomes_matches_networks():
    ga = dnnevo.GeneticAlgorithm(config(), seed=3)
    genomes, nets = ga.ask()
    for mine, theirs in zip(ref.decode_genomes(genomes[:10], 5, 2), ref.stack_networks(nets[:10])):
        np.testing.assert_array_equal(mine, theirs)


@pytest.mark.parametrize("seed", [0, 1, 12345])
def test_timings_within_range(seed):
    cfg = config()
    draws = []
    for generation in range(4):
        for trial in range(4):
            timing = seq.timings(cfg, seed, generation, trial)
            assert len(timing) == 10
            assert timing == seq.timings(cfg, seed, generation, trial)
            draws.extend(timing)
    draws = np.array(draws)
    assert draws.min() >= 10 and draws.max() <= 40
    assert draws.dtype.kind == "i"
    # 128 draws of each: both ends of the range reachable, several distinct values.
    assert len(np.unique(draws)) > 15
    assert seq.timings(cfg, seed, 0, 0) != seq.timings(cfg, seed, 0, 1)
    assert seq.timings(cfg, seed, 0, 0) != seq.timings(cfg, seed, 1, 0)


def silent_network(size=5):
    """Output f(0 - 50) ~ 2e-22 forever: no weights, no sensors, threshold +50."""
    return dnnevo.Network(tau=np.ones(size), theta=np.full(size, 50.0),
                          weights=np.zeros((size, size)), sensor_weights=np.zeros((size, 2)))


def test_switch_table_of_a_silent_network():
    cfg = config(targets=["0", "1", "01"])
    table = seq.switch_table(cfg, silent_network(), 6, 3)
    pairs = {(s.first, s.second): s for s in table}
    assert list(pairs) == [("0", "1"), ("0", "01"), ("1", "0"), ("1", "01"), ("01", "0"), ("01", "1")]
    # Always 0: right at once on 0*, never on 1*; on (01)* the 1s after the switch are wrong.
    for first in ("1", "01"):
        assert pairs[(first, "0")].settled_after == (0,) * 6
        assert pairs[(first, "0")].median_triggers == 0.0
    for first, second in [("0", "1"), ("0", "01"), ("1", "01"), ("01", "1")]:
        assert pairs[(first, second)].settled == 0 and pairs[(first, second)].median_triggers is None
    # Trial j has fresh timings 2j and 2j + 1, never evolution's.
    a, b, _ = seq.switch_trial(cfg, silent_network(), "1", "0",
                               seq.fresh_timings(cfg, 3, 0) + seq.fresh_timings(cfg, 3, 1))
    assert len(a.r) == 8 and len(b.r) == 12
    assert seq.fresh_timings(cfg, 3, 0) != seq.timings(cfg, 3, 0, 0)
    # A switch counts only when the answers stay right for SWITCH_HOLD triggers to the end. The
    # second pattern continues the first's phase: after 8 triggers it is read from index 8 on.
    assert seq.SWITCH_HOLD == 4
    timing = seq.fresh_timings(cfg, 3, 0) + seq.fresh_timings(cfg, 3, 1)
    for tail, settled in [("111111110000", 8), ("111111111000", None)]:
        assert seq.switch_trial(cfg, silent_network(), "0", "0" * 8 + tail, timing)[2] == settled
    with pytest.raises(ValueError, match="switch_after"):
        seq.switch_table(cfg, silent_network(), 2, 3, switch_after=20)


def test_constant_output_earns_all_or_nothing():
    cfg = config()
    net = silent_network()
    timing = seq.timings(cfg, 0, 0, 0)
    zero = check_trial(cfg, net, "0", timing)
    one = check_trial(cfg, net, "1", timing)
    np.testing.assert_allclose(zero.r, 1.0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(one.r, 0.0, rtol=0, atol=1e-15)
    assert zero.trigger_correct.all() and not one.trigger_correct.any()
    # Perfect on the two 0* trials, nothing on the two 1* trials.
    f = dnnevo.evaluate("sequence", [net], generation=0, seed=0, config=cfg)
    np.testing.assert_allclose(f, [0.5], rtol=0, atol=1e-12)


def reference_fitness(cfg, nets, generation, seed):
    p = cfg.task_params
    n_trials = len(p["targets"]) * p["trials_per_target"]
    timings = [seq.timings(cfg, seed, generation, t) for t in range(n_trials)]
    return ref.fitness(ref.stack_networks(nets), p["targets"], timings, p["trials_per_target"],
                       perf_base=p["perf_base"], **protocol(cfg))


@pytest.mark.parametrize("generation, seed", [(0, 0), (7, 3)])
def test_evaluate_matches_reference(generation, seed):
    cfg = config()
    nets = [dnnevo.Network.random(5, 2, seed=1000 + s) for s in range(24)]
    want, r = reference_fitness(cfg, nets, generation, seed)
    assert r.shape == (24, 4, 10)
    got = dnnevo.evaluate("sequence", nets, generation=generation, seed=seed, config=cfg)
    np.testing.assert_allclose(got, want, rtol=0, atol=TOL)
    # Hand-written score of the first network from its trials, target-major.
    trials = [seq.run_trial(cfg, nets[0], cfg.task_params["targets"][t // 2],
                            seq.timings(cfg, seed, generation, t)) for t in range(4)]
    perf = [max(0.0, (tr.r.mean() - 0.5) / 0.5) for tr in trials]
    assert got[0] == pytest.approx(np.mean(perf), abs=1e-12)
    assert np.ptp(got) > 0.05, "the networks should not all score alike"
    # Genomes score like the networks they encode.
    genomes = np.stack([n.genome() for n in nets])
    again = dnnevo.evaluate("sequence", genomes, generation=generation, seed=seed, config=cfg)
    np.testing.assert_array_equal(again, got)


def test_evaluate_matches_reference_other_targets_and_generation_mean():
    cfg = config(targets=["01", "10", "011"], trials_per_target=1, perf_base="generation-mean",
                 size=10)
    nets = [dnnevo.Network.random(10, 2, seed=s) for s in range(12)]
    want, r = reference_fitness(cfg, nets, 2, 9)
    got = dnnevo.evaluate("sequence", nets, generation=2, seed=9, config=cfg)
    np.testing.assert_allclose(got, want, rtol=0, atol=TOL)
    assert np.ptp(got) > 0.0


def test_chained_evaluation_matches_reference():
    cfg = config(targets=["0", "1", "01", "10"], trials_per_target=2, chain=True, size=6)
    p = cfg.task_params
    generation, seed = 3, 5
    order = seq.trial_order(cfg, seed, generation)
    assert sorted(order) == list(range(8)) and order != sorted(order)
    nets = [dnnevo.Network.random(6, 2, seed=40 + s) for s in range(5)]
    got = dnnevo.evaluate("sequence", nets, generation=generation, seed=seed, config=cfg)
    for net, fitness in zip(nets, got):
        links = [(p["targets"][t // 2], seq.timings(cfg, seed, generation, t)) for t in order]
        rs = ref.run_chain(*net_params(net), links, **protocol(cfg))
        assert fitness == pytest.approx(np.mean(ref.performance(np.array(rs), 0.5)), abs=TOL)
    # Without the chain every trial starts from rest, which scores differently.
    apart = dnnevo.evaluate("sequence", nets, generation=generation, seed=seed,
                            config=config(targets=["0", "1", "01", "10"], trials_per_target=2,
                                          size=6))
    assert not np.array_equal(apart, got)
    assert seq.trial_order(config(), seed, generation) == [0, 1, 2, 3]


def test_assess_reports_every_target():
    cfg = config()
    report = seq.assess(cfg, silent_network(), 4, 0)
    assert set(report) >= {"targets", "success"}
    assert [t["target"] for t in report["targets"]] == ["0", "1"]
    zero, one = report["targets"]
    assert zero["succeeded"] and zero["success_fraction"] == 1.0
    assert zero["mean_performance"] == pytest.approx(1.0, abs=1e-12)
    assert not one["succeeded"] and one["success_fraction"] == 0.0
    assert one["mean_performance"] == 0.0
    assert report["success"] is False

    report = seq.assess(cfg, dnnevo.Network.random(5, 2, seed=4), 3, 1)
    for t in report["targets"]:
        assert set(t) >= {"target", "mean_performance", "success_fraction", "succeeded"}
        assert 0.0 <= t["mean_performance"] <= 1.0
        assert t["success_fraction"] in (0.0, 1 / 3, 2 / 3, 1.0)
        assert t["succeeded"] == (t["success_fraction"] >= 0.9)
    assert report["success"] == all(t["succeeded"] for t in report["targets"])


def test_fig5_shows_the_papers_pair_when_the_task_has_it() -> None:
    from dnnevo.tasks.sequence import fig5_pair

    assert fig5_pair(["0", "1", "01", "10"]) == ("01", "0")
    assert fig5_pair(["0", "1"]) == ("1", "0")
    assert fig5_pair(["01", "10"]) == ("10", "01")
