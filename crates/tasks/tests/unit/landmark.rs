use ctrnn::{Layout, Network, Precision, Purpose, Stream, Task};
use tasks::landmark::*;

mod trials;

fn task(config: LandmarkConfig) -> LandmarkTask {
    LandmarkTask::new(config).unwrap()
}

fn small() -> LandmarkConfig {
    LandmarkConfig {
        trials_per_landmark: 2,
        trial_seconds: 20.0,
        ..LandmarkConfig::default()
    }
}

/// A network whose classifier fires at the constant rate `f(-theta0)`.
fn constant(theta0: f64) -> Network {
    let mut theta = vec![0.0; 8];
    theta[0] = theta0;
    Network::new(vec![1.0; 8], theta, vec![0.0; 64], vec![0.0; 8], None).unwrap()
}

fn random_networks(count: usize, seed: u64) -> Vec<Network> {
    let layout = Layout {
        size: 8,
        n_inputs: 1,
    };
    tasks::testing::random_networks(layout, count, seed)
}

#[test]
fn score_and_answer_on_hand_made_outputs() {
    assert_eq!(score(1, 0.2), 0.8);
    assert_eq!(score(2, 0.2), 0.2);
    assert_eq!(score(1, 1.0), 0.0);
    assert_eq!([answer(0.49), answer(0.5), answer(0.9)], [1, 2, 2]);
    let t = task(small());
    let theta = -1.0f64;
    let f = 1.0 / (1.0 + theta.exp());
    let fitness = t.evaluate(&[constant(theta)], 0, 3, None).unwrap()[0];
    assert!((fitness - 0.5 * ((1.0 - f) + f)).abs() < 1e-15, "{fitness}");
    let a = t.assess(&constant(theta), 5, 1, false).unwrap();
    assert_eq!(a.confusion, [[0, 5], [0, 5]]);
    assert_eq!(a.rate, 0.5);
    assert!(!a.success);
}

#[test]
fn sensing_is_keyed_by_the_stream_and_sees_the_landmark() {
    let t = task(small());
    let s = |trial: u64| Stream::new(4, 2, Purpose::Trial, 0, trial);
    let a = t.sense(2, s(0), false).unwrap();
    assert_eq!(a, t.sense(2, s(0), false).unwrap());
    assert_ne!(a.poses, t.sense(2, s(1), false).unwrap().poses);
    assert_eq!(a.input.len(), 200);
    assert!(a.input.iter().all(|&x| (0.0..=1.0).contains(&x)));
    for (x, r) in a.input.iter().zip(&a.range) {
        assert_eq!(*x, (0.5 / r).min(1.0));
    }
    // Over a whole lap the sonar sees the landmark: some echoes come from inside the room.
    let full = task(LandmarkConfig::default());
    let lap = full.sense(1, s(0), false).unwrap();
    let inner = lap
        .echoes
        .iter()
        .flatten()
        .filter(|p| (1.5..4.5).contains(&p[0]) && (1.5..3.5).contains(&p[1]));
    assert!(inner.count() > 5);
    // Robot-like trials jitter the world.
    let rough = t.sense(2, s(0), true).unwrap();
    assert_ne!(rough.world, a.world);
    assert!(t.sense(3, s(0), false).is_err());
}

#[test]
fn batched_outputs_equal_the_record_and_ignore_threads() {
    for precision in [Precision::F64, Precision::F32] {
        batched_outputs_equal_the_record_and_ignore_threads_in(precision);
    }
}

fn batched_outputs_equal_the_record_and_ignore_threads_in(precision: Precision) {
    let t = task(LandmarkConfig {
        precision,
        ..small()
    });
    let nets = random_networks(11, 5);
    let trials = t.trials(9, 1).unwrap();
    assert_eq!(
        trials.iter().map(|s| s.landmark).collect::<Vec<_>>(),
        [1, 1, 2, 2]
    );
    let out = t.outputs(&nets, &trials, None).unwrap();
    for (p, net) in nets.iter().enumerate() {
        for (k, s) in trials.iter().enumerate() {
            let rec = t.record(net, s.clone()).unwrap();
            assert_eq!(rec.classification.to_bits(), out[p][k].to_bits());
            let single = rec.outputs.iter().flatten().all(|&y| y as f32 as f64 == y);
            assert_eq!(single, precision == Precision::F32);
            assert_eq!(rec.outputs.len(), s.input.len());
        }
    }
    let fitness = t.evaluate(&nets, 1, 9, None).unwrap();
    // Networks that listen to the sonar: the fitness is the mean score of their own trials'
    // answers, landmark by landmark, and not the constant classifier's one half.
    for (p, f) in fitness.iter().enumerate() {
        let scores: Vec<f64> = trials
            .iter()
            .zip(&out[p])
            .map(|(s, &o)| score(s.landmark, o))
            .collect();
        assert_eq!(f.to_bits(), (scores.iter().sum::<f64>() / 4.0).to_bits());
    }
    assert!(
        fitness.iter().any(|&f| (f - 0.5).abs() > 1e-3),
        "{fitness:?}"
    );
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    assert_eq!(
        one.install(|| t.evaluate(&nets, 1, 9, None).unwrap()),
        fitness
    );
}

#[test]
fn config_errors_name_the_field() {
    use serde_json::json;
    let err = |p: serde_json::Value| LandmarkTask::from_params(&p).unwrap_err().to_string();
    assert!(err(json!({"classifier": 8})).contains("classifier is 8"));
    assert!(err(json!({"trial_seconds": -1.0})).contains("trial_seconds is -1"));
    assert!(err(json!({"robot_like": {"room_scale": 0.9}})).contains("robot_like.room_scale"));
    assert!(err(
        json!({"landmark1": {"room": [-1.0, 5.0], "start": {"min": [0.4, 0.4], "max": [1.0, 1.0]}}})
    )
    .contains("landmark1"));
    assert!(err(json!({"sim": {"dt": 0.0}})).contains("dt"));
    assert!(err(json!({"sonar": 1})).contains("unknown field `sonar`"));
    let e = task(small())
        .evaluate(
            &[Network::new(vec![1.0], vec![0.0], vec![0.0], vec![0.0, 0.0], None).unwrap()],
            0,
            0,
            None,
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("M = 2"), "{e}");
}
