//! `dnnevo._core.LandmarkTask`, the landmark-recognition task built once from a run's settings
//! (`RunConfig.builtin()`): a recorded robot trial and the (robot-like) assessment; and the sonar
//! world's ray casts. Results cross as Python values.

use ctrnn::{Purpose, Stream};
use numpy::PyArrayDyn;
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use tasks::landmark::{LandmarkTask, Record};
use tasks::RunConfig;

use crate::arrays::AnyInt;
use crate::detach::detached;
use crate::errors::{ConfigError, IntoPy, InvalidArgumentError};
use crate::json::to_py;
use crate::network::PyNetwork;
use crate::pyjson::dict_to_map;
use crate::records::{matrix, vector};

/// The landmark-recognition task of a run's settings. Made by `RunConfig.builtin()`.
#[pyclass(module = "dnnevo._core", name = "LandmarkTask", frozen)]
pub struct PyLandmarkTask {
    inner: LandmarkTask,
}

impl PyLandmarkTask {
    /// The task a run config names; an error in its `task_params` is named as the config
    /// names it.
    pub(crate) fn from_run(run: &RunConfig) -> PyResult<Self> {
        Ok(PyLandmarkTask {
            inner: run.with_task_params(LandmarkTask::from_params).py_err()?,
        })
    }
}

#[pymethods]
impl PyLandmarkTask {
    /// The task's settings, every default filled in, as a dict.
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.inner.config())
    }

    /// (size, n_inputs) of the networks the task drives.
    #[getter]
    fn layout(&self) -> (usize, usize) {
        crate::layout::layout(&self.inner)
    }

    /// One fresh trial (`Purpose::Evaluate` stream `trial` of `seed`) with `landmark`, recorded
    /// step by step.
    #[pyo3(signature = (net, landmark, seed, trial, robot_like=false))]
    fn record(
        &self,
        py: Python<'_>,
        net: &PyNetwork,
        landmark: AnyInt,
        seed: AnyInt,
        trial: AnyInt,
        robot_like: bool,
    ) -> PyResult<PyLandmarkRecord> {
        let landmark: u8 = landmark.to("landmark", "[0, 256)")?;
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let trial: u64 = trial.to("trial", "[0, 2**64)")?;
        let (task, net) = (&self.inner, &net.inner);
        let record = py
            .detach(|| {
                let stream = Stream::new(seed, 0, Purpose::Evaluate, 0, trial);
                task.record(net, task.sense(landmark, stream, robot_like)?)
            })
            .py_err()?;
        PyLandmarkRecord::new(py, record)
    }

    /// Assesses a network on fresh trials, as a dict. Releases the GIL; Ctrl-C interrupts.
    #[pyo3(signature = (net, per_landmark, seed, robot_like=false))]
    fn assess<'py>(
        &self,
        py: Python<'py>,
        net: &PyNetwork,
        per_landmark: AnyInt,
        seed: AnyInt,
        robot_like: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let per_landmark: usize = per_landmark.to("per_landmark", "[0, 2**64)")?;
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let (task, net) = (&self.inner, &net.inner);
        let report = detached(py, f64::INFINITY, |cancel| {
            task.assess_cancellable(net, per_landmark, seed, robot_like, Some(cancel))
        })?;
        to_py(py, &report)
    }
}

/// One landmark trial, step by step: arrays of length T (`poses` is (T, 3) as x, y, heading;
/// `echoes` (T, 2), NaN where nothing echoed; `outputs` (T, N)), the trial's `world` and the
/// classifier's final output.
#[pyclass(module = "dnnevo._core", name = "LandmarkRecord", frozen)]
pub struct PyLandmarkRecord {
    /// The landmark, 1 or 2.
    #[pyo3(get)]
    landmark: u8,
    /// The trial's world (jittered under robot-like conditions), as a dict.
    #[pyo3(get)]
    world: Py<PyAny>,
    /// The network's input at each step, `min(1, d0 / range)`.
    #[pyo3(get)]
    input: Py<PyArrayDyn<f64>>,
    /// The sonar's range at each step, in metres.
    #[pyo3(get)]
    range: Py<PyArrayDyn<f64>>,
    /// The robot's pose (x, y, heading) at each step, before it moves.
    #[pyo3(get)]
    poses: Py<PyArrayDyn<f64>>,
    /// Where the echo came from at each step (NaN: nothing within range).
    #[pyo3(get)]
    echoes: Py<PyArrayDyn<f64>>,
    /// Every neuron's firing rate after each step, (T, N).
    #[pyo3(get)]
    outputs: Py<PyArrayDyn<f64>>,
    /// The classifier's output at the end: below 0.5 means landmark 1.
    #[pyo3(get)]
    classification: f64,
}

