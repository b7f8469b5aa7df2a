//! Tests of the sequence task.

use ctrnn::{Error, Layout, Method, Network, Precision, Purpose, Stream, Task};
use std::sync::atomic::AtomicBool;
use tasks::sequence::*;
use tasks::testing::sequence::{correct, mean, score};

/// A one-neuron network with zero weights and threshold `theta`: its output stays at
/// `f(-theta)` whatever the inputs.
fn constant(theta: f64) -> Network {
    Network::new(vec![1.0], vec![theta], vec![0.0], vec![0.0, 0.0], None).unwrap()
}

/// Random 5-neuron, 2-sensor networks over the paper's ranges.
fn random_networks(count: usize, seed: u64) -> Vec<Network> {
    let layout = Layout {
        size: 5,
        n_inputs: 2,
    };
    tasks::testing::random_networks(layout, count, seed)
}

fn task(config: SequenceConfig) -> SequenceTask {
    SequenceTask::new(config).unwrap()
}

fn small() -> SequenceConfig {
    SequenceConfig {
        targets: vec!["0".into(), "1".into(), "01".into()],
        triggers: 5,
        ..SequenceConfig::default()
    }
}

#[test]
fn timings_are_in_range_and_keyed_by_seed_generation_trial() {
    let t = task(SequenceConfig {
        delay: (3, 7),
        gap: (20, 22),
        triggers: 50,
        ..SequenceConfig::default()
    });
    let a = t.timings(1, 2, 3);
    assert_eq!(a.len(), 50);
    assert!(a
        .iter()
        .all(|&(d, g)| (3..=7).contains(&d) && (20..=22).contains(&g)));
    // Both ends of each range are reached.
    for v in [3, 7] {
        assert!(a.iter().any(|x| x.0 == v), "delay {v} never drawn");
    }
    for v in [20, 22] {
        assert!(a.iter().any(|x| x.1 == v), "gap {v} never drawn");
    }
    assert_eq!(a, t.timings(1, 2, 3));
    for other in [t.timings(2, 2, 3), t.timings(1, 3, 3), t.timings(1, 2, 4)] {
        assert_ne!(a, other);
    }
    // Common random numbers: individual 0's timings are everyone's.
    assert_eq!(a, t.timings_of(1, 2, 0, 3));
    assert_ne!(a, t.timings_of(1, 2, 1, 3));
    // The order of draws is delay_0, gap_0, delay_1, ... from the trial's stream.
    let mut s = Stream::new(1, 2, Purpose::Trial, 0, 3);
    for &(d, g) in &a[..5] {
        assert_eq!(d as u64, s.range_inclusive_int(3, 7));
        assert_eq!(g as u64, s.range_inclusive_int(20, 22));
    }
    // A fixed range gives fixed timings; assessment timings are a different stream.
    let fixed = task(SequenceConfig {
        delay: (12, 12),
        gap: (0, 0),
        ..SequenceConfig::default()
    });
    assert!(fixed.timings(5, 0, 0).iter().all(|&x| x == (12, 0)));
    assert_ne!(t.assessment_timings(1, 3), t.timings(1, 0, 3));
    assert_eq!(t.assessment_timings(1, 3), t.assessment_timings(1, 3));
}

#[test]
fn constant_output_earns_r_one_or_zero() {
    let t = task(SequenceConfig::default());
    let timing = t.timings(0, 0, 0);
    // f(v + 100) rounds to exactly 1.
    let high = constant(-100.0);
    let one = t.run_pattern(&high, "1", &timing, true).unwrap();
    assert_eq!(one.r, vec![1.0; 10]);
    assert!(one.trigger_correct.iter().all(|&c| c));
    let zero = t.run_pattern(&high, "0", &timing, true).unwrap();
    assert_eq!(zero.r, vec![0.0; 10]);
    assert!(zero.trigger_correct.iter().all(|&c| !c));
    let alt = t.run_pattern(&high, "01", &timing, true).unwrap();
    assert_eq!(alt.targets, vec![0, 1, 0, 1, 0, 1, 0, 1, 0, 1]);
    assert_eq!(
        alt.r,
        vec![0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0]
    );
}

