//! `dnnevo._core.RunConfig`: a run's settings, parsed and validated once, in Rust, and held by
//! Python (`EvolutionConfig.native`); and the built-in task they name, built once on first use.

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyTuple;
use tasks::RunConfig;

use crate::errors::{ConfigError, IntoPy};
use crate::landmark::PyLandmarkTask;
use crate::nav1d::PyNav1dTask;
use crate::sequence::PySequenceTask;

/// A run's settings (`EvolutionConfig.to_dict()` as JSON), checked once when made: every
/// value's rule lives in `tasks::RunConfig::validate`, and a problem is a `ConfigError` that
/// names its field. `Evolution`, `evaluate` and the task objects take this, never text.
#[pyclass(module = "dnnevo._core", name = "RunConfig", frozen)]
pub struct PyRunConfig {
    pub(crate) run: RunConfig,
    /// The built-in task object, built by the first `builtin()` and kept.
    builtin: PyOnceLock<Py<PyAny>>,
}

#[pymethods]
impl PyRunConfig {
    /// Parses and validates `config`, JSON text of `EvolutionConfig.to_dict()`.
    #[new]
    fn new(config: &str) -> PyResult<Self> {
        let run = RunConfig::from_json(config).py_err()?;
        Ok(PyRunConfig {
            run,
            builtin: PyOnceLock::new(),
        })
    }

    /// The task's name.
    #[getter]
    fn task(&self) -> &str {
        &self.run.task
    }

    /// The config as JSON text, every default filled in.
    fn to_json(&self) -> String {
        serde_json::to_string(&self.run).expect("settings always serialise")
    }

    /// The built-in task this config names, built once: a `SequenceTask`, `Nav1dTask` or
    /// `LandmarkTask`. A name that is not a built-in task is a `ConfigError`.
    fn builtin(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        self.builtin
            .get_or_try_init(py, || build(py, &self.run))
            .map(|task| task.clone_ref(py))
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let args = PyTuple::new(py, [slf.get().to_json()])?;
        PyTuple::new(py, [slf.get_type().into_any(), args.into_any()])
    }

    fn __repr__(&self) -> String {
        format!("RunConfig({})", self.to_json())
    }
}

/// The task object for `run.task`.
fn build(py: Python<'_>, run: &RunConfig) -> PyResult<Py<PyAny>> {
    Ok(match run.task.as_str() {
        "sequence" => Py::new(py, PySequenceTask::from_run(run)?)?.into_any(),
        "nav1d" => Py::new(py, PyNav1dTask::from_run(run)?)?.into_any(),
        "landmark" => Py::new(py, PyLandmarkTask::from_run(run)?)?.into_any(),
        // The registry's own message names the built-in tasks.
        other => {
            return Err(match run.build_task() {
                Err(e) => crate::errors::to_py(e),
                Ok(_) => {
                    ConfigError::new_err(format!("task {other:?} has no object in the binding"))
                }
            })
        }
    })
}
