//! One-dimensional navigation (paper §4): a point agent on a line learns, over successive
//! trials, whether its environment is landmark-far or landmark-near, and then goes to the goal.
//!
//! # The world
//! The line runs over `[-half_length, half_length]` (default ±20); the agent starts at `start`
//! (default 0) with velocity `f(v_R) - f(v_L)`. The goal is at one end. The landmark is a segment
//! of width `landmark_width` (default 4) centred at `landmark_offset` (default 10) from the
//! centre: on the goal's side in a landmark-near environment, on the other side in a
//! landmark-far one. Input 0 is the landmark sensor; input 1, if the network has it, is the
//! reinforcement. By default the world is continuous: the agent moves and its sensors are read at
//! every integration step of the network ([`World`]). See [`world`] for one update of the world
//! and the end of a trial, and `docs/nav1d.md`.
//!
//! # What is scored
//! [`Objective`] picks the experiment: the paper's goal-seeking networks (`goal`), its
//! classifier (`classify`), or one network for the whole task (`single`). The integrated system
//! of §4.2 is [`System`].
//!
//! # Success rule
//! On fresh conditions ([`Nav1dTask::fresh_chains`], drawn with `Purpose::Evaluate`), at least 95 %
//! ([`SUCCESS_RATE`]) of the scored trials are done right: the goal reached (`goal`, and trials
//! 2..k with `single`) or the environment classified right (`classify`: `f(v_C) >= 0.5` exactly in
//! landmark-near environments).
//!
//! # Example
//! ```
//! use ctrnn::{Network, Task};
//! use tasks::nav1d::{Nav1dConfig, Nav1dTask};
//! let task = Nav1dTask::new(Nav1dConfig { reinforcement_input: false, ..Nav1dConfig::default() })?;
//! // Right motor (neuron 1) on, left motor (neuron 0) off: the agent always moves right, so it
//! // reaches the goal in the two goal-right trials of four.
//! let net = Network::new(vec![1.0; 5], vec![8.0, -8.0, 0.0, 0.0, 0.0], vec![0.0; 25],
//!                        vec![0.0; 5], None)?;
//! assert_eq!(task.evaluate(&[net], 0, 7, None)?, vec![0.5]);
//! # Ok::<(), ctrnn::Error>(())
//! ```

mod config;
mod environment;
mod system;
mod task;
pub mod world;

pub use config::{Nav1dConfig, Objective, World};
pub use environment::Environment;
pub use system::{Part, System, SystemAssessment, SystemEpisode};
pub use task::{Assessment, Episode, Nav1dTask, Record, SUCCESS_CHAINS, SUCCESS_RATE};
pub use world::{Condition, Side};