/// A neuron that follows the trigger: sensor weight 20 from the trigger, 3 from the
/// reinforcement, threshold 5, tau 0.5.
fn follower() -> Network {
    Network::new(vec![0.5], vec![5.0], vec![0.0], vec![20.0, 3.0], None).unwrap()
}

#[test]
fn r_is_measured_over_the_trigger_window() {
    let t = task(SequenceConfig::default());
    let net = follower();
    let timing = t.timings(7, 1, 0);
    let rec = t.run_pattern(&net, "01", &timing, true).unwrap();
    // First window (target bit 0) by hand: from v = 0, Euler with h = 0.2 gives
    // v = 20 (1 - 0.8^j) after j steps; the output is recorded after each of the 10 time
    // steps of 10 Euler steps each.
    let sig = |x: f64| 1.0 / (1.0 + (-x).exp());
    let mut sum = 0.0;
    for n in 1..=10 {
        sum += sig(20.0 * (1.0 - 0.8f64.powi(10 * n)) - 5.0);
    }
    let want = 1.0 - sum / 10.0;
    assert!((rec.r[0] - want).abs() < 1e-12, "{} vs {want}", rec.r[0]);
    // A window shifted by one step would include f(-5) = 0.0067 and be well above.
    assert!(rec.r[0] < 0.01);
    // The second trigger wants a 1, which the follower gives.
    assert!(rec.r[1] > 0.99);

    // The whole trial replayed through ctrnn's own integrator from an input series built
    // here from the timings, feeding back the recorded R values.
    let mut inputs = vec![];
    let mut windows = vec![];
    for (k, &(d, g)) in timing.iter().enumerate() {
        windows.push(inputs.len() / 2);
        for (rows, value) in [(10, [1.0, 0.0]), (d, [0.0; 2]), (10, [0.0, rec.r[k]])] {
            for _ in 0..rows {
                inputs.extend_from_slice(&value);
            }
        }
        for _ in 0..g {
            inputs.extend_from_slice(&[0.0; 2]);
        }
    }
    let steps = inputs.len() / 2;
    assert_eq!(rec.output.len(), steps);
    let trig: Vec<f64> = inputs.iter().step_by(2).copied().collect();
    let reinf: Vec<f64> = inputs.iter().skip(1).step_by(2).copied().collect();
    assert_eq!(rec.trigger, trig);
    assert_eq!(rec.reinforcement, reinf);
    let mut replay = net.clone();
    let states = replay.run(&inputs, steps, &t.config().integrator).unwrap();
    let out: Vec<f64> = states
        .iter()
        .map(|v| ctrnn::math::sigmoid(v - 5.0))
        .collect();
    assert_eq!(rec.output, out);
    for (k, &w) in windows.iter().enumerate() {
        let p = (k % 2) as f64;
        let err: f64 = out[w..w + 10].iter().map(|o| (p - o).abs()).sum();
        assert_eq!(rec.r[k], 1.0 - err / 10.0, "trigger {k}");
    }
    assert_eq!(rec.final_state, replay.state());
    assert_eq!(rec.outputs.len(), steps);
    assert_eq!(rec.outputs[3], vec![rec.output[3]]);
}

#[test]
fn performance_of_hand_made_values() {
    assert_eq!(performance(&[1.0, 1.0], 0.5), 1.0);
    assert_eq!(performance(&[0.5, 0.5], 0.5), 0.0);
    assert_eq!(performance(&[0.75], 0.5), 0.5);
    assert_eq!(performance(&[0.2, 0.3], 0.5), 0.0);
    assert_eq!(performance(&[0.2, 0.4], 0.0), 0.30000000000000004);
    let p = performance(&[1.0, 0.5], 2.0 / 3.0);
    assert!((p - 0.25).abs() < 1e-15, "{p}");
    assert_eq!(performance(&[1.0], 1.0), 0.0);
}

