//! Task parameters arrive, and detailed results leave, as JSON text.

use pyo3::prelude::*;

use crate::errors::ConfigError;

/// Parses a task's JSON parameters; bad JSON is a `ConfigError`.
pub fn params(text: &str) -> PyResult<serde_json::Value> {
    serde_json::from_str(text).map_err(|e| ConfigError::new_err(format!("task parameters: {e}")))
}

/// JSON text of a task record.
pub fn to_json<T: serde::Serialize>(value: &T) -> String {
    serde_json::to_string(value).expect("task records always serialise")
}
