use ctrnn::{Error, Purpose, Stream, Task};
use serde_json::json;

use sim2d::WorldSpec;

use tasks::landmark::{LandmarkConfig, LandmarkTask, RobotLike, Training};
use tasks::testing::landmark::varied_validation_trials;

/// Short trials, 3 per landmark, every variation on.
fn varied() -> LandmarkConfig {
    LandmarkConfig {
        trials_per_landmark: 3,
        trial_seconds: 15.0,
        training: Training {
            ideal_trials_per_landmark: 1,
            landmark_shift: 0.3,
            landmark_turn_deg: 20.0,
            landmark_scale: 0.2,
            follower_speed: 0.2,
            follower_distance: 0.1,
            cone_deg: 10.0,
            trial_seconds: 3.0,
            input_gain: 0.3,
            input_offset: 0.05,
            input_noise_sd: 0.02,
            room_scale: 0.0,
            sonar_axis_deg: 0.0,
            at_ends: false,
        },
        ..LandmarkConfig::default()
    }
}

fn task(config: LandmarkConfig) -> LandmarkTask {
    LandmarkTask::new(config).unwrap()
}

fn err(params: serde_json::Value) -> String {
    LandmarkTask::from_params(&params).unwrap_err().to_string()
}

#[test]
fn bad_training_fields_are_config_errors_that_name_them() {
    let e = LandmarkTask::from_params(&json!({"training": {"landmark_turn_deg": 200.0}}));
    assert!(
        matches!(&e, Err(Error::Config(m))
            if m == "training.landmark_turn_deg is 200; it must be in [0, 180]"),
        "{e:?}"
    );
    assert!(err(json!({"training": {"input_gain": -0.1}}))
        .contains("training.input_gain is -0.1; it must be in [0, 0.9]"));
    assert!(err(json!({"training": {"ideal_trials_per_landmark": 4}}))
        .contains("ideal_trials_per_landmark is 4; it must be at most trials_per_landmark (3)"));
    assert!(err(json!({"training": {"trial_seconds": 45.0}}))
        .contains("training.trial_seconds is 45; it must be below"));
    let e = err(json!({"training": {"follower_distance": 0.3}}));
    assert!(
        e.contains("training.follower_distance") && e.contains("follower.wall_distance"),
        "{e}"
    );
    assert!(err(json!({"training": {"cone_deg": 30.0}})).contains("sonars[0].cone_deg"));
    assert!(
        err(json!({"training": {"landmark_shift": 0.1}, "train_robot_like": true}))
            .contains("training is either robot-like or varied")
    );
    assert!(err(json!({"training": {"noise_sd": 0.1}}))
        .contains("landmark: training.noise_sd: unknown field `noise_sd`"));
    assert!(err(json!({"training": {"cone_deg": "wide"}}))
        .contains("landmark: training.cone_deg: invalid type: string \"wide\""));
    // A landmark moved out of the room is an error when the trial is drawn.
    let far = LandmarkConfig {
        training: Training {
            landmark_shift: 5.0,
            ..Training::default()
        },
        ..varied()
    };
    let e = LandmarkTask::new(far).unwrap_err().to_string();
    assert!(
        e.contains(
            "landmark1: training moved the landmark out of the room (training.landmark_shift"
        ),
        "{e}"
    );
    // So is a room scaled until the landmark no longer fits, when the config is read.
    let e = err(json!({"training": {"room_scale": 0.3}, "landmark1": {
        "room": [6.0, 5.0], "start": {"min": [0.4, 0.4], "max": [5.6, 4.6]},
        "boxes": [{"center": [0.8, 2.5], "size": [1.2, 0.6]}]}}));
    assert!(e.contains("room_scale reach too far for this world"), "{e}");
    assert!(LandmarkTask::from_params(&json!({"training": {"room_scale": 0.3}})).is_ok());
    // All ranges 0 is off, whatever ideal_trials_per_landmark says.
    assert!(Training::default().is_off());
    assert!(Training {
        ideal_trials_per_landmark: 2,
        ..Training::default()
    }
    .is_off());
    assert!(!varied().training.is_off());
}

