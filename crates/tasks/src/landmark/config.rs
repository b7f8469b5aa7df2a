//! The settings of the landmark-recognition experiment: the network, the two worlds, the robot
//! trial, and the "robot-like" conditions of the stand-in for the paper's real-robot test.

use ctrnn::{Error, Integrator, Precision, Result};

use crate::common::TIME_STEP;
use serde::{Deserialize, Serialize};
use sim2d::{SimSpec, WorldSpec};

use super::training::Training;

/// Conditions that make a simulated trial more like the real robot's: sonar noise, specular
/// misses and a jittered room. Each trial draws its own jitter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RobotLike {
    /// Gaussian range noise of the network's sonar, in metres. Default 0.03.
    pub noise_sd: f64,
    /// Rays hitting a surface at more than this angle of incidence, in degrees, are lost (a
    /// specular miss). Default 60.
    pub specular_max_incidence_deg: f64,
    /// Each box moves by up to this much in x and y, in metres. Default 0.15.
    pub box_shift: f64,
    /// The room's width and height each scale by up to this fraction. Default 0.05.
    pub room_scale: f64,
}

impl Default for RobotLike {
    fn default() -> Self {
        RobotLike {
            noise_sd: 0.03,
            specular_max_incidence_deg: 60.0,
            box_shift: 0.15,
            room_scale: 0.05,
        }
    }
}

/// The landmark-recognition settings (paper §3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LandmarkConfig {
    /// Neurons per network N. Default 8.
    pub size: usize,
    /// The classifier neuron: `f < 0.5` at the end of a trial means landmark 1. Default 0.
    pub classifier: usize,
    /// Trials per landmark in one evaluation. Default 3 (the paper's 6 trials in all).
    pub trials_per_landmark: usize,
    /// Fresh trials per landmark in a run's validation set, on which the best candidates of each
    /// generation are judged to choose the champion (in the training conditions). Default 50.
    pub validation_trials: usize,
    /// Simulated seconds per trial. Default 45.
    pub trial_seconds: f64,
    /// The sonar input is `min(1, d0 / range)`. Default 0.5 m.
    pub d0: f64,
    /// The world of landmark 1. Default the shipped `landmark1.toml` (two crates pushed together).
    pub landmark1: WorldSpec,
    /// The world of landmark 2. Default the shipped `landmark2.toml` (two crates 0.6 m apart).
    pub landmark2: WorldSpec,
    /// The robot trial: time step, robot, wall follower and the network's sonar (`sonars[0]`, the
    /// left one, is the input). Default [`SimSpec::default`] (0.1 s steps).
    pub sim: SimSpec,
    /// Train (and check success) under robot-like conditions instead of the ideal world.
    /// Default false.
    pub train_robot_like: bool,
    /// What "robot-like" means. Default [`RobotLike::default`].
    pub robot_like: RobotLike,
    /// How the training trials vary: a minimal simulation that varies what a network must not
    /// rely on, differing in kind from the robot-like test (see [`Training`]). Default
    /// [`Training::default`]: no variation, the paper's training. Cannot be combined with
    /// `train_robot_like`.
    pub training: Training,
    /// How the network is integrated over one robot step; `dt * substeps` is one unit of network
    /// time, so by default one robot step of 0.1 s is one network time step. Default 10 Euler
    /// steps of 0.1.
    pub integrator: Integrator,
    /// The floating-point type the networks compute in: `"f64"` (default, the reference) or
    /// `"f32"`, opt-in single precision (see [`ctrnn::Precision`]). The world, the inputs and the
    /// scores stay `f64`; each input is rounded to `f32` as the network reads it.
    pub precision: Precision,
}

impl Default for LandmarkConfig {
    fn default() -> Self {
        LandmarkConfig {
            size: 8,
            classifier: 0,
            trials_per_landmark: 3,
            validation_trials: 50,
            trial_seconds: 45.0,
            d0: sim2d::DEFAULT_D0,
            landmark1: WorldSpec::landmark(1).expect("the shipped world is valid"),
            landmark2: WorldSpec::landmark(2).expect("the shipped world is valid"),
            sim: SimSpec::default(),
            train_robot_like: false,
            robot_like: RobotLike::default(),
            training: Training::default(),
            integrator: TIME_STEP,
            precision: Precision::F64,
        }
    }
}

/// A `sim2d` error as a config error.
pub(crate) fn config_error(e: sim2d::Error) -> Error {
    Error::Config(e.to_string())
}

