//! The sequence-learning task's detailed API for `dnnevo.sequence`: trial timings, one recorded
//! trial, and the success assessment. Results cross as JSON, decoded by the Python wrapper.

use pyo3::prelude::*;
use tasks::sequence::SequenceTask;

use crate::detach::detached;
use crate::errors::IntoPy;
use crate::json::{self, to_json};
use crate::network::PyNetwork;

fn task(params: &str) -> PyResult<SequenceTask> {
    SequenceTask::from_params(&json::params(params)?).py_err()
}

/// The (delay, gap) of every trigger of a trial, as evolution drew them.
#[pyfunction]
pub fn sequence_timings(
    params: &str,
    seed: u64,
    generation: u64,
    trial: usize,
) -> PyResult<Vec<(usize, usize)>> {
    Ok(task(params)?.timings(seed, generation, trial))
}

/// The (delay, gap) of every trigger of fresh trial `trial`, as `sequence_assess` draws them.
#[pyfunction]
pub fn sequence_fresh_timings(
    params: &str,
    seed: u64,
    trial: usize,
) -> PyResult<Vec<(usize, usize)>> {
    Ok(task(params)?.assessment_timings(seed, trial))
}

/// The order in which a generation's trials run (target-major trial numbers; shuffled when they
/// are chained).
#[pyfunction]
pub fn sequence_trial_order(params: &str, seed: u64, generation: u64) -> PyResult<Vec<usize>> {
    Ok(task(params)?.trial_order(seed, generation))
}

/// One trial of `pattern` (e.g. "01") with the given timings, recorded step by step, as JSON.
/// With `reset` false the trial continues from the network's state.
#[pyfunction]
#[pyo3(signature = (params, net, pattern, timing, reset=true))]
pub fn sequence_trial(
    py: Python<'_>,
    params: &str,
    net: &PyNetwork,
    pattern: &str,
    timing: Vec<(usize, usize)>,
    reset: bool,
) -> PyResult<String> {
    let task = task(params)?;
    let net = &net.inner;
    let record = py
        .detach(|| task.run_pattern(net, pattern, &timing, reset))
        .py_err()?;
    Ok(to_json(&record))
}

/// Assesses a network on fresh timings, `trials_per_target` trials per target, as JSON.
/// Releases the GIL; Ctrl-C interrupts.
#[pyfunction]
pub fn sequence_assess(
    py: Python<'_>,
    params: &str,
    net: &PyNetwork,
    trials_per_target: usize,
    seed: u64,
) -> PyResult<String> {
    let task = task(params)?;
    let net = &net.inner;
    let report = detached(py, f64::INFINITY, |cancel| {
        task.assess_cancellable(net, trials_per_target, seed, Some(cancel))
    })?;
    Ok(to_json(&report))
}
