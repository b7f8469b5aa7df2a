//! Tasks by name: the one place that maps a task's name and its JSON parameters to a
//! [`ctrnn::Task`].
//!
//! # Example
//! ```
//! let e = tasks::build("maze", &serde_json::json!({})).err().unwrap().to_string();
//! assert!(e.contains("unknown task \"maze\"; known tasks: sequence, nav1d, landmark"), "{e}");
//! ```

use ctrnn::{Error, Result, Task};

use crate::landmark::LandmarkTask;
use crate::nav1d::Nav1dTask;
use crate::sequence::SequenceTask;

/// The names [`build`] knows, in the order they are listed in messages.
const NAMES: &[&str] = &["sequence", "nav1d", "landmark"];

/// The names of the known tasks.
pub fn names() -> &'static [&'static str] {
    NAMES
}

/// Makes the task `name` from `params`, a JSON object of its config fields (`null` means all
/// defaults).
///
/// - `"sequence"`: a [`SequenceConfig`](crate::sequence::SequenceConfig);
/// - `"nav1d"`: a [`Nav1dConfig`](crate::nav1d::Nav1dConfig);
/// - `"landmark"`: a [`LandmarkConfig`](crate::landmark::LandmarkConfig).
///
/// Unknown names, unknown or mistyped parameters and out-of-range values are [`Error::Config`]
/// errors that say what was wrong and what is allowed.
///
/// # Example
/// ```
/// use ctrnn::Task;
/// let params = serde_json::json!({"size": 10, "perf_base": "generation-mean"});
/// let task = tasks::build("sequence", &params)?;
/// assert_eq!(task.layout().size, 10);
/// let e = tasks::build("sequence", &serde_json::json!({"sise": 10})).err().unwrap().to_string();
/// assert!(e.contains("unknown field `sise`"), "{e}");
/// # Ok::<(), ctrnn::Error>(())
/// ```
pub fn build(name: &str, params: &serde_json::Value) -> Result<Box<dyn Task>> {
    match name {
        "sequence" => Ok(Box::new(SequenceTask::from_params(params)?)),
        "nav1d" => Ok(Box::new(Nav1dTask::from_params(params)?)),
        "landmark" => Ok(Box::new(LandmarkTask::from_params(params)?)),
        _ => Err(Error::Config(format!(
            "unknown task {name:?}; known tasks: {}",
            NAMES.join(", ")
        ))),
    }
}