#[test]
fn a_robot_like_jitter_that_could_move_a_box_out_of_its_room_is_refused() {
    // Landmark 1's box (1.2 m x 0.6 m at (3, 2.5) in a 6 m x 5 m room) is 3 * 0.95 - 0.6 = 2.25 m
    // from the left and right walls of the room 5% narrower.
    let e = err(json!({"robot_like": {"box_shift": 3.0}}));
    assert_eq!(
        e,
        "invalid config: robot_like.box_shift is 3; with robot_like.room_scale 0.05 it could move \
         landmark1's box 0 out of its room (at most 2.250 m keeps it inside)"
    );
    let near = json!({"robot_like": {"box_shift": 0.2, "room_scale": 0.3}, "landmark1": {
        "room": [6.0, 5.0], "start": {"min": [0.4, 0.4], "max": [5.6, 4.6]},
        "boxes": [{"center": [0.8, 2.5], "size": [1.2, 0.6]}]}});
    assert!(err(near).contains(
        "robot_like.room_scale is 0.3; a room that much smaller would push \
                                landmark1's box 0 into its wall"
    ));
    assert!(LandmarkTask::from_params(
        &json!({"robot_like": {"box_shift": 0.9, "room_scale": 0.45}})
    )
    .is_ok());
}

#[test]
fn with_training_off_the_trials_are_the_unvaried_ones() {
    for robot_like in [false, true] {
        let plain = LandmarkConfig {
            trial_seconds: 15.0,
            train_robot_like: robot_like,
            ..LandmarkConfig::default()
        };
        let t = task(plain.clone());
        let trials = t.trials(3, 2).unwrap();
        for (k, s) in trials.iter().enumerate() {
            let stream = Stream::new(3, 2, Purpose::Trial, 0, k as u64);
            let landmark = if k < 3 { 1 } else { 2 };
            assert_eq!(s, &t.sense(landmark, stream, robot_like).unwrap());
        }
        let off = task(LandmarkConfig {
            training: Training {
                ideal_trials_per_landmark: 3,
                ..Training::default()
            },
            ..plain
        });
        assert_eq!(off.trials(3, 2).unwrap(), trials);
    }
}

#[test]
fn varied_trials_are_deterministic_and_ignore_threads() {
    let t = task(varied());
    let trials = t.trials(5, 1).unwrap();
    assert_eq!(trials, t.trials(5, 1).unwrap());
    assert_ne!(trials, t.trials(5, 2).unwrap());
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    assert_eq!(one.install(|| t.trials(5, 1).unwrap()), trials);
    let net = ctrnn::Network::new(
        vec![1.0; 8],
        vec![0.5; 8],
        (0..64).map(|k| f64::from(k % 7) - 3.0).collect(),
        vec![4.0; 8],
        None,
    )
    .unwrap();
    let nets = vec![net; 3];
    assert_eq!(
        one.install(|| t.evaluate(&nets, 1, 5, None).unwrap()),
        t.evaluate(&nets, 1, 5, None).unwrap()
    );
}

#[test]
fn varied_trials_vary_within_their_ranges_and_keep_the_landmark_rigid() {
    let c = varied();
    let t = task(c.clone());
    let unvaried = task(LandmarkConfig {
        training: Training::default(),
        ..c.clone()
    });
    let plain = unvaried.trials(8, 4).unwrap();
    let mut lengths = vec![];
    for (k, (s, p)) in t.trials(8, 4).unwrap().iter().zip(&plain).enumerate() {
        if k % 3 == 0 {
            // The first trial of each landmark stays ideal.
            assert_eq!(s, p);
            continue;
        }
        assert_ne!(s.world, p.world);
        lengths.push(s.input.len());
        assert!((120..=180).contains(&s.input.len()), "{}", s.input.len());
        assert!(s.input.iter().all(|x| (0.0..=1.0).contains(x)));
        // The room never changes; the boxes move, turn and scale together.
        assert_eq!(s.world.room, p.world.room);
        let scale = s.world.boxes[0].size[0] / p.world.boxes[0].size[0];
        assert!((0.8..=1.2).contains(&scale), "{scale}");
        for (b, q) in s.world.boxes.iter().zip(&p.world.boxes) {
            assert!((b.size[0] / q.size[0] - scale).abs() < 1e-12);
            assert!((b.size[1] / q.size[1] - scale).abs() < 1e-12);
            assert!((b.angle_deg - s.world.boxes[0].angle_deg).abs() < 1e-12);
            assert!(b.angle_deg.abs() <= 20.0);
        }
        if s.landmark == 2 {
            // The crates keep their layout: their distance scales with them.
            let d = |w: &WorldSpec| {
                (w.boxes[1].center[0] - w.boxes[0].center[0])
                    .hypot(w.boxes[1].center[1] - w.boxes[0].center[1])
            };
            assert!((d(&s.world) - scale * d(&p.world)).abs() < 1e-9);
        }
    }
    assert!(lengths.iter().any(|&n| n != lengths[0]));
}

