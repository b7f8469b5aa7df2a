//! Conversions between Python array-likes and flat `f64` vectors, with errors that name the
//! argument and the shape that was expected.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyAny;

use crate::errors::InvalidArgumentError;

/// A flat row-major copy of an array and its shape.
pub struct Dense {
    /// The values, row-major.
    pub data: Vec<f64>,
    /// The shape.
    pub shape: Vec<usize>,
}

/// Converts any array-like to a float64 array (as `numpy.asarray(x, dtype=float)` would) and
/// copies it out. `make_err` builds the exception for a value that cannot be converted.
pub fn dense(obj: &Bound<'_, PyAny>, name: &str, make_err: fn(String) -> PyErr) -> PyResult<Dense> {
    if obj.is_none() {
        // NumPy would make it a NaN of shape ().
        return Err(make_err(format!(
            "{name} is None; expected an array of numbers"
        )));
    }
    let py = obj.py();
    let np = py.import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj, np.getattr("float64")?))
        .map_err(|e| make_err(format!("{name} is not a numeric array: {e}")))?;
    let arr = np.call_method1("ascontiguousarray", (arr,))?;
    let arr = arr.cast_into::<PyArrayDyn<f64>>()?;
    let ro = arr.readonly();
    Ok(Dense {
        shape: ro.shape().to_vec(),
        data: ro.as_slice()?.to_vec(),
    })
}

impl Dense {
    /// Checks the number of dimensions; `expected` describes the shape, e.g. "(T, M)".
    pub fn expect_ndim(
        &self,
        ndim: usize,
        name: &str,
        expected: &str,
        make_err: fn(String) -> PyErr,
    ) -> PyResult<()> {
        if self.shape.len() == ndim {
            Ok(())
        } else {
            Err(make_err(format!(
                "{name} has shape {}; expected {expected}",
                shape_str(&self.shape)
            )))
        }
    }
}

/// `(2, 3)`-style rendering of a shape.
pub fn shape_str(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Builds a NumPy array of the given shape from row-major data.
pub fn to_numpy<'py>(
    py: Python<'py>,
    data: Vec<f64>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    PyArray1::from_vec(py, data).reshape(shape.to_vec())
}

/// [`to_numpy`], read-only: a copy of a value the caller cannot change through it, so that
/// writing to it fails loudly instead of changing nothing.
pub fn to_numpy_read_only<'py>(
    py: Python<'py>,
    data: Vec<f64>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let array = to_numpy(py, data, shape)?;
    array.getattr("flags")?.setattr("writeable", false)?;
    Ok(array)
}

/// `obj` as an error quotes it, on one line: an array (anything with a dtype and a shape of at
/// least one dimension) by its dtype and shape, anything else by its repr, its whitespace runs
/// made one space and cut after [`SHOWN_CHARS`] characters.
pub fn shown(obj: &Bound<'_, PyAny>) -> String {
    let text = |a: PyResult<Bound<'_, PyAny>>| a.and_then(|x| x.str().map(|s| s.to_string()));
    if let (Ok(dtype), Ok(shape)) = (text(obj.getattr("dtype")), text(obj.getattr("shape"))) {
        if shape != "()" {
            return format!("an array of dtype {dtype} and shape {shape}");
        }
    }
    let repr = obj
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".into());
    let line = repr.split_whitespace().collect::<Vec<_>>().join(" ");
    match line.char_indices().nth(SHOWN_CHARS) {
        Some((cut, _)) => format!("{}...", &line[..cut]),
        None => line,
    }
}

/// The longest repr that [`shown`] quotes whole.
const SHOWN_CHARS: usize = 80;

/// The error for a malformed argument that is not a network parameter.
pub fn arg_err(msg: String) -> PyErr {
    InvalidArgumentError::new_err(msg)
}

/// An integer argument in `T`'s range (e.g. `[0, 2**64)` for `u64`): a negative or too large
/// value is an `InvalidArgumentError` naming the argument, never an `OverflowError`.
pub fn uint<T: TryFrom<i128>>(obj: &Bound<'_, PyAny>, name: &str, max: &str) -> PyResult<T> {
    let what = || shown(obj);
    let is_bool = obj.is_instance_of::<pyo3::types::PyBool>();
    if is_bool || !(obj.is_instance_of::<pyo3::types::PyInt>() || obj.hasattr("__index__")?) {
        return Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "{name} is {}; expected an integer",
            what()
        )));
    }
    obj.extract::<i128>()
        .ok()
        .and_then(|v| T::try_from(v).ok())
        .ok_or_else(|| {
            arg_err(format!(
                "{name} is {}; it must be an integer in {max}",
                what()
            ))
        })
}

