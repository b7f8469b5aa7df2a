//! Landmark recognition (paper §3): a wall-following robot passes a landmark with a sonar
//! looking into the room, and a network tells from the sonar's time course which of two
//! landmarks it was.
//!
//! # One trial
//! The robot starts at a random pose in a 6 m x 5 m room (`sim2d`), finds a wall and follows the
//! perimeter counter-clockwise. Every robot step (0.1 s by default) the left sonar's range `d`
//! becomes the network's one input, `min(1, d0 / d)`, held for one network time step. After
//! `trial_seconds` (45 s) the classifier neuron's output `f` is read: `f < 0.5` means landmark 1
//! (two crates pushed together), otherwise landmark 2 (two crates 0.6 m apart). The score is
//! `1 - f` on landmark 1 and `f` on landmark 2; fitness is the mean over `trials_per_landmark`
//! trials of each landmark, from a reset state each.
//!
//! The wall follower, not the network, drives the robot, so a trial's sensing is computed once
//! and fed to the whole population.
//!
//! # Success rule
//! At least 95 % ([`SUCCESS_RATE`]) of fresh trials classified right. `assess` with
//! `robot_like` is the stand-in for the paper's real-robot test: sonar noise, specular misses and
//! a jittered room ([`RobotLike`]).
//!
//! # Example
//! ```
//! use ctrnn::{Network, Task};
//! use tasks::landmark::{LandmarkConfig, LandmarkTask};
//! let task = LandmarkTask::new(LandmarkConfig { trials_per_landmark: 1, ..LandmarkConfig::default() })?;
//! // A network whose classifier is stuck at 0.5 scores 0.5 on each landmark.
//! let net = Network::new(vec![1.0; 8], vec![0.0; 8], vec![0.0; 64], vec![0.0; 8], None)?;
//! assert_eq!(task.evaluate(&[net], 0, 1, None)?, vec![0.5]);
//! # Ok::<(), ctrnn::Error>(())
//! ```

mod config;
mod task;
mod training;
mod trials;

pub use config::{LandmarkConfig, RobotLike};
pub use task::{
    answer, score, Assessment, LandmarkTask, Record, Sensing, SUCCESS_RATE, SUCCESS_TRIALS,
};
pub use training::Training;