#[test]
fn constant_outputs_score_half_or_nothing() {
    let t = task(SequenceConfig::default());
    let nets = [constant(100.0), constant(-100.0), constant(0.0)];
    let f = t.evaluate(&nets, 0, 3, None).unwrap();
    // Always 0: perfect on the two 0* trials, nothing on the two 1* trials. Always 1: the
    // reverse. Always 0.5: R = 0.5 everywhere, nothing above the base.
    assert_eq!(f, vec![0.5, 0.5, 0.0]);
    // Clamped once per evaluation, no constant output earns anything.
    let t = task(SequenceConfig {
        clamp: Clamp::Evaluation,
        ..SequenceConfig::default()
    });
    assert_eq!(t.evaluate(&nets, 0, 3, None).unwrap(), vec![0.0, 0.0, 0.0]);
}

#[test]
fn batched_evaluation_equals_run_trial() {
    for precision in [Precision::F64, Precision::F32] {
        batched_evaluation_equals_run_trial_in(precision);
    }
}

fn batched_evaluation_equals_run_trial_in(precision: Precision) {
    let t = task(SequenceConfig {
        precision,
        ..small()
    });
    let nets = random_networks(19, 11);
    let (seed, generation) = (5, 3);
    let scores = t.scores(&nets, generation, seed, None).unwrap();
    let (n_trials, k) = (6, 5);
    assert_eq!((scores.trials, scores.triggers), (n_trials, k));
    assert_eq!(scores.r.len(), 19 * n_trials * k);
    for (p, net) in nets.iter().enumerate() {
        let mut fitness = 0.0;
        for trial in 0..n_trials {
            let timing = t.timings(seed, generation, trial);
            let rec = t.run_trial(net, trial / 2, &timing, true).unwrap();
            // In f32 the network's rates are f32s.
            let single = |x: f64| x as f32 as f64 == x;
            if precision == Precision::F32 {
                assert!(rec.output.iter().all(|&y| single(y)), "network {p}");
            } else {
                assert!(!rec.output.iter().all(|&y| single(y)), "network {p}");
            }
            let at = (p * n_trials + trial) * k;
            assert_eq!(rec.r, scores.r[at..at + k], "network {p}, trial {trial}");
            fitness += performance(&rec.r, 0.5);
        }
        assert_eq!(scores.fitness[p], fitness / n_trials as f64, "network {p}");
    }
    // Not trivially equal: the random networks score differently.
    assert!(scores.fitness.iter().any(|&f| f != scores.fitness[0]));
    assert!(scores.r.iter().any(|&r| r > 0.01 && r < 0.99));
}

#[test]
fn the_error_of_several_diverging_networks_names_the_first_whatever_the_threads() {
    let t = task(small());
    let mut nets = random_networks(160, 2);
    // Two networks whose Euler steps are unstable (dt / tau = 10), in blocks 4 and 5 of 10: with
    // two threads, one runs blocks 0-4 in order and the other starts at block 5, so the later
    // network's divergence is found first.
    let fast = |net: &Network| {
        let tau = vec![0.01; net.size()];
        let (theta, w, s) = (net.theta(), net.weights(), net.sensor_weights());
        Network::new(tau, theta.to_vec(), w.to_vec(), s.to_vec(), None).unwrap()
    };
    nets[70] = fast(&nets[70]);
    nets[85] = fast(&nets[85]);
    for threads in [1, 2, 2, 2, 2, 2] {
        let e = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| t.evaluate(&nets, 0, 0, None))
            .unwrap_err();
        assert!(
            e.to_string().contains("network 70 "),
            "{threads} threads: {e}"
        );
    }
}

#[test]
fn evaluation_does_not_depend_on_threads() {
    for precision in [Precision::F64, Precision::F32] {
        evaluation_does_not_depend_on_threads_in(precision);
    }
}

