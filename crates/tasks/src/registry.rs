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

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn every_name_builds_with_defaults() {
        for name in names() {
            let task = build(name, &serde_json::Value::Null).unwrap();
            task.layout().validate().unwrap();
            build(name, &json!({})).unwrap();
        }
    }

    #[test]
    fn sequence_params_are_read_and_checked() {
        let task = build("sequence", &json!({"size": 7, "targets": ["01", "10"]})).unwrap();
        assert_eq!(task.layout().size, 7);
        assert_eq!(task.layout().n_inputs, 2);
        let err = |p: serde_json::Value| build("sequence", &p).err().unwrap();
        let e = err(json!({"triggers": 10, "bogus": 1}));
        assert!(matches!(e, Error::Config(_)), "{e:?}");
        assert!(e.to_string().contains("bogus"), "{e}");
        let e = err(json!({"size": "five"})).to_string();
        assert!(e.contains("sequence"), "{e}");
        let e = err(json!({"targets": ["0", "2"]})).to_string();
        assert!(e.contains("targets[1]"), "{e}");
        let e = err(json!([1, 2])).to_string();
        assert!(e.contains("JSON object"), "{e}");
    }

    #[test]
    fn unknown_name_lists_the_known_ones() {
        let e = build("x", &json!({})).err().unwrap();
        assert!(matches!(e, Error::Config(_)));
        assert_eq!(
            e.to_string(),
            "invalid config: unknown task \"x\"; known tasks: sequence, nav1d, landmark"
        );
    }
}
