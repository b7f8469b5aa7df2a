//! Read-only NumPy arrays for the fields of the core's typed results: the tasks' records
//! (`SequenceRecord`, `Nav1dRecord`, `LandmarkRecord`) and the analysis results
//! (`dnnevo._core.Equilibrium`, ...). Each is built once, in Rust, from the core's own struct, and
//! is frozen like the object that holds it: writing into one of its arrays raises.

use numpy::{PyArray1, PyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::arrays::to_numpy;

/// `array`, made read-only.
pub fn frozen<T>(py: Python<'_>, array: Py<T>) -> PyResult<Py<T>> {
    let kwargs = PyDict::new(py);
    kwargs.set_item("write", false)?;
    array
        .bind(py)
        .as_any()
        .call_method("setflags", (), Some(&kwargs))?;
    Ok(array)
}

/// A float vector as a read-only 1-D array.
pub fn vector(py: Python<'_>, v: Vec<f64>) -> PyResult<Py<PyArrayDyn<f64>>> {
    let n = v.len();
    frozen(py, to_numpy(py, v, &[n])?.unbind())
}

/// Rows of `columns` floats as a read-only (rows, columns) array.
pub fn matrix<R: AsRef<[f64]>>(
    py: Python<'_>,
    rows: Vec<R>,
    columns: usize,
) -> PyResult<Py<PyArrayDyn<f64>>> {
    let n = rows.len();
    let flat: Vec<f64> = rows.iter().flat_map(|r| r.as_ref().to_vec()).collect();
    frozen(py, to_numpy(py, flat, &[n, columns])?.unbind())
}

/// Integers as a read-only int64 array.
pub fn integers<T: Copy + TryInto<i64>>(py: Python<'_>, v: &[T]) -> PyResult<Py<PyArray1<i64>>> {
    let v: Vec<i64> = v
        .iter()
        .map(|&x| x.try_into().unwrap_or(i64::MAX))
        .collect();
    frozen(py, PyArray1::from_vec(py, v).unbind())
}

/// Booleans as a read-only bool array.
pub fn flags(py: Python<'_>, v: Vec<bool>) -> PyResult<Py<PyArray1<bool>>> {
    frozen(py, PyArray1::from_vec(py, v).unbind())
}