fn evaluation_does_not_depend_on_threads_in(precision: Precision) {
    let t = task(SequenceConfig {
        precision,
        ..small()
    });
    let nets = random_networks(37, 2);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| t.scores(&nets, 4, 9, None).unwrap())
    };
    let one = run(1);
    let two = run(2);
    let bits = |s: &Scores| s.r.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&one), bits(&two));
    assert_eq!(one, two);
    // A network's score does not depend on its neighbours either.
    let alone = t.scores(&nets[20..21], 4, 9, None).unwrap();
    assert_eq!(alone.fitness[0], one.fitness[20]);
}

#[test]
fn copies_in_a_batch_score_as_if_each_ran() {
    // A population of copies (as a GA breeds them) runs one network of each kind; every copy's
    // R, and so every fitness, has the bits of the network run alone.
    let t = task(SequenceConfig {
        perf_base: PerfBase::GenerationMean,
        ..small()
    });
    let distinct = random_networks(23, 8);
    let picks: Vec<usize> = (0..70).map(|i| (i * 7 + i / 5) % 23).collect();
    let nets: Vec<Network> = picks.iter().map(|&i| distinct[i].clone()).collect();
    let scores = t.scores(&nets, 2, 6, None).unwrap();
    let per = scores.trials * scores.triggers;
    let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    for (p, &i) in picks.iter().enumerate() {
        let alone = t.scores(&distinct[i..i + 1], 2, 6, None).unwrap();
        assert_eq!(
            bits(&scores.r[p * per..(p + 1) * per]),
            bits(&alone.r),
            "network {p}"
        );
    }
    // The generation's base and every fitness as when each copy ran in its own lanes: the same
    // batch made of distinct networks (each nudged apart in its state, which a trial resets).
    let nudged: Vec<Network> = nets
        .iter()
        .enumerate()
        .map(|(p, n)| {
            let mut state = vec![0.0; n.size()];
            state[0] = p as f64 * 1e-3;
            let mut n = n.clone();
            n.set_state(Some(&state)).unwrap();
            n
        })
        .collect();
    let apart = t.scores(&nudged, 2, 6, None).unwrap();
    assert_eq!(bits(&scores.r), bits(&apart.r));
    assert_eq!(bits(&scores.base), bits(&apart.base));
    assert_eq!(bits(&scores.fitness), bits(&apart.fitness));
}

#[test]
fn independent_conditions_use_each_individuals_timings() {
    let t = task(SequenceConfig {
        independent_conditions: true,
        ..small()
    });
    let nets = random_networks(11, 4);
    let scores = t.scores(&nets, 1, 8, None).unwrap();
    for (p, net) in nets.iter().enumerate() {
        for trial in 0..6 {
            let timing = t.timings_of(8, 1, p, trial);
            let rec = t.run_trial(net, trial / 2, &timing, true).unwrap();
            let at = (p * 6 + trial) * 5;
            assert_eq!(rec.r, scores.r[at..at + 5], "network {p}, trial {trial}");
        }
    }
    let common = task(small()).scores(&nets, 1, 8, None).unwrap();
    assert_eq!(
        common.r[..30],
        scores.r[..30],
        "individual 0 has the common timings"
    );
    assert_ne!(common.r, scores.r);
}