impl PyLandmarkRecord {
    fn new(py: Python<'_>, record: Record) -> PyResult<Self> {
        let s = record.sensing;
        let size = record.outputs.first().map_or(0, Vec::len);
        let echoes: Vec<[f64; 2]> = s
            .echoes
            .iter()
            .map(|e| e.unwrap_or([f64::NAN, f64::NAN]))
            .collect();
        Ok(PyLandmarkRecord {
            landmark: s.landmark,
            world: to_py(py, &s.world)?.unbind(),
            input: vector(py, s.input)?,
            range: vector(py, s.range)?,
            poses: matrix(py, s.poses, 3)?,
            echoes: matrix(py, echoes, 2)?,
            outputs: matrix(py, record.outputs, size)?,
            classification: record.classification,
        })
    }
}

#[pymethods]
impl PyLandmarkRecord {
    fn __repr__(&self) -> String {
        format!(
            "LandmarkRecord(landmark={}, classification={})",
            self.landmark, self.classification
        )
    }
}

/// The distance along each ray (rows of `origins` and `directions`, K x 2) to the nearest wall
/// or box of `world` (a `WorldSpec` as a dict), or `max_distance` when nothing is nearer.
#[pyfunction]
pub fn sim2d_cast_rays<'py>(
    py: Python<'py>,
    world: &Bound<'py, PyDict>,
    origins: PyReadonlyArray2<'py, f64>,
    directions: PyReadonlyArray2<'py, f64>,
    max_distance: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let world = dict_to_map(world.as_any(), "world")
        .map_err(|e| ConfigError::new_err(e.value(py).to_string()))?;
    let spec: sim2d::WorldSpec = serde_json::from_value(serde_json::Value::Object(world))
        .map_err(|e| ConfigError::new_err(format!("world: {e}")))?;
    let world = sim2d::World::new(&spec).map_err(|e| ConfigError::new_err(e.to_string()))?;
    let (o, d) = (origins.as_array(), directions.as_array());
    if o.ncols() != 2 || o.shape() != d.shape() {
        return Err(InvalidArgumentError::new_err(format!(
            "origins has shape {:?} and directions {:?}; both must be (K, 2)",
            o.shape(),
            d.shape()
        )));
    }
    if !(max_distance.is_finite() && max_distance > 0.0) {
        return Err(InvalidArgumentError::new_err(format!(
            "max_distance is {max_distance}; it must be a number > 0"
        )));
    }
    let rays: Vec<([f64; 2], [f64; 2])> = (0..o.nrows())
        .map(|k| ([o[[k, 0]], o[[k, 1]]], [d[[k, 0]], d[[k, 1]]]))
        .collect();
    let out: Vec<f64> = py.detach(|| {
        rays.iter()
            .map(|(o, d)| {
                world
                    .cast_ray(*o, *d, max_distance)
                    .map_or(max_distance, |h| h.distance)
            })
            .collect()
    });
    Ok(PyArray1::from_vec(py, out))
}

/// The default world of landmark `n` (1 or 2), as a dict.
#[pyfunction]
pub fn sim2d_landmark_world(py: Python<'_>, n: u32) -> PyResult<Bound<'_, PyAny>> {
    let spec =
        sim2d::WorldSpec::landmark(n).map_err(|e| InvalidArgumentError::new_err(e.to_string()))?;
    to_py(py, &spec)
}
