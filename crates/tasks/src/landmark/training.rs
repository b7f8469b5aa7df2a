//! Varied training: a Jakobi-style minimal simulation for the landmark task.
//!
//! The ideal simulator is exact in ways the real robot is not: the landmark always stands at the
//! same spot, the robot always drives at the same speed the same distance from the wall, the
//! sonar always has the same beam, and its reading always maps to the same input. An evolved
//! network can use any of these as a cue (the exact height of a bump, the exact time between two
//! bumps), and then fails on a robot. [`Training`] varies, trial by trial, what a network must
//! *not* rely on, so that only the cue that tells the landmarks apart on any robot is left: the
//! shape of the sonar's time course as the robot passes one long box or two boxes with a gap.
//!
//! The variations are chosen to differ in kind from the robot-like *test*
//! ([`RobotLike`](super::RobotLike): Gaussian range noise, specular misses, each box shifted on
//! its own, the room scaled), so that passing the test measures transfer to conditions training
//! never saw. `docs/worlds.md` gives the argument for each element.
//!
//! # One varied trial
//! Trial `t` of a generation keeps its own stream `Stream::new(seed, generation, Purpose::Trial,
//! 0, t)` for the start pose, exactly as an unvaried trial, and draws its variation from a second
//! stream, `Stream::new(seed, generation, Purpose::Trial, 1, t)`, in this order: the landmark's
//! shift in x and y, its turn, its scale, the follower's speed factor and distance offset, the
//! sonar's cone offset, the trial-length offset, the input's gain and offset, then one normal
//! variate per step for the input noise (only when `input_noise_sd > 0`). Every draw is made even
//! when its range is 0, so changing one range never moves another's draws.
//!
//! # Validation
//! A champion chosen on the ideal world alone can be one that relies on exactly what training
//! varies. So when training varies, the validation set ([`Task::validate`](ctrnn::Task)) holds
//! `validation_trials` varied trials per landmark besides the ideal ones, drawn as above from
//! `Purpose::Validate`'s streams at generation 0 instead of `Purpose::Trial`'s.

use ctrnn::{Error, Purpose, Result, Stream};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sim2d::{BoxSpec, WorldSpec};

use super::config::LandmarkConfig;
use super::task::{LandmarkTask, Sensing};

/// How the training trials vary (all ranges default to 0: no variation, the paper's training).
///
/// Each trial draws its own values, each uniform over its range. The test trials
/// ([`LandmarkTask::assess`]) never vary.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Training {
    /// The first this-many trials of each landmark in a generation stay unvaried (ideal), the
    /// rest vary. At most `trials_per_landmark`. Default 0.
    pub ideal_trials_per_landmark: usize,
    /// The whole landmark (all its boxes together, keeping their layout) moves by up to this much
    /// in x and in y, in metres. Default 0.
    pub landmark_shift: f64,
    /// The whole landmark turns about its centre by up to this many degrees, in [0, 180].
    /// Default 0.
    pub landmark_turn_deg: f64,
    /// The whole landmark (its boxes' sizes and their distances from its centre) scales by a
    /// factor in `1 ± landmark_scale`, in [0, 0.5]. Default 0.
    pub landmark_scale: f64,
    /// The wall follower's speed scales by a factor in `1 ± follower_speed`, in [0, 0.5].
    /// Default 0.
    pub follower_speed: f64,
    /// The wall follower's distance from the wall changes by up to this much, in metres; the
    /// follower must stay valid at both ends. Default 0.
    pub follower_distance: f64,
    /// The network's sonar's cone widens or narrows by up to this many degrees; the cone must
    /// stay in (0, 180) at both ends. Default 0.
    pub cone_deg: f64,
    /// The trial (and so the moment the answer is read) lengthens or shortens by up to this many
    /// seconds, less than `trial_seconds`. Default 0.
    pub trial_seconds: f64,
    /// The input `x` becomes `gain x + offset` (then clipped to [0, 1]), with the gain in
    /// `1 ± input_gain`, in [0, 0.9]. Default 0.
    pub input_gain: f64,
    /// The offset of `input_gain`'s line is in `± input_offset`, in [0, 0.5]. Default 0.
    pub input_offset: f64,
    /// Gaussian noise added to the input itself (not the range) at every step, sd in [0, 1].
    /// Default 0.
    pub input_noise_sd: f64,
}

/// One trial's draw of [`Training`]'s variations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Variation {
    shift: [f64; 2],
    turn_deg: f64,
    scale: f64,
    speed_factor: f64,
    distance_offset: f64,
    cone_offset: f64,
    seconds_offset: f64,
    gain: f64,
    offset: f64,
}

/// `range(-r, r)`: uniform over `[-r, r)`, and exactly 0 when `r` is 0.
fn symmetric(stream: &mut Stream, r: f64) -> f64 {
    stream.range(-r, r)
}

