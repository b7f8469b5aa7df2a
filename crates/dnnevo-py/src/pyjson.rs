//! Python values to JSON and back, for network files' metadata and network dicts: the error
//! for a value JSON cannot hold names where it is.

use pyo3::prelude::*;
use pyo3::types::{PyAny, PyDict};
use serde_json::{Map, Value};

use crate::errors::FormatError;

fn json_module(py: Python<'_>) -> PyResult<Bound<'_, PyModule>> {
    py.import("json")
}

/// Converts a Python dict (JSON-compatible) to a JSON object; the error for a value JSON cannot
/// hold (NaN, infinity, an object) names where it is, e.g. `theta[0]`.
pub(crate) fn dict_to_map(d: &Bound<'_, PyAny>, what: &str) -> PyResult<Map<String, Value>> {
    match to_value(d, String::new(), 0).map_err(|e| FormatError::new_err(format!("{what}: {e}")))? {
        Value::Object(m) => Ok(m),
        _ => Err(FormatError::new_err(format!("{what} must be a dict"))),
    }
}

/// The deepest nesting of lists and dicts accepted in meta and network dicts: serde_json's own
/// limit when it reads a file back, so whatever is saved can be loaded.
pub const MAX_JSON_DEPTH: usize = 128;

/// A Python value as JSON; the error says where the first unrepresentable value is.
fn to_value(obj: &Bound<'_, PyAny>, path: String, depth: usize) -> Result<Value, String> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyList, PyString, PyTuple};
    let at = |p: &str| {
        if p.is_empty() {
            "the top level".to_string()
        } else {
            p.to_string()
        }
    };
    if depth > MAX_JSON_DEPTH {
        return Err(format!(
            "{} nests lists and dicts deeper than {MAX_JSON_DEPTH}",
            at(&path)
        ));
    }
    if obj.is_none() {
        Ok(Value::Null)
    } else if let Ok(b) = obj.cast::<PyBool>() {
        Ok(Value::Bool(b.is_true()))
    } else if let Ok(i) = obj.cast::<PyInt>() {
        i.extract::<i64>()
            .map(Value::from)
            .map_err(|_| format!("{} is an integer too large for JSON", at(&path)))
    } else if let Ok(f) = obj.cast::<PyFloat>() {
        let x = f.value();
        serde_json::Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| format!("{} is {x}; every value must be finite", at(&path)))
    } else if let Ok(s) = obj.cast::<PyString>() {
        Ok(Value::String(s.to_string()))
    } else if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = Map::new();
        for (k, v) in d.iter() {
            let key = k
                .cast::<PyString>()
                .map_err(|_| format!("a key of {} is not a string", at(&path)))?
                .to_string();
            let sub = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            map.insert(key, to_value(&v, sub, depth + 1)?);
        }
        Ok(Value::Object(map))
    } else if obj.is_instance_of::<PyList>()
        || obj.is_instance_of::<PyTuple>()
        || obj.hasattr("tolist").unwrap_or(false)
    {
        let seq = if obj.hasattr("tolist").unwrap_or(false) {
            obj.call_method0("tolist").map_err(|e| e.to_string())?
        } else {
            obj.clone()
        };
        if !(seq.is_instance_of::<PyList>() || seq.is_instance_of::<PyTuple>()) {
            return to_value(&seq, path, depth + 1);
        }
        let mut items = Vec::new();
        for (k, item) in seq.try_iter().map_err(|e| e.to_string())?.enumerate() {
            let item = item.map_err(|e| e.to_string())?;
            items.push(to_value(&item, format!("{path}[{k}]"), depth + 1)?);
        }
        Ok(Value::Array(items))
    } else {
        let kind = obj
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default();
        Err(format!(
            "{} is of type {kind}, which JSON cannot hold",
            at(&path)
        ))
    }
}

pub(crate) fn json_to_py<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    json_module(py)?.call_method1("loads", (text,))
}

/// A JSON value as the Python value `json.loads` would give, built directly (no text between).
pub(crate) fn value_to_py<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    use pyo3::types::{PyList, PyNone};
    Ok(match value {
        Value::Null => PyNone::get(py).to_owned().into_any(),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_u64(), n.as_i64()) {
            (Some(u), _) => u.into_pyobject(py)?.into_any(),
            (None, Some(i)) => i.into_pyobject(py)?.into_any(),
            _ => n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(value_to_py(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, value_to_py(py, v)?)?;
            }
            dict.into_any()
        }
    })
}
