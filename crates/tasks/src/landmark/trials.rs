//! The trial sets drawn with [`Training`]'s variations: a generation's training trials and, when
//! training varies, the varied half of the validation set (see the `training` module).

use ctrnn::{Purpose, Result, Stream};
use rayon::prelude::*;

use super::task::{LandmarkTask, Sensing};
use super::training::vary_world;

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
    /// `(seed, generation, purpose, 1, t)` and `(seed, generation, purpose, 2, t)` for its
    /// variation.
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
        let mut third = Stream::new(seed, set.generation, set.purpose, 2, t as u64);
        let v = training.draw(&mut draws, &mut third);
        let world = vary_world(c.world(landmark), &v)?;
        let mut sim = c.sim.clone();
        sim.follower.speed *= v.speed_factor;
        sim.follower.wall_distance += v.distance_offset;
        sim.sonars[0].cone_deg += v.cone_offset;
        sim.sonars[0].mount_angle_deg += v.axis_offset;
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