#[test]
fn generation_mean_base() {
    let t = task(SequenceConfig {
        targets: vec!["0".into()],
        triggers: 3,
        perf_base: PerfBase::GenerationMean,
        ..SequenceConfig::default()
    });
    // Outputs 0, 0.25 and 1: mean R 1, 0.75 and 0 on 0*.
    let quarter = constant(3f64.ln());
    let nets = [constant(100.0), quarter.clone(), constant(-100.0)];
    let s = t.scores(&nets, 0, 1, None).unwrap();
    assert!((s.mean_r[2] - 0.75).abs() < 1e-12);
    assert!((s.base[0] - 1.75 / 3.0).abs() < 1e-12, "{:?}", s.base);
    assert_eq!(s.base, vec![mean(&s.mean_r)]);
    let want = [1.0, 0.4, 0.0];
    for (f, w) in s.fitness.iter().zip(want) {
        assert!((f - w).abs() < 1e-12, "{:?}", s.fitness);
    }
    // The same network scores differently in another batch.
    let s = t.scores(&nets[1..], 0, 1, None).unwrap();
    assert!((s.fitness[0] - 0.6).abs() < 1e-12, "{:?}", s.fitness);
    // A generation of perfect networks has nothing to beat: fitness 0, not NaN.
    let s = t.scores(&[constant(100.0)], 0, 1, None).unwrap();
    assert_eq!(s.fitness, vec![0.0]);
}

#[test]
fn target_mean_base_is_each_targets_generation_mean() {
    let config = SequenceConfig {
        triggers: 3,
        perf_base: PerfBase::TargetMean,
        ..SequenceConfig::default()
    };
    // Outputs 0, 0.25 and 1: mean R 1, 0.75 and 0 on 0*, and 0, 0.25 and 1 on 1*.
    let nets = [constant(100.0), constant(3f64.ln()), constant(-100.0)];
    let s = task(config.clone()).scores(&nets, 0, 1, None).unwrap();
    let (b0, b1) = (1.75 / 3.0, 1.25 / 3.0);
    assert!((s.base[0] - b0).abs() < 1e-12 && (s.base[1] - b1).abs() < 1e-12);
    let p = |r: f64, b: f64| (r - b) / (1.0 - b);
    let close = |got: &[f64], want: &[f64]| {
        assert!(
            got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-12),
            "{got:?} != {want:?}"
        )
    };
    // Per trial, clamped: always-0 earns 1 on its two 0* trials, 0 on its 1* trials.
    close(&s.fitness, &[0.5, p(0.75, b0) / 2.0, p(1.0, b1) / 2.0]);
    // Clamped once: the failed target costs what it falls below its own base.
    let once = task(SequenceConfig {
        clamp: Clamp::Evaluation,
        ..config.clone()
    })
    .scores(&nets, 0, 1, None)
    .unwrap();
    let mean2 = |a: f64, b: f64| (2.0 * a + 2.0 * b) / 4.0;
    close(
        &once.fitness,
        &[
            mean2(1.0, p(0.0, b1)),
            mean2(p(0.75, b0), p(0.25, b1)),
            mean2(p(0.0, b0), 1.0),
        ]
        .map(|x| x.max(0.0)),
    );
}

#[test]
fn min_and_mean_min_aggregates_judge_the_weakest_target() {
    let nets = [
        constant(100.0),
        constant(3f64.ln()),
        Network::new(vec![1.0], vec![0.5], vec![2.0], vec![3.0, -4.0], None).unwrap(),
    ];
    let config = SequenceConfig {
        triggers: 4,
        ..SequenceConfig::default()
    };
    let mean = task(config.clone()).scores(&nets, 0, 1, None).unwrap();
    for clamp in [Clamp::Trial, Clamp::Evaluation] {
        let with = |aggregate| {
            task(SequenceConfig {
                aggregate,
                clamp,
                ..config.clone()
            })
            .scores(&nets, 0, 1, None)
            .unwrap()
        };
        let (min, both) = (with(Aggregate::Min), with(Aggregate::MeanMin));
        let overall = with(Aggregate::Mean);
        for i in 0..nets.len() {
            // Each target's score from the trials' mean R, by hand.
            let trials = &mean.mean_r[i * 4..(i + 1) * 4];
            let target = |j: usize| {
                let (a, b) = (trials[2 * j], trials[2 * j + 1]);
                match clamp {
                    Clamp::Trial => (score(a, 0.5) + score(b, 0.5)) / 2.0,
                    Clamp::Evaluation => score((a + b) / 2.0, 0.5),
                }
            };
            let worst = target(0).min(target(1));
            assert_eq!(min.fitness[i], worst, "network {i}, {clamp:?}");
            assert_eq!(both.fitness[i], 0.5 * (overall.fitness[i] + worst));
        }
    }
    // Always 0 is perfect on 0* and worthless on 1*: the minimum gives it nothing.
    assert_eq!(
        task(SequenceConfig {
            aggregate: Aggregate::Min,
            ..config.clone()
        })
        .scores(&nets[..1], 0, 1, None)
        .unwrap()
        .fitness,
        vec![0.0]
    );
}

