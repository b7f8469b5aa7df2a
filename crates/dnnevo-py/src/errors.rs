//! Maps `ctrnn` errors to the Python exception tree defined in `dnnevo/errors.py`.
//!
//! The classes live in Python because some derive from two bases (`DnnevoError` and `ValueError`),
//! which `create_exception!` cannot express.

use pyo3::exceptions::{PyFileNotFoundError, PyKeyboardInterrupt, PyOSError};
use pyo3::{import_exception, PyErr};

import_exception!(dnnevo.errors, DnnevoError);
import_exception!(dnnevo.errors, InvalidNetworkError);
import_exception!(dnnevo.errors, InvalidArgumentError);
import_exception!(dnnevo.errors, FormatError);
import_exception!(dnnevo.errors, ConfigError);
import_exception!(dnnevo.errors, FitnessError);

/// Converts a core error into the matching Python exception.
pub fn to_py(e: ctrnn::Error) -> PyErr {
    use ctrnn::Error as E;
    match e {
        E::InvalidNetwork(m) => InvalidNetworkError::new_err(m),
        E::InvalidArgument(m) => InvalidArgumentError::new_err(m),
        E::Format(m) => FormatError::new_err(m),
        E::Config(m) => ConfigError::new_err(m),
        E::Fitness(m) => FitnessError::new_err(m),
        E::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
        E::Io { context, source } => {
            let msg = format!("{context}: {source}");
            if source.kind() == std::io::ErrorKind::NotFound {
                PyFileNotFoundError::new_err(msg)
            } else {
                PyOSError::new_err(msg)
            }
        }
    }
}

/// `?`-friendly conversion of core results.
pub trait IntoPy<T> {
    /// Converts the error, if any, into a Python exception.
    fn py_err(self) -> pyo3::PyResult<T>;
}

impl<T> IntoPy<T> for ctrnn::Result<T> {
    fn py_err(self) -> pyo3::PyResult<T> {
        self.map_err(to_py)
    }
}
