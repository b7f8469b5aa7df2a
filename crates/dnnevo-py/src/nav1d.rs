//! The one-dimensional navigation task's detailed API for `dnnevo.nav1d`: trial conditions, a
//! recorded chain of trials, the success assessment and the integrated system. Conditions and
//! results cross as JSON, decoded by the Python wrapper.

use pyo3::prelude::*;
use tasks::nav1d::{Condition, Environment, Nav1dTask, Part, Side, System};

use crate::arrays::AnyInt;
use crate::detach::detached;
use crate::errors::{IntoPy, InvalidArgumentError};
use crate::json::{self, to_json};
use crate::network::PyNetwork;

fn task(params: &str) -> PyResult<Nav1dTask> {
    Nav1dTask::from_params(&json::params(params)?).py_err()
}

fn chain(text: &str) -> PyResult<Vec<Condition>> {
    serde_json::from_str(text)
        .map_err(|e| InvalidArgumentError::new_err(format!("conditions: {e}")))
}

/// The chains of trials evolution ran in `generation`, as JSON.
#[pyfunction]
pub fn nav1d_chains(params: &str, seed: AnyInt, generation: AnyInt) -> PyResult<String> {
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let generation: u64 = generation.to("generation", "[0, 2**64)")?;
    Ok(to_json(&task(params)?.chains(seed, generation)))
}

/// Trials per chain of the task's success check: `trials_per_environment` for a `single` or
/// chained `goal` task, else 1.
#[pyfunction]
pub fn nav1d_chain_len(params: &str) -> PyResult<usize> {
    Ok(task(params)?.chain_len())
}

/// `count` fresh chains of `trials` trials, as JSON.
#[pyfunction]
pub fn nav1d_fresh_chains(
    params: &str,
    count: AnyInt,
    trials: AnyInt,
    seed: AnyInt,
) -> PyResult<String> {
    let count: usize = count.to("count", "[0, 2**64)")?;
    let trials: usize = trials.to("trials", "[0, 2**64)")?;
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    Ok(to_json(&task(params)?.fresh_chains(count, trials, seed)))
}

/// One chain (JSON list of conditions), recorded step by step, as JSON.
#[pyfunction]
#[pyo3(signature = (params, net, conditions, reset=true))]
pub fn nav1d_record(
    py: Python<'_>,
    params: &str,
    net: &PyNetwork,
    conditions: &str,
    reset: bool,
) -> PyResult<String> {
    let task = task(params)?;
    let chain = chain(conditions)?;
    let net = &net.inner;
    let record = py.detach(|| task.record(net, &chain, reset)).py_err()?;
    Ok(to_json(&record))
}

/// Assesses a network on `chains` fresh chains, as JSON. Releases the GIL; Ctrl-C interrupts.
#[pyfunction]
pub fn nav1d_assess(
    py: Python<'_>,
    params: &str,
    net: &PyNetwork,
    chains: AnyInt,
    seed: AnyInt,
) -> PyResult<String> {
    let chains: usize = chains.to("chains", "[0, 2**64)")?;
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let task = task(params)?;
    let net = &net.inner;
    let report = detached(py, f64::INFINITY, |cancel| {
        task.assess_cancellable(net, chains, seed, Some(cancel))
    })?;
    Ok(to_json(&report))
}

/// A subnetwork as Python passes it: its task's JSON parameters and the network.
type PyPart<'py> = (String, PyRef<'py, PyNetwork>);

fn system(parts: [&PyPart<'_>; 3], persist_state: bool) -> PyResult<System> {
    let [c, f, n] = parts.map(|(params, net)| {
        task(params).map(|task| Part {
            task,
            network: net.inner.clone(),
        })
    });
    Ok(System::new(c?, f?, n?)
        .py_err()?
        .persist_state(persist_state))
}

/// Assesses the integrated system on fresh environments, as JSON. Releases the GIL; Ctrl-C
/// interrupts.
#[pyfunction]
#[pyo3(signature = (classifier, far, near, environments, trials, seed, persist_state=true))]
#[allow(clippy::too_many_arguments)]
pub fn nav1d_system_assess(
    py: Python<'_>,
    classifier: PyPart<'_>,
    far: PyPart<'_>,
    near: PyPart<'_>,
    environments: AnyInt,
    trials: AnyInt,
    seed: AnyInt,
    persist_state: bool,
) -> PyResult<String> {
    let environments: usize = environments.to("environments", "[0, 2**64)")?;
    let trials: usize = trials.to("trials", "[0, 2**64)")?;
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let system = system([&classifier, &far, &near], persist_state)?;
    let report = detached(py, f64::INFINITY, |cancel| {
        system.assess_cancellable(environments, trials, seed, Some(cancel))
    })?;
    Ok(to_json(&report))
}

/// One environment of the integrated system, recorded: the classifier's trial, the picked
/// network's trials and the pick, as JSON.
#[pyfunction]
#[pyo3(signature = (classifier, far, near, conditions, persist_state=true))]
pub fn nav1d_system_record(
    py: Python<'_>,
    classifier: PyPart<'_>,
    far: PyPart<'_>,
    near: PyPart<'_>,
    conditions: &str,
    persist_state: bool,
) -> PyResult<String> {
    let system = system([&classifier, &far, &near], persist_state)?;
    let chain = chain(conditions)?;
    let (a, b, chosen) = py.detach(|| system.record(&chain)).py_err()?;
    Ok(to_json(
        &serde_json::json!({"first": a, "rest": b, "chosen": chosen}),
    ))
}

/// A lowercase enum variant, or an error naming `what` and the `allowed` values.
fn variant<T: serde::de::DeserializeOwned>(what: &str, text: &str, allowed: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(text.into())).map_err(|_| {
        InvalidArgumentError::new_err(format!("{what} is {text:?}; expected {allowed}"))
    })
}

/// The trial with the config's exact geometry for `environment` ("far" or "near") and `goal`
/// ("left" or "right"), as JSON.
#[pyfunction]
pub fn nav1d_exact(params: &str, environment: &str, goal: &str) -> PyResult<String> {
    let task = task(params)?;
    let env: Environment = variant("environment", environment, "\"far\" or \"near\"")?;
    let side: Side = variant("goal", goal, "\"left\" or \"right\"")?;
    Ok(to_json(&Condition::exact(task.config(), env, side)))
}