#[test]
fn continuing_without_reset_chains_trials() {
    let t = task(SequenceConfig::default());
    let net = &random_networks(1, 5)[0];
    let timing = t.timings(1, 0, 0);
    let whole = t.run_pattern(net, "0", &timing, true).unwrap();
    let first = t.run_pattern(net, "0", &timing[..4], true).unwrap();
    let mut cont = net.clone();
    cont.set_state(Some(&first.final_state)).unwrap();
    let second = t.run_pattern(&cont, "0", &timing[4..], false).unwrap();
    assert_eq!([first.r, second.r].concat(), whole.r);
    assert_eq!([first.output, second.output].concat(), whole.output);
    // With a reset the continuation starts over.
    let fresh = t.run_pattern(&cont, "0", &timing[4..], true).unwrap();
    assert_ne!(
        fresh.output,
        whole.output[whole.output.len() - fresh.output.len()..]
    );
}

#[test]
fn chained_trials_continue_from_the_trial_before() {
    let config = SequenceConfig {
        chain: true,
        ..small()
    };
    let t = task(config.clone());
    let nets = random_networks(19, 12);
    let (seed, generation) = (3, 2);
    let order = t.trial_order(seed, generation);
    let mut sorted = order.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, (0..6).collect::<Vec<_>>(), "a permutation");
    assert_ne!(
        order, sorted,
        "shuffled (this seed's order is not the identity)"
    );
    assert_ne!(
        order,
        t.trial_order(seed, generation + 1),
        "drawn per generation"
    );
    let scores = t.scores(&nets, generation, seed, None).unwrap();
    for (p, net) in nets.iter().enumerate() {
        // By hand: each trial a whole record that starts from the last one's final state.
        let mut state: Option<Vec<f64>> = None;
        for &trial in &order {
            let mut cont = net.clone();
            cont.set_state(state.as_deref()).unwrap();
            let timing = t.timings(seed, generation, trial);
            let rec = t
                .run_trial(&cont, trial / 2, &timing, state.is_none())
                .unwrap();
            let at = (p * 6 + trial) * 5;
            assert_eq!(rec.r, scores.r[at..at + 5], "network {p}, trial {trial}");
            state = Some(rec.final_state);
        }
    }
    // Not the unchained scores: the state carried over changes the later trials.
    let apart = task(SequenceConfig {
        chain: false,
        ..config
    });
    assert_eq!(apart.trial_order(seed, generation), sorted);
    assert_ne!(
        apart.scores(&nets, generation, seed, None).unwrap().r,
        scores.r
    );
}

#[test]
fn assess_judges_the_warm_up_and_matches_run_trial() {
    let t = task(SequenceConfig::default());
    let low = constant(100.0);
    let a = t.assess(&low, 5, 1).unwrap();
    assert_eq!(a.targets[0].success_fraction, 1.0);
    assert_eq!(a.targets[0].mean_performance, 1.0);
    assert!(a.targets[0].succeeded);
    assert_eq!(a.targets[1].success_fraction, 0.0);
    assert!(!a.success);

    // A random network, 11 trials per target (a group of 8 and a partial group).
    let net = &random_networks(3, 6)[2];
    let a = t.assess(net, 11, 4).unwrap();
    for (i, report) in a.targets.iter().enumerate() {
        let mut perf = vec![];
        let mut ok = 0;
        for j in 0..11 {
            let timing = t.assessment_timings(4, i * 11 + j);
            let rec = t.run_trial(net, i, &timing, true).unwrap();
            perf.push(performance(&rec.r, 0.5));
            ok += usize::from(rec.trigger_correct[2..].iter().all(|&c| c));
        }
        assert_eq!(report.mean_performance, mean(&perf));
        assert_eq!(report.success_fraction, ok as f64 / 11.0);
    }
    // Too few triggers to judge anything after the warm-up.
    let short = task(SequenceConfig {
        targets: vec!["011".into()],
        triggers: 6,
        ..SequenceConfig::default()
    });
    let e = short.assess(&low, 3, 0).unwrap_err().to_string();
    assert!(e.contains("warm-up of 6"), "{e}");
}