impl LandmarkConfig {
    /// Checks every field; the error names the field and says what is allowed.
    ///
    /// # Example
    /// ```
    /// use tasks::landmark::LandmarkConfig;
    /// let bad = LandmarkConfig { classifier: 8, ..LandmarkConfig::default() };
    /// assert!(bad.validate().unwrap_err().to_string().contains("classifier is 8"));
    /// ```
    pub fn validate(&self) -> Result<()> {
        let config = |msg: String| Err(Error::Config(msg));
        for (name, value) in [
            ("size", self.size),
            ("trials_per_landmark", self.trials_per_landmark),
            ("validation_trials", self.validation_trials),
        ] {
            crate::common::check_count(name, value)?;
        }
        if self.classifier >= self.size {
            return config(format!(
                "classifier is {}; it must be a neuron index below size ({})",
                self.classifier, self.size
            ));
        }
        for (name, value) in [("trial_seconds", self.trial_seconds), ("d0", self.d0)] {
            if !(value.is_finite() && value > 0.0) {
                return config(format!("{name} is {value}; it must be a number > 0"));
            }
        }
        self.landmark1
            .validate()
            .map_err(|e| Error::Config(format!("landmark1: {e}")))?;
        self.landmark2
            .validate()
            .map_err(|e| Error::Config(format!("landmark2: {e}")))?;
        self.sim
            .validate()
            .map_err(|e| Error::Config(format!("sim: {e}")))?;
        if self.sim.sonars.is_empty() {
            return config("sim.sonars is empty; the network reads sonars[0]".into());
        }
        let r = &self.robot_like;
        for (name, value, hi) in [
            ("robot_like.noise_sd", r.noise_sd, f64::INFINITY),
            (
                "robot_like.specular_max_incidence_deg",
                r.specular_max_incidence_deg,
                90.0,
            ),
            ("robot_like.box_shift", r.box_shift, f64::INFINITY),
            ("robot_like.room_scale", r.room_scale, 0.5),
        ] {
            if !(value.is_finite() && (0.0..=hi).contains(&value)) {
                return config(format!("{name} is {value}; it must be in [0, {hi}]"));
            }
        }
        self.check_robot_like_fits()?;
        self.training.validate()?;
        self.validate_training()?;
        self.integrator.validate().map_err(|e| match e {
            Error::InvalidArgument(msg) => Error::Config(format!("integrator: {msg}")),
            other => other,
        })?;
        // `as` saturates, so an absurd ratio stays absurd rather than wrapping.
        let longest = ((self.trial_seconds + self.training.trial_seconds) / self.sim.dt).round();
        crate::common::check_trial_steps(
            "(trial_seconds + training.trial_seconds) / sim.dt",
            longest as u128,
            self.integrator.substeps,
        )
    }

    /// The robot-like jitter keeps every box inside its room at the extremes of
    /// `robot_like.box_shift` and `room_scale`, so that `WorldSpec::jittered` never has to clamp
    /// a box back in: a box's distance from each wall scales with the room, so the room at its
    /// smallest, `1 - room_scale`, leaves the least margin, and the shift must stay within it.
    fn check_robot_like_fits(&self) -> Result<()> {
        let r = &self.robot_like;
        let least = 1.0 - r.room_scale;
        for (name, world) in [
            ("landmark1", &self.landmark1),
            ("landmark2", &self.landmark2),
        ] {
            for (i, b) in world.boxes.iter().enumerate() {
                let half = b.aabb_half_extents();
                for k in 0..2 {
                    let margin = b.center[k].min(world.room[k] - b.center[k]) * least - half[k];
                    if margin < 0.0 {
                        return Err(Error::Config(format!(
                            "robot_like.room_scale is {}; a room that much smaller would push \
                             {name}'s box {i} into its wall",
                            r.room_scale
                        )));
                    }
                    if r.box_shift > margin {
                        return Err(Error::Config(format!(
                            "robot_like.box_shift is {}; with robot_like.room_scale {} it could \
                             move {name}'s box {i} out of its room (at most {margin:.3} m keeps it \
                             inside)",
                            r.box_shift, r.room_scale
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// How `training`'s ranges fit the rest of the config: trial counts and lengths, robot-like
    /// training, and a follower and sonar that stay valid at both ends of the ranges.
    fn validate_training(&self) -> Result<()> {
        let t = &self.training;
        let err = |msg: String| Err(Error::Config(format!("training.{msg}")));
        if t.ideal_trials_per_landmark > self.trials_per_landmark {
            return err(format!(
                "ideal_trials_per_landmark is {}; it must be at most trials_per_landmark ({})",
                t.ideal_trials_per_landmark, self.trials_per_landmark
            ));
        }
        if t.trial_seconds >= self.trial_seconds {
            return err(format!(
                "trial_seconds is {}; it must be below the trial's own length, trial_seconds ({})",
                t.trial_seconds, self.trial_seconds
            ));
        }
        if t.is_off() {
            return Ok(());
        }
        if self.train_robot_like {
            return Err(Error::Config(
                "training varies the training trials, and train_robot_like is true; training is \
                 either robot-like or varied, so set train_robot_like = false or leave training \
                 empty"
                    .into(),
            ));
        }
        for n in [1, 2] {
            t.check_world(self.world(n)).map_err(|e| match e {
                Error::Config(m) => Error::Config(format!("landmark{n}: {m}")),
                other => other,
            })?;
        }
        // The follower and the sonar must be valid at both ends of their ranges.
        for sign in [-1.0, 1.0] {
            let mut sim = self.sim.clone();
            sim.follower.wall_distance += sign * t.follower_distance;
            sim.follower.speed *= 1.0 + sign * t.follower_speed;
            sim.sonars[0].cone_deg += sign * t.cone_deg;
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

    /// Robot steps per trial: `trial_seconds / sim.dt`, rounded.
    pub fn steps(&self) -> usize {
        (self.trial_seconds / self.sim.dt).round() as usize
    }

    /// The world of landmark `n` (1 or 2).
    pub fn world(&self, n: u8) -> &WorldSpec {
        if n == 1 {
            &self.landmark1
        } else {
            &self.landmark2
        }
    }
}
