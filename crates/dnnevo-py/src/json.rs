//! Task reports (`assess`), task settings (`params()`), worlds and analysis results leave as Python
//! values (dicts, lists, numbers), built in Rust from their serde form: no JSON text crosses the
//! border. Records are typed objects of their own (`records.rs`).

use pyo3::prelude::*;

use crate::pyjson::value_to_py;

/// A task record or report as the Python value `json.loads` of its JSON would be.
pub fn to_py<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let value = serde_json::to_value(value).expect("task records always serialise");
    value_to_py(py, &value)
}
