//! The sequence-learning task's detailed API for `dnnevo.sequence`: trial timings, one recorded
//! trial, and the success assessment. Results cross as JSON, decoded by the Python wrapper.

use pyo3::prelude::*;
use tasks::sequence::SequenceTask;

use crate::arrays::{pairs, AnyInt};
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
    seed: AnyInt,
    generation: AnyInt,
    trial: AnyInt,
) -> PyResult<Vec<(usize, usize)>> {
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let generation: u64 = generation.to("generation", "[0, 2**64)")?;
    let trial: usize = trial.to("trial", "[0, 2**64)")?;
    Ok(task(params)?.timings(seed, generation, trial))
}

/// The (delay, gap) of every trigger of fresh trial `trial`, as `sequence_assess` draws them.
#[pyfunction]
pub fn sequence_fresh_timings(
    params: &str,
    seed: AnyInt,
    trial: AnyInt,
) -> PyResult<Vec<(usize, usize)>> {
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let trial: usize = trial.to("trial", "[0, 2**64)")?;
    Ok(task(params)?.assessment_timings(seed, trial))
}

/// The order in which a generation's trials run (target-major trial numbers; shuffled when they
/// are chained).
#[pyfunction]
pub fn sequence_trial_order(
    params: &str,
    seed: AnyInt,
    generation: AnyInt,
) -> PyResult<Vec<usize>> {
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let generation: u64 = generation.to("generation", "[0, 2**64)")?;
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
    timing: Vec<(AnyInt, AnyInt)>,
    reset: bool,
) -> PyResult<String> {
    let timing = pairs(&timing, "timing")?;
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
    trials_per_target: AnyInt,
    seed: AnyInt,
) -> PyResult<String> {
    let trials_per_target: usize = trials_per_target.to("trials_per_target", "[0, 2**64)")?;
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let task = task(params)?;
    let net = &net.inner;
    let report = detached(py, f64::INFINITY, |cancel| {
        task.assess_cancellable(net, trials_per_target, seed, Some(cancel))
    })?;
    Ok(to_json(&report))
}