#[test]
fn trigger_correct_is_the_side_of_one_half() {
    assert!(correct(1, 0.51) && !correct(1, 0.5) && !correct(1, 0.2));
    assert!(correct(0, 0.49) && !correct(0, 0.5) && !correct(0, 0.8));
    assert_eq!(warmup("011"), 6);
}

#[test]
fn cancel_interrupts() {
    let t = task(SequenceConfig::default());
    let flag = AtomicBool::new(true);
    let r = t.evaluate(&random_networks(9, 0), 0, 0, Some(&flag));
    assert!(matches!(r, Err(Error::Interrupted)), "{r:?}");
}

#[test]
fn wrong_networks_and_targets_are_errors() {
    let t = task(SequenceConfig::default());
    let one_input = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    let e = t.evaluate(&[constant(0.0), one_input.clone()], 0, 0, None);
    assert!(e.unwrap_err().to_string().contains("network 1 has M = 1"));
    let timing = t.timings(0, 0, 0);
    assert!(t.run_trial(&one_input, 0, &timing, true).is_err());
    let e = t.run_trial(&constant(0.0), 2, &timing, true).unwrap_err();
    assert!(e.to_string().contains("2 targets"), "{e}");
    assert!(t.run_pattern(&constant(0.0), "0a", &timing, true).is_err());
    let fast = Network::new(vec![0.01], vec![0.0], vec![-5.0], vec![1.0, 1.0], None).unwrap();
    let e = t.evaluate(&[constant(0.0), fast], 0, 0, None).unwrap_err();
    assert!(e.to_string().contains("diverged") && e.to_string().contains("network 1"));
    assert_eq!(t.evaluate(&[], 0, 0, None).unwrap(), Vec::<f64>::new());
}

#[test]
fn config_validation_names_the_field() {
    let check = |c: SequenceConfig, field: &str| {
        let e = c.validate().unwrap_err();
        assert!(matches!(e, Error::Config(_)), "{e:?}");
        assert!(e.to_string().contains(field), "{e} lacks {field}");
    };
    let d = SequenceConfig::default;
    check(
        SequenceConfig {
            targets: vec![],
            ..d()
        },
        "targets is empty",
    );
    check(
        SequenceConfig {
            targets: vec!["0".into(), "".into()],
            ..d()
        },
        "targets[1]",
    );
    check(
        SequenceConfig {
            targets: vec!["0".into(), "0".into()],
            ..d()
        },
        "distinct",
    );
    check(SequenceConfig { size: 0, ..d() }, "size");
    check(SequenceConfig { triggers: 0, ..d() }, "triggers");
    check(
        SequenceConfig {
            trigger_steps: 0,
            ..d()
        },
        "trigger_steps",
    );
    check(
        SequenceConfig {
            trials_per_target: 0,
            ..d()
        },
        "trials_per_target",
    );
    check(
        SequenceConfig {
            delay: (5, 4),
            ..d()
        },
        "delay",
    );
    check(SequenceConfig { gap: (5, 4), ..d() }, "gap");
    for b in [-0.1, 1.0, f64::NAN] {
        check(
            SequenceConfig {
                perf_base: PerfBase::Value(b),
                ..d()
            },
            "perf_base",
        );
    }
    let mut c = d();
    c.integrator.dt = 0.0;
    check(c, "integrator: dt");
    d().validate().unwrap();
    SequenceConfig {
        reinforcement_steps: 0,
        delay: (0, 0),
        gap: (0, 0),
        ..d()
    }
    .validate()
    .unwrap();
}