#[test]
fn at_ends_puts_every_range_at_the_end_on_its_draws_side() {
    let c = varied();
    let uniform = task(c.clone()).trials(8, 4).unwrap();
    let ends = task(LandmarkConfig {
        training: Training {
            at_ends: true,
            ..c.training.clone()
        },
        ..c
    })
    .trials(8, 4)
    .unwrap();
    let plain = LandmarkConfig::default();
    for (k, (e, u)) in ends.iter().zip(&uniform).enumerate() {
        if k % 3 == 0 {
            assert_eq!(e, u, "the ideal trials do not vary");
            continue;
        }
        // 15 s +- 3 s of 0.1 s steps, and the landmark's scale 1 +- 0.2 and turn +-20 degrees,
        // the last two at the end on the side of the uniform draw of the same stream.
        assert!([120, 180].contains(&e.input.len()), "trial {k}");
        let side = |x: f64| if x < 0.0 { -1.0 } else { 1.0 };
        let ideal = &plain.world(e.landmark).boxes[0];
        let scale = |s: &tasks::landmark::Sensing| s.world.boxes[0].size[0] / ideal.size[0] - 1.0;
        assert!((scale(e) - 0.2 * side(scale(u))).abs() < 1e-12, "trial {k}");
        let turn = |s: &tasks::landmark::Sensing| s.world.boxes[0].angle_deg - ideal.angle_deg;
        assert!((turn(e) - 20.0 * side(turn(u))).abs() < 1e-12, "trial {k}");
    }
    // Ranges of 0 stay off, whatever at_ends says.
    assert!(Training {
        at_ends: true,
        ..Training::default()
    }
    .is_off());
}

/// The robot-like test and training share nothing: the test never draws from the training
/// variations, and training never uses the robot-like model.
#[test]
fn the_test_world_and_the_training_world_are_separate() {
    let c = varied();
    let plain = task(LandmarkConfig {
        training: Training::default(),
        ..c.clone()
    });
    let t = task(c.clone());
    let net = ctrnn::Network::new(
        vec![2.0; 8],
        vec![0.0; 8],
        vec![1.0; 64],
        vec![3.0; 8],
        None,
    )
    .unwrap();
    for robot_like in [false, true] {
        assert_eq!(
            t.fresh_trials(2, 9, robot_like).unwrap(),
            plain.fresh_trials(2, 9, robot_like).unwrap()
        );
        assert_eq!(
            t.assess(&net, 2, 9, robot_like).unwrap(),
            plain.assess(&net, 2, 9, robot_like).unwrap()
        );
    }
    assert_eq!(
        t.succeeds(&net, 4).unwrap(),
        plain.succeeds(&net, 4).unwrap()
    );
    // Training reads nothing of the robot-like model: changing it changes no training trial.
    let wild = task(LandmarkConfig {
        robot_like: RobotLike {
            noise_sd: 0.5,
            specular_max_incidence_deg: 10.0,
            box_shift: 0.4,
            room_scale: 0.3,
        },
        ..c
    });
    assert_eq!(wild.trials(6, 3).unwrap(), t.trials(6, 3).unwrap());
}

