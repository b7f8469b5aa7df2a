//! The experiments of Yamauchi & Beer, each coupling a [`ctrnn::Network`] with its environment and
//! scoring it: sequence learning (§5), one-dimensional navigation (§4) and landmark recognition
//! (§3).
//!
//! Every experiment implements [`ctrnn::Task`], so an evolution run scores a whole generation
//! with one call; [`registry::build`] makes a task from its name and a JSON object of parameters.
//!
//! # Example
//! ```
//! use ctrnn::Task;
//! let task = tasks::build("sequence", &serde_json::json!({"targets": ["0", "1"]}))?;
//! assert_eq!(task.layout().n_inputs, 2);
//! # Ok::<(), ctrnn::Error>(())
//! ```
#![warn(missing_docs)]

mod aggregate;
mod common;
pub mod landmark;
mod lanes;
pub mod nav1d;
pub mod registry;
mod run_config;
pub mod sequence;
mod step_check;
// Internals for the crate's own integration tests (tests/unit); not public API.
#[doc(hidden)]
pub mod testing;

pub use aggregate::Aggregate;
pub use common::{MAX_COUNT, TIME_STEP};
pub use registry::{build, names};
pub use run_config::RunConfig;
pub use sequence::{
    performance, Assessment, Clamp, PerfBase, Scores, SequenceConfig, SequenceTask, TargetReport,
    TrialRecord,
};
pub use step_check::StepChecked;
