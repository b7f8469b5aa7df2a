//! NumPy arrays for the fields of the tasks' typed records (`SequenceRecord`, `Nav1dRecord`,
//! `LandmarkRecord`): each record is built once, in Rust, from the task's own struct.

use numpy::{PyArray1, PyArrayDyn};
use pyo3::prelude::*;

use crate::arrays::to_numpy;

/// A float vector as a 1-D array.
pub fn vector(py: Python<'_>, v: Vec<f64>) -> PyResult<Py<PyArrayDyn<f64>>> {
    let n = v.len();
    Ok(to_numpy(py, v, &[n])?.unbind())
}

/// Rows of `columns` floats as a (rows, columns) array.
pub fn matrix<R: AsRef<[f64]>>(
    py: Python<'_>,
    rows: Vec<R>,
    columns: usize,
) -> PyResult<Py<PyArrayDyn<f64>>> {
    let n = rows.len();
    let flat: Vec<f64> = rows.iter().flat_map(|r| r.as_ref().to_vec()).collect();
    Ok(to_numpy(py, flat, &[n, columns])?.unbind())
}

/// Integers as an int64 array.
pub fn integers<T: Copy + TryInto<i64>>(py: Python<'_>, v: &[T]) -> Py<PyArray1<i64>> {
    let v: Vec<i64> = v
        .iter()
        .map(|&x| x.try_into().unwrap_or(i64::MAX))
        .collect();
    PyArray1::from_vec(py, v).unbind()
}

/// Booleans as a bool array.
pub fn flags(py: Python<'_>, v: Vec<bool>) -> Py<PyArray1<bool>> {
    PyArray1::from_vec(py, v).unbind()
}
