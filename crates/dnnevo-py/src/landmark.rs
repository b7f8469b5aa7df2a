//! The landmark-recognition task's detailed API for `dnnevo.landmark`: a recorded robot trial,
//! the (robot-like) assessment, and the sonar world's ray casts. Results cross as JSON.

use ctrnn::{Purpose, Stream};
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use tasks::landmark::LandmarkTask;

use crate::arrays::AnyInt;
use crate::detach::detached;
use crate::errors::{ConfigError, IntoPy, InvalidArgumentError};
use crate::json::{self, to_json};
use crate::network::PyNetwork;

fn task(params: &str) -> PyResult<LandmarkTask> {
    LandmarkTask::from_params(&json::params(params)?).py_err()
}

/// One fresh trial (`Purpose::Evaluate` stream `trial` of `seed`) with `landmark`, recorded step
/// by step, as JSON.
#[pyfunction]
#[pyo3(signature = (params, net, landmark, seed, trial, robot_like=false))]
pub fn landmark_record(
    py: Python<'_>,
    params: &str,
    net: &PyNetwork,
    landmark: AnyInt,
    seed: AnyInt,
    trial: AnyInt,
    robot_like: bool,
) -> PyResult<String> {
    let landmark: u8 = landmark.to("landmark", "[0, 256)")?;
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let trial: u64 = trial.to("trial", "[0, 2**64)")?;
    let task = task(params)?;
    let net = &net.inner;
    let record = py
        .detach(|| {
            let stream = Stream::new(seed, 0, Purpose::Evaluate, 0, trial);
            task.record(net, task.sense(landmark, stream, robot_like)?)
        })
        .py_err()?;
    Ok(to_json(&record))
}

/// Assesses a network on fresh trials, as JSON. Releases the GIL; Ctrl-C interrupts.
#[pyfunction]
#[pyo3(signature = (params, net, per_landmark, seed, robot_like=false))]
pub fn landmark_assess(
    py: Python<'_>,
    params: &str,
    net: &PyNetwork,
    per_landmark: AnyInt,
    seed: AnyInt,
    robot_like: bool,
) -> PyResult<String> {
    let per_landmark: usize = per_landmark.to("per_landmark", "[0, 2**64)")?;
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let task = task(params)?;
    let net = &net.inner;
    let report = detached(py, f64::INFINITY, |cancel| {
        task.assess_cancellable(net, per_landmark, seed, robot_like, Some(cancel))
    })?;
    Ok(to_json(&report))
}

/// The distance along each ray (rows of `origins` and `directions`, K x 2) to the nearest wall
/// or box of the world `world` (a JSON `WorldSpec`), or `max_distance` when nothing is nearer.
#[pyfunction]
pub fn sim2d_cast_rays<'py>(
    py: Python<'py>,
    world: &str,
    origins: PyReadonlyArray2<'py, f64>,
    directions: PyReadonlyArray2<'py, f64>,
    max_distance: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let spec: sim2d::WorldSpec =
        serde_json::from_str(world).map_err(|e| ConfigError::new_err(format!("world: {e}")))?;
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

/// The default world of landmark `n` (1 or 2), as JSON.
#[pyfunction]
pub fn sim2d_landmark_world(n: u32) -> PyResult<String> {
    let spec =
        sim2d::WorldSpec::landmark(n).map_err(|e| InvalidArgumentError::new_err(e.to_string()))?;
    Ok(to_json(&spec))
}
