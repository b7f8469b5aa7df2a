//! Dynamical analysis for `dnnevo.analysis`: equilibria, limit cycles and bifurcation sweeps of a
//! network under a constant input. Results cross as the typed objects of `dynamics.rs`. Each call
//! runs with the GIL released and stops on Ctrl-C.

use ctrnn::analysis::{self, CycleSearch, EquilibriumSearch, Sweep};
use pyo3::prelude::*;

use crate::arrays::{arg_err, AnyFloat, AnyInt};
use crate::detach::detached;
use crate::dynamics::{PyBifurcation, PyCycle, PyEquilibrium};
use crate::network::PyNetwork;

/// A count argument in `[min, MAX_COUNT]` as `usize`, or `InvalidArgumentError` naming it.
fn count(name: &str, value: &AnyInt, min: usize) -> PyResult<usize> {
    let range = format!("[{min}, {}]", tasks::MAX_COUNT);
    let n: usize = value.to(name, &range)?;
    if !(min..=tasks::MAX_COUNT).contains(&n) {
        return Err(arg_err(format!(
            "{name} is {n}; it must be an integer in {range}"
        )));
    }
    Ok(n)
}

fn seed(value: &AnyInt) -> PyResult<u64> {
    value.to("seed", "[0, 2**64)")
}

/// `retry_starts`, or the core's default ([`analysis::RETRY_STARTS`]) when None; 0 never retries.
fn retry(value: Option<&AnyInt>) -> PyResult<usize> {
    match value {
        None => Ok(EquilibriumSearch::default().retry_starts),
        Some(v) => count("retry_starts", v, 0),
    }
}

/// Every equilibrium Newton's method reaches, with eigenvalues and stability, as `Equilibrium` objects; searched
/// again with `retry_starts` starts (None: the core's default) when the count is even.
#[pyfunction]
#[pyo3(signature = (net, input, *, starts=AnyInt::from(512), tolerance=AnyFloat::from(1e-10), distinct=AnyFloat::from(1e-6), max_iterations=AnyInt::from(100), seed=AnyInt::from(0), retry_starts=None), text_signature = "(net, input, *, starts=512, tolerance=1e-10, distinct=1e-6, max_iterations=100, seed=0, retry_starts=None)")]
#[allow(clippy::too_many_arguments)]
pub fn analysis_equilibria<'py>(
    py: Python<'py>,
    net: &PyNetwork,
    input: Vec<f64>,
    starts: AnyInt,
    tolerance: AnyFloat,
    distinct: AnyFloat,
    max_iterations: AnyInt,
    seed: AnyInt,
    retry_starts: Option<AnyInt>,
) -> PyResult<Vec<PyEquilibrium>> {
    let settings = EquilibriumSearch {
        starts: count("starts", &starts, 1)?,
        tolerance: tolerance.to("tolerance")?,
        distinct: distinct.to("distinct")?,
        max_iterations: count("max_iterations", &max_iterations, 1)?,
        seed: self::seed(&seed)?,
        retry_starts: retry(retry_starts.as_ref())?,
    };
    let n = net.inner.size() as f64;
    let starts = settings.starts + settings.retry_starts;
    let cost = starts as f64 * settings.max_iterations as f64 * n * n * n;
    let net = &net.inner;
    let found = detached(py, cost, |cancel| {
        analysis::equilibria_cancellable(net, &input, &settings, Some(cancel))
    })?;
    found
        .into_iter()
        .map(|e| PyEquilibrium::new(py, e))
        .collect()
}

/// The attracting limit cycles reached from the search's starts, as `Cycle` objects.
#[pyfunction]
#[pyo3(signature = (net, input, *, starts=AnyInt::from(8), steps_per_tau=AnyInt::from(20), transient=AnyFloat::from(100.0), window=AnyFloat::from(100.0), at_rest=AnyFloat::from(1e-6), tolerance=AnyFloat::from(1e-5), orbit_points=AnyInt::from(200), seed=AnyInt::from(1)), text_signature = "(net, input, *, starts=8, steps_per_tau=20, transient=100.0, window=100.0, at_rest=1e-6, tolerance=1e-5, orbit_points=200, seed=1)")]
#[allow(clippy::too_many_arguments)]
pub fn analysis_cycles<'py>(
    py: Python<'py>,
    net: &PyNetwork,
    input: Vec<f64>,
    starts: AnyInt,
    steps_per_tau: AnyInt,
    transient: AnyFloat,
    window: AnyFloat,
    at_rest: AnyFloat,
    tolerance: AnyFloat,
    orbit_points: AnyInt,
    seed: AnyInt,
) -> PyResult<Vec<PyCycle>> {
    let settings = CycleSearch {
        starts: count("starts", &starts, 1)?,
        steps_per_tau: count("steps_per_tau", &steps_per_tau, 1)?,
        transient: transient.to("transient")?,
        window: window.to("window")?,
        at_rest: at_rest.to("at_rest")?,
        tolerance: tolerance.to("tolerance")?,
        orbit_points: count("orbit_points", &orbit_points, 2)?,
        seed: self::seed(&seed)?,
    };
    let net = &net.inner;
    let found = detached(py, f64::INFINITY, |cancel| {
        analysis::limit_cycles(net, &input, &settings, Some(cancel))
    })?;
    found.into_iter().map(|c| PyCycle::new(py, c)).collect()
}

/// A sweep of input `index` from `start` to `stop` with the others held at `input`, as a `Bifurcation`;
/// with `cycle_starts > 0` it also searches for limit cycles at each value from that many starts
/// and follows them as branches. `retry_starts` as for `analysis_equilibria`.
#[pyfunction]
#[pyo3(signature = (net, input, index, start, stop, *, steps=AnyInt::from(101), starts=AnyInt::from(128), tolerance=AnyFloat::from(1e-10), distinct=AnyFloat::from(1e-6), max_iterations=AnyInt::from(100), seed=AnyInt::from(0), cycle_starts=AnyInt::from(0), retry_starts=None), text_signature = "(net, input, index, start, stop, *, steps=101, starts=128, tolerance=1e-10, distinct=1e-6, max_iterations=100, seed=0, cycle_starts=0, retry_starts=None)")]
#[allow(clippy::too_many_arguments)]
pub fn analysis_bifurcation<'py>(
    py: Python<'py>,
    net: &PyNetwork,
    input: Vec<f64>,
    index: AnyInt,
    start: AnyFloat,
    stop: AnyFloat,
    steps: AnyInt,
    starts: AnyInt,
    tolerance: AnyFloat,
    distinct: AnyFloat,
    max_iterations: AnyInt,
    seed: AnyInt,
    cycle_starts: AnyInt,
    retry_starts: Option<AnyInt>,
) -> PyResult<PyBifurcation> {
    let cycle_starts = count("cycle_starts", &cycle_starts, 0)?;
    let sweep = Sweep {
        input: count("index", &index, 0)?,
        from: start.to("start")?,
        to: stop.to("stop")?,
        steps: count("steps", &steps, 2)?,
        search: EquilibriumSearch {
            starts: count("starts", &starts, 1)?,
            tolerance: tolerance.to("tolerance")?,
            distinct: distinct.to("distinct")?,
            max_iterations: count("max_iterations", &max_iterations, 1)?,
            seed: self::seed(&seed)?,
            retry_starts: retry(retry_starts.as_ref())?,
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
    PyBifurcation::new(py, found, input)
}