/// An integer argument of any size, for parameters with a literal default: the value when it
/// fits in an `i128`, else only its `repr`, so that [`AnyInt::to`] can raise an
/// `InvalidArgumentError` naming the argument where pyo3 would raise `OverflowError`.
/// A value that is not an integer at all (a float, a bool, a string) is kept too, so that
/// [`AnyInt::to`] raises a `TypeError` that names the argument.
#[derive(Clone, Debug)]
pub struct AnyInt {
    value: Option<i128>,
    repr: String,
    integer: bool,
}

impl From<i128> for AnyInt {
    fn from(value: i128) -> Self {
        AnyInt {
            value: Some(value),
            repr: value.to_string(),
            integer: true,
        }
    }
}

impl<'a, 'py> FromPyObject<'a, 'py> for AnyInt {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let is_bool = obj.is_instance_of::<pyo3::types::PyBool>();
        let integer =
            !is_bool && (obj.is_instance_of::<pyo3::types::PyInt>() || obj.hasattr("__index__")?);
        Ok(AnyInt {
            value: if integer {
                obj.extract::<i128>().ok()
            } else {
                None
            },
            repr: shown(&obj),
            integer,
        })
    }
}

impl AnyInt {
    /// The value as `T`, or an `InvalidArgumentError` saying `name` must be an integer in
    /// `range` (e.g. `"[1, 2**64)"`).
    pub fn to<T: TryFrom<i128>>(&self, name: &str, range: &str) -> PyResult<T> {
        let message = format!("{name} is {}; it must be an integer in {range}", self.repr);
        if !self.integer {
            return Err(pyo3::exceptions::PyTypeError::new_err(message));
        }
        self.value
            .and_then(|v| T::try_from(v).ok())
            .ok_or_else(|| arg_err(message))
    }
}

/// A real-number argument, for parameters with a literal default: the value of anything Python
/// takes as a float (an int, a float, a NumPy number), kept with its `repr` so that
/// [`AnyFloat::to`] raises a `TypeError` that names the argument for anything else (a string, a
/// bool), where pyo3 would say only "must be real number".
#[derive(Clone, Debug)]
pub struct AnyFloat {
    value: Option<f64>,
    repr: String,
    /// A number too large for a float (an int of 2**2000), which is no type error.
    overflow: bool,
}

impl From<f64> for AnyFloat {
    fn from(value: f64) -> Self {
        AnyFloat {
            value: Some(value),
            repr: value.to_string(),
            overflow: false,
        }
    }
}

impl<'a, 'py> FromPyObject<'a, 'py> for AnyFloat {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        // A bool, Python's or NumPy's (a scalar or an array of dtype bool), is no number here.
        let dtype_kind = obj
            .getattr("dtype")
            .and_then(|d| d.getattr("kind"))
            .and_then(|k| k.extract::<String>());
        let is_bool =
            obj.is_instance_of::<pyo3::types::PyBool>() || dtype_kind.is_ok_and(|k| k == "b");
        let value = if is_bool {
            None
        } else {
            Some(obj.extract::<f64>())
        };
        let overflow = matches!(&value, Some(Err(e)) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()));
        Ok(AnyFloat {
            value: value.and_then(Result::ok),
            repr: shown(&obj),
            overflow,
        })
    }
}

impl AnyFloat {
    /// The value, or a `TypeError` saying `name` must be a number. (Its range is the caller's
    /// to check.)
    pub fn to(&self, name: &str) -> PyResult<f64> {
        if self.overflow {
            return Err(arg_err(format!(
                "{name} is {}; it must be a finite number",
                self.repr
            )));
        }
        self.value.ok_or_else(|| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "{name} is {}; expected a number",
                self.repr
            ))
        })
    }
}

/// Pairs of integers (e.g. a trial's `(delay, gap)` timings) as `usize`, each checked like
/// [`AnyInt::to`] and named `name[i][j]`.
pub fn pairs(items: &[(AnyInt, AnyInt)], name: &str) -> PyResult<Vec<(usize, usize)>> {
    items
        .iter()
        .enumerate()
        .map(|(i, (a, b))| {
            let range = "[0, 2**64)";
            Ok((
                a.to(&format!("{name}[{i}][0]"), range)?,
                b.to(&format!("{name}[{i}][1]"), range)?,
            ))
        })
        .collect()
}
