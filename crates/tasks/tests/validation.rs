//! The validation set of every task: drawn from its own stream, so it never coincides with the
//! training conditions of any generation or with the conditions `dnnevo evaluate` draws, and
//! judged per network whatever the batch it comes in.

use ctrnn::{Layout, Network, Purpose, Task, Validation};
use tasks::landmark::{LandmarkConfig, LandmarkTask};
use tasks::nav1d::{Nav1dConfig, Nav1dTask, Objective};
use tasks::{SequenceConfig, SequenceTask};

const SEED: u64 = 11;

fn random_networks(layout: Layout, count: usize) -> Vec<Network> {
    tasks::testing::random_networks(layout, count, 5)
}

/// `validate` of a batch equals `validate` of each network alone, and every value is in [0, 1].
fn check_batch_independent(task: &dyn Task, nets: &[Network]) -> Vec<Validation> {
    let batch = task.validate(nets, SEED, None).unwrap().unwrap();
    assert_eq!(batch.len(), nets.len());
    for (net, v) in nets.iter().zip(&batch) {
        let alone = task
            .validate(std::slice::from_ref(net), SEED, None)
            .unwrap();
        assert_eq!(alone.unwrap()[0], *v);
        assert!(
            (0.0..=1.0).contains(&v.rate) && (0.0..=1.0).contains(&v.score),
            "{v:?}"
        );
    }
    batch
}

#[test]
fn sequence_validation_is_its_own_stream() {
    let task = SequenceTask::new(SequenceConfig {
        validation_trials: 8,
        ..SequenceConfig::default()
    })
    .unwrap();
    let n = 2 * 8;
    let validation: Vec<_> = (0..n)
        .map(|t| task.fresh_timings(Purpose::Validate, SEED, t))
        .collect();
    for (t, v) in validation.iter().enumerate() {
        assert_ne!(*v, task.assessment_timings(SEED, t), "trial {t}");
        for g in 0..50 {
            for u in 0..task.config().n_trials() {
                assert_ne!(*v, task.timings(SEED, g, u), "trial {t}, generation {g}");
            }
        }
    }
    assert_eq!(
        validation[3],
        task.fresh_timings(Purpose::Validate, SEED, 3),
        "the validation set is fixed for the run"
    );
    let nets = random_networks(task.layout(), 5);
    check_batch_independent(&task, &nets);
    // The rate is the lowest target's: it never exceeds what assess finds on either target
    // over the same trials, so compare with a network stuck at 0, right on 0* and wrong on 1*.
    let mut theta = vec![0.0; 5];
    theta[0] = 30.0;
    let zero = Network::new(vec![1.0; 5], theta, vec![0.0; 25], vec![0.0; 10], None).unwrap();
    let v = task.validate(&[zero], SEED, None).unwrap().unwrap()[0];
    assert_eq!(
        v.rate, 0.0,
        "right on every 0* trial, wrong on every 1* trial: {v:?}"
    );
}

#[test]
fn nav1d_validation_is_its_own_stream() {
    let task = Nav1dTask::new(Nav1dConfig {
        objective: Objective::Single,
        size: 5,
        start_jitter: 1.0,
        landmark_jitter: 1.0,
        validation_chains: 6,
        ..Nav1dConfig::default()
    })
    .unwrap();
    let k = task.chain_len();
    let validation = task.chains_from(Purpose::Validate, 6, k, SEED);
    let fresh = task.fresh_chains(6, k, SEED);
    for (e, chain) in validation.iter().enumerate() {
        assert_ne!(*chain, fresh[e], "chain {e}");
        for g in 0..50 {
            assert!(
                task.chains(SEED, g).iter().all(|c| c != chain),
                "chain {e} is a training chain of generation {g}"
            );
        }
    }
    let nets = random_networks(task.layout(), 5);
    check_batch_independent(&task, &nets);
}

#[test]
fn landmark_validation_is_its_own_stream() {
    let task = LandmarkTask::new(LandmarkConfig {
        trials_per_landmark: 2,
        trial_seconds: 10.0,
        validation_trials: 3,
        ..LandmarkConfig::default()
    })
    .unwrap();
    let start = |s: &tasks::landmark::Sensing| s.poses[0];
    let validation = task.trials_from(Purpose::Validate, 3, SEED, false).unwrap();
    let fresh = task.fresh_trials(3, SEED, false).unwrap();
    let training: Vec<_> = (0..20)
        .flat_map(|g| task.trials(SEED, g).unwrap())
        .map(|s| start(&s))
        .collect();
    for (t, v) in validation.iter().enumerate() {
        assert_ne!(start(v), start(&fresh[t]), "trial {t}");
        assert!(
            !training.contains(&start(v)),
            "trial {t} starts where a training trial did"
        );
    }
    let nets = random_networks(task.layout(), 3);
    let vs = check_batch_independent(&task, &nets);
    // The rate is the fraction of the validation trials classified right.
    for (net, v) in nets.iter().zip(&vs) {
        let right = validation
            .iter()
            .filter(|s| {
                let rec = task.record(net, (*s).clone()).unwrap();
                tasks::landmark::answer(rec.classification) == s.landmark
            })
            .count();
        assert_eq!(v.rate, right as f64 / validation.len() as f64);
    }
}