/// With training varied, the validation set is `validation_trials` ideal trials per landmark
/// and as many varied ones, from the Validate streams (never a training trial), and each
/// network's rate counts its right answers over the whole set, trials of every length.
#[test]
fn varied_training_validates_on_ideal_and_varied_trials() {
    let c = LandmarkConfig {
        validation_trials: 3,
        ..varied()
    };
    let t = task(c.clone());
    let set = varied_validation_trials(&t, 21).unwrap().unwrap();
    assert_eq!(set.len(), 12);
    let steps = c.steps();
    for (i, s) in set.iter().enumerate() {
        let landmark = if i < 6 { 1 } else { 2 };
        assert_eq!(s.landmark, landmark, "trial {i}");
        let ideal = i % 6 < 3;
        assert_eq!(&s.world == c.world(landmark), ideal, "trial {i}");
        if ideal {
            assert_eq!(s.input.len(), steps, "trial {i}");
        }
    }
    let lengths: std::collections::BTreeSet<_> = set.iter().map(|s| s.input.len()).collect();
    assert!(
        lengths.len() > 2,
        "varied trials differ in length: {lengths:?}"
    );
    let training: Vec<_> = (0..20)
        .flat_map(|g| t.trials(21, g).unwrap())
        .map(|s| s.poses[0])
        .collect();
    assert!(set.iter().all(|s| !training.contains(&s.poses[0])));
    // Training off: the unvaried set of before.
    let plain = task(LandmarkConfig {
        training: Training::default(),
        ..c
    });
    assert!(varied_validation_trials(&plain, 21).is_none());

    let nets: Vec<_> = (0..3)
        .map(|i| {
            let mut s = Stream::new(5, 0, Purpose::Init, i, 0);
            let layout = t.layout();
            let genes = ctrnn::genome::random(layout, &Default::default(), &mut s);
            ctrnn::genome::decode(layout, &genes).unwrap()
        })
        .collect();
    let vs = t.validate(&nets, 21, None).unwrap().unwrap();
    for (net, v) in nets.iter().zip(&vs) {
        let records: Vec<_> = set
            .iter()
            .map(|s| t.record(net, s.clone()).unwrap())
            .collect();
        let right = records
            .iter()
            .filter(|r| tasks::landmark::answer(r.classification) == r.sensing.landmark)
            .count();
        assert_eq!(v.rate, right as f64 / 12.0);
        let total: f64 = records
            .iter()
            .map(|r| tasks::landmark::score(r.sensing.landmark, r.classification))
            .sum();
        assert_eq!(v.score, total / 12.0);
    }
}

/// The room's scale and the sonar's axis draw from a third stream: the other variations keep
/// their draws, the room and everything in it scale within range, and the boxes keep the size
/// and turn the second stream gave them.
#[test]
fn room_and_axis_variations_leave_the_other_draws_alone() {
    let base = varied();
    let wider = LandmarkConfig {
        training: Training {
            room_scale: 0.2,
            sonar_axis_deg: 15.0,
            ..base.training.clone()
        },
        ..base.clone()
    };
    let before = task(base).trials(6, 3).unwrap();
    let after = task(wider).trials(6, 3).unwrap();
    let mut rooms = vec![];
    for (k, (a, b)) in after.iter().zip(&before).enumerate() {
        if k % 3 == 0 {
            assert_eq!(a, b, "the ideal trials do not vary");
            continue;
        }
        let [sx, sy] = [a.world.room[0] / 6.0, a.world.room[1] / 5.0];
        assert!(
            (0.8..=1.2).contains(&sx) && (0.8..=1.2).contains(&sy),
            "{sx} {sy}"
        );
        rooms.push(a.world.room);
        assert!((a.world.start.max[0] - 5.6 * sx).abs() < 1e-12);
        assert!((a.world.start.min[1] - 0.4 * sy).abs() < 1e-12);
        for (p, q) in a.world.boxes.iter().zip(&b.world.boxes) {
            assert_eq!((p.size, p.angle_deg), (q.size, q.angle_deg));
            // The landmark moves whole: its layout (landmark 2's gap) does not stretch.
            for k in 0..2 {
                let apart =
                    |w: &WorldSpec| w.boxes.last().unwrap().center[k] - w.boxes[0].center[k];
                assert!((apart(&a.world) - apart(&b.world)).abs() < 1e-9);
            }
        }
        assert_eq!(
            a.input.len(),
            b.input.len(),
            "the trial's length is the second stream's"
        );
    }
    assert!(rooms.iter().any(|r| r != &rooms[0]));
    let e = err(json!({"training": {"room_scale": 0.4}}));
    assert!(
        e.contains("training.room_scale is 0.4; it must be in [0, 0.3]"),
        "{e}"
    );
    let e = err(json!({"training": {"sonar_axis_deg": -1.0}}));
    assert!(
        e.contains("training.sonar_axis_deg is -1; it must be in [0, 90]"),
        "{e}"
    );
}