#[test]
fn config_reads_and_writes_json() {
    let c = SequenceConfig::from_params(&serde_json::json!({
        "targets": ["011", "101", "110"],
        "size": 10,
        "perf_base": "generation-mean",
        "delay": [5, 6],
        "integrator": {"method": "rk4", "dt": 0.05, "substeps": 20},
    }))
    .unwrap();
    assert_eq!(c.perf_base, PerfBase::GenerationMean);
    assert_eq!(c.delay, (5, 6));
    assert_eq!(c.integrator.method, Method::Rk4);
    assert_eq!(c.gap, (10, 40));
    let text = serde_json::to_string(&c).unwrap();
    assert!(text.contains("\"perf_base\":\"generation-mean\""), "{text}");
    let back: SequenceConfig = serde_json::from_str(&text).unwrap();
    assert_eq!(back, c);
    let c = SequenceConfig::from_params(&serde_json::json!({"perf_base": 0})).unwrap();
    assert_eq!(c.perf_base, PerfBase::Value(0.0));
    let c = SequenceConfig::from_params(
        &serde_json::json!({"perf_base": "target-mean", "aggregate": "mean-min"}),
    )
    .unwrap();
    assert_eq!(
        (c.perf_base, c.aggregate),
        (PerfBase::TargetMean, Aggregate::MeanMin)
    );
    let text = serde_json::to_string(&c).unwrap();
    assert!(
        text.contains("\"perf_base\":\"target-mean\"") && text.contains("\"mean-min\""),
        "{text}"
    );
    let err = |v: serde_json::Value| SequenceConfig::from_params(&v).unwrap_err().to_string();
    let e = err(serde_json::json!({"perf_base": "mean"}));
    assert!(
        e.contains("generation-mean") && e.contains("\"mean\""),
        "{e}"
    );
    assert!(e.contains("target-mean"), "{e}");
    let e = err(serde_json::json!({"aggregate": "median"}));
    assert!(e.contains("unknown variant `median`"), "{e}");
    let e = err(serde_json::json!({"perf_base": 2.5}));
    assert!(e.contains("perf_base is 2.5"), "{e}");
    let e = err(serde_json::json!({"trigers": 3}));
    assert!(e.contains("unknown field `trigers`"), "{e}");
    let e = err(serde_json::json!({"independent_conditions": 1}));
    assert!(e.contains("sequence"), "{e}");
    assert_eq!(
        SequenceConfig::from_params(&serde_json::Value::Null).unwrap(),
        SequenceConfig::default()
    );
}

#[test]
fn layout_is_size_and_two_sensors() {
    let t = task(SequenceConfig {
        size: 10,
        ..SequenceConfig::default()
    });
    assert_eq!(
        t.layout(),
        Layout {
            size: 10,
            n_inputs: 2
        }
    );
}

/// The paper's size: 1000 random 5-neuron networks, 4 trials of 10 triggers.
/// Run with `cargo test -p tasks --release -- --ignored --nocapture paper_size`.
#[test]
#[ignore]
fn paper_size_generation_timing() {
    let t = task(SequenceConfig::default());
    let nets = random_networks(1000, 1);
    t.evaluate(&nets, 0, 0, None).unwrap();
    let reps = 20;
    let start = std::time::Instant::now();
    for g in 0..reps {
        t.evaluate(&nets, g, 0, None).unwrap();
    }
    let per = start.elapsed().as_secs_f64() / reps as f64;
    println!(
        "1000 networks x 4 trials: {:.1} ms per generation on {} threads",
        per * 1e3,
        rayon::current_num_threads()
    );
}
