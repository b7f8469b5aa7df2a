//! Dynamical analysis for `dnnevo.analysis`: equilibria, limit cycles and bifurcation sweeps of a
//! network under a constant input. Results cross as JSON, decoded into dataclasses by the Python
//! wrapper. Each call runs with the GIL released and stops on Ctrl-C.

use ctrnn::analysis::{self, CycleSearch, EquilibriumSearch, Sweep};
use pyo3::prelude::*;

use crate::arrays::arg_err;
use crate::detach::detached;
use crate::json::to_json;
use crate::network::PyNetwork;

/// A count argument as `usize`, or `InvalidArgumentError` naming it.
fn count(name: &str, value: i64, min: i64) -> PyResult<usize> {
    if value < min {
        return Err(arg_err(format!("{name} is {value}; it must be >= {min}")));
    }
    Ok(value as usize)
}

fn seed(value: i64) -> PyResult<u64> {
    u64::try_from(value).map_err(|_| arg_err(format!("seed is {value}; it must be >= 0")))
}

/// Every equilibrium Newton's method reaches, with eigenvalues and stability, as JSON.
#[pyfunction]
#[pyo3(signature = (net, input, *, starts=512, tolerance=1e-10, distinct=1e-6, max_iterations=100, seed=0))]
#[allow(clippy::too_many_arguments)]
pub fn analysis_equilibria(
    py: Python<'_>,
    net: &PyNetwork,
    input: Vec<f64>,
    starts: i64,
    tolerance: f64,
    distinct: f64,
    max_iterations: i64,
    seed: i64,
) -> PyResult<String> {
    let settings = EquilibriumSearch {
        starts: count("starts", starts, 1)?,
        tolerance,
        distinct,
        max_iterations: count("max_iterations", max_iterations, 1)?,
        seed: self::seed(seed)?,
    };
    let n = net.inner.size() as f64;
    let cost = settings.starts as f64 * settings.max_iterations as f64 * n * n * n;
    let net = &net.inner;
    let found = detached(py, cost, |_| analysis::equilibria(net, &input, &settings))?;
    Ok(to_json(&found))
}

/// The attracting limit cycles reached from the search's starts, as JSON.
#[pyfunction]
#[pyo3(signature = (net, input, *, starts=8, steps_per_tau=20, transient=100.0, window=100.0, at_rest=1e-6, tolerance=1e-5, orbit_points=200, seed=1))]
#[allow(clippy::too_many_arguments)]
pub fn analysis_cycles(
    py: Python<'_>,
    net: &PyNetwork,
    input: Vec<f64>,
    starts: i64,
    steps_per_tau: i64,
    transient: f64,
    window: f64,
    at_rest: f64,
    tolerance: f64,
    orbit_points: i64,
    seed: i64,
) -> PyResult<String> {
    let settings = CycleSearch {
        starts: count("starts", starts, 1)?,
        steps_per_tau: count("steps_per_tau", steps_per_tau, 1)?,
        transient,
        window,
        at_rest,
        tolerance,
        orbit_points: count("orbit_points", orbit_points, 2)?,
        seed: self::seed(seed)?,
    };
    let net = &net.inner;
    let found = detached(py, f64::INFINITY, |cancel| {
        analysis::limit_cycles(net, &input, &settings, Some(cancel))
    })?;
    Ok(to_json(&found))
}

/// A sweep of input `index` from `start` to `stop` with the others held at `input`, as JSON;
/// with `cycle_starts > 0` it also searches for limit cycles at each value from that many starts.
#[pyfunction]
#[pyo3(signature = (net, input, index, start, stop, *, steps=101, starts=128, tolerance=1e-10, distinct=1e-6, max_iterations=100, seed=0, cycle_starts=0))]
#[allow(clippy::too_many_arguments)]
pub fn analysis_bifurcation(
    py: Python<'_>,
    net: &PyNetwork,
    input: Vec<f64>,
    index: i64,
    start: f64,
    stop: f64,
    steps: i64,
    starts: i64,
    tolerance: f64,
    distinct: f64,
    max_iterations: i64,
    seed: i64,
    cycle_starts: i64,
) -> PyResult<String> {
    let cycle_starts = count("cycle_starts", cycle_starts, 0)?;
    let sweep = Sweep {
        input: count("index", index, 0)?,
        from: start,
        to: stop,
        steps: count("steps", steps, 2)?,
        search: EquilibriumSearch {
            starts: count("starts", starts, 1)?,
            tolerance,
            distinct,
            max_iterations: count("max_iterations", max_iterations, 1)?,
            seed: self::seed(seed)?,
        },
        cycles: (cycle_starts > 0).then(|| CycleSearch {
            starts: cycle_starts,
            ..CycleSearch::default()
        }),
    };
    let net = &net.inner;
    let found = detached(py, f64::INFINITY, |cancel| {
        analysis::bifurcation(net, &input, &sweep, Some(cancel))
    })?;
    Ok(to_json(&found))
}