impl Training {
    /// Whether every range is 0, so that training is the paper's (no draws, no changes).
    pub fn is_off(&self) -> bool {
        self == &Training {
            ideal_trials_per_landmark: self.ideal_trials_per_landmark,
            ..Training::default()
        }
    }

    /// Checks every field against `config`; the error names the field (`training.<field>`) and
    /// says what is allowed.
    pub fn validate(&self, config: &LandmarkConfig) -> Result<()> {
        let err = |msg: String| Err(Error::Config(format!("training.{msg}")));
        let inf = f64::INFINITY;
        for (name, value, hi) in [
            ("landmark_shift", self.landmark_shift, inf),
            ("landmark_turn_deg", self.landmark_turn_deg, 180.0),
            ("landmark_scale", self.landmark_scale, 0.5),
            ("follower_speed", self.follower_speed, 0.5),
            ("follower_distance", self.follower_distance, inf),
            ("cone_deg", self.cone_deg, inf),
            ("trial_seconds", self.trial_seconds, inf),
            ("input_gain", self.input_gain, 0.9),
            ("input_offset", self.input_offset, 0.5),
            ("input_noise_sd", self.input_noise_sd, 1.0),
        ] {
            if !(value.is_finite() && (0.0..=hi).contains(&value)) {
                return err(format!("{name} is {value}; it must be in [0, {hi}]"));
            }
        }
        if self.ideal_trials_per_landmark > config.trials_per_landmark {
            return err(format!(
                "ideal_trials_per_landmark is {}; it must be at most trials_per_landmark ({})",
                self.ideal_trials_per_landmark, config.trials_per_landmark
            ));
        }
        if self.trial_seconds >= config.trial_seconds {
            return err(format!(
                "trial_seconds is {}; it must be below the trial's own length, trial_seconds ({})",
                self.trial_seconds, config.trial_seconds
            ));
        }
        if self.is_off() {
            return Ok(());
        }
        if config.train_robot_like {
            return Err(Error::Config(
                "training varies the training trials, and train_robot_like is true; training is \
                 either robot-like or varied, so set train_robot_like = false or leave training \
                 empty"
                    .into(),
            ));
        }
        // The follower and the sonar must be valid at both ends of their ranges.
        for sign in [-1.0, 1.0] {
            let mut sim = config.sim.clone();
            sim.follower.wall_distance += sign * self.follower_distance;
            sim.follower.speed *= 1.0 + sign * self.follower_speed;
            sim.sonars[0].cone_deg += sign * self.cone_deg;
            if let Err(e) = sim.validate() {
                return err(format!(
                    "follower_distance, follower_speed or cone_deg reach too far: at their {} \
                     end, {e}",
                    if sign < 0.0 { "lower" } else { "upper" }
                ));
            }
        }
        Ok(())
    }

    /// Draws one trial's variation from `stream` (see the [module docs](self) for the order).
    pub(crate) fn draw(&self, stream: &mut Stream) -> Variation {
        let shift = [
            symmetric(stream, self.landmark_shift),
            symmetric(stream, self.landmark_shift),
        ];
        let turn_deg = symmetric(stream, self.landmark_turn_deg);
        let scale = 1.0 + symmetric(stream, self.landmark_scale);
        let speed_factor = 1.0 + symmetric(stream, self.follower_speed);
        let distance_offset = symmetric(stream, self.follower_distance);
        let cone_offset = symmetric(stream, self.cone_deg);
        let seconds_offset = symmetric(stream, self.trial_seconds);
        let gain = 1.0 + symmetric(stream, self.input_gain);
        let offset = symmetric(stream, self.input_offset);
        Variation {
            shift,
            turn_deg,
            scale,
            speed_factor,
            distance_offset,
            cone_offset,
            seconds_offset,
            gain,
            offset,
        }
    }
}

/// `world` with its boxes, taken together as one landmark, scaled about the landmark's centre
/// (the centre of the boxes' bounding box), turned about it and moved. An error if a box leaves
/// the room.
fn move_landmark(world: &WorldSpec, v: &Variation) -> Result<WorldSpec> {
    if world.boxes.is_empty() {
        return Ok(world.clone());
    }
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for b in &world.boxes {
        let half = b.aabb_half_extents();
        for k in 0..2 {
            lo[k] = lo[k].min(b.center[k] - half[k]);
            hi[k] = hi[k].max(b.center[k] + half[k]);
        }
    }
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    let (s, c) = v.turn_deg.to_radians().sin_cos();
    let boxes = world
        .boxes
        .iter()
        .map(|b| {
            let rel = [
                (b.center[0] - centre[0]) * v.scale,
                (b.center[1] - centre[1]) * v.scale,
            ];
            BoxSpec {
                center: [
                    centre[0] + v.shift[0] + c * rel[0] - s * rel[1],
                    centre[1] + v.shift[1] + s * rel[0] + c * rel[1],
                ],
                size: [b.size[0] * v.scale, b.size[1] * v.scale],
                angle_deg: b.angle_deg + v.turn_deg,
            }
        })
        .collect();
    let out = WorldSpec {
        boxes,
        ..world.clone()
    };
    out.validate()
        .map_err(|e| Error::Config(format!("training moved the landmark out of the room: {e}")))?;
    Ok(out)
}

impl LandmarkTask {
    /// Training trial `t` of `generation` (landmark 1 for `t < trials_per_landmark`, then 2):
    /// unvaried (robot-like if `train_robot_like`) when training is off or `t` is among a
    /// landmark's first `ideal_trials_per_landmark`, else varied (see the [module docs](self)).
    pub(crate) fn training_trial(&self, seed: u64, generation: u64, t: usize) -> Result<Sensing> {
        let c = self.config();
        let set = TrialSet {
            purpose: Purpose::Trial,
            generation,
            per_landmark: c.trials_per_landmark,
            ideal_per_landmark: c.training.ideal_trials_per_landmark,
        };
        self.drawn_trial(&set, seed, t)
    }

    /// The validation set when training varies: `validation_trials` unvaried trials per landmark
    /// followed by as many varied ones, drawn like training trials but from
    /// [`Purpose::Validate`]'s streams at generation 0, so that the champion is chosen on the
    /// conditions training varies over as well as on the ideal world. `None` when training is off.
    pub(crate) fn varied_validation_trials(&self, seed: u64) -> Option<Result<Vec<Sensing>>> {
        let c = self.config();
        if c.training.is_off() {
            return None;
        }
        let set = TrialSet {
            purpose: Purpose::Validate,
            generation: 0,
            per_landmark: 2 * c.validation_trials,
            ideal_per_landmark: c.validation_trials,
        };
        Some(
            (0..2 * set.per_landmark)
                .into_par_iter()
                .map(|t| self.drawn_trial(&set, seed, t))
                .collect(),
        )
    }

    /// Trial `t` of `set` (landmark 1 for `t < per_landmark`, then 2), from the streams
    /// `(seed, generation, purpose, 0, t)` for its start pose and sonar, and
    /// `(seed, generation, purpose, 1, t)` for its variation.
    fn drawn_trial(&self, set: &TrialSet, seed: u64, t: usize) -> Result<Sensing> {
        let c = self.config();
        let k = set.per_landmark;
        let (landmark, index) = if t < k { (1, t) } else { (2, t - k) };
        let stream = Stream::new(seed, set.generation, set.purpose, 0, t as u64);
        let training = &c.training;
        if training.is_off() || index < set.ideal_per_landmark {
            return self.sense(landmark, stream, c.train_robot_like);
        }
        let mut draws = Stream::new(seed, set.generation, set.purpose, 1, t as u64);
        let v = training.draw(&mut draws);
        let world = move_landmark(c.world(landmark), &v)?;
        let mut sim = c.sim.clone();
        sim.follower.speed *= v.speed_factor;
        sim.follower.wall_distance += v.distance_offset;
        sim.sonars[0].cone_deg += v.cone_offset;
        let steps = ((c.trial_seconds + v.seconds_offset) / sim.dt).round() as usize;
        let mut sensing = self.sense_in(landmark, world, &sim, steps, stream)?;
        let sd = training.input_noise_sd;
        for x in &mut sensing.input {
            let noise = if sd > 0.0 { sd * draws.normal() } else { 0.0 };
            *x = (v.gain * *x + v.offset + noise).clamp(0.0, 1.0);
        }
        Ok(sensing)
    }
}

/// Which trials a set holds and whose streams they draw from.
struct TrialSet {
    purpose: Purpose,
    generation: u64,
    /// Trials per landmark.
    per_landmark: usize,
    /// The first this-many trials of each landmark are unvaried.
    ideal_per_landmark: usize,
}

#[cfg(test)]
mod tests {
    use ctrnn::{Purpose, Stream, Task};
    use serde_json::json;

    use super::super::{LandmarkConfig, LandmarkTask, RobotLike};
    use super::*;

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
        assert!(
            err(json!({"training": {"ideal_trials_per_landmark": 4}})).contains(
                "ideal_trials_per_landmark is 4; it must be at most trials_per_landmark (3)"
            )
        );
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
        let e = task(far).trials(0, 0).unwrap_err().to_string();
        assert!(e.contains("moved the landmark out of the room"), "{e}");
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
        let set = t.varied_validation_trials(21).unwrap().unwrap();
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
        assert!(plain.varied_validation_trials(21).is_none());

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
                .filter(|r| super::super::answer(r.classification) == r.sensing.landmark)
                .count();
            assert_eq!(v.rate, right as f64 / 12.0);
            let total: f64 = records
                .iter()
                .map(|r| super::super::score(r.sensing.landmark, r.classification))
                .sum();
            assert_eq!(v.score, total / 12.0);
        }
    }
}
