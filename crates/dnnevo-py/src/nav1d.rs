//! `dnnevo._core.Nav1dTask`, the one-dimensional navigation task built once from a run's
//! settings (`RunConfig.builtin()`): trial conditions, a recorded chain of trials, the success
//! assessment; and the integrated system of three such networks. Conditions cross as dicts,
//! results as Python values.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use tasks::nav1d::{Condition, Environment, Nav1dTask, Part, Side, System};

use crate::arrays::AnyInt;
use crate::detach::detached;
use crate::errors::{IntoPy, InvalidArgumentError};
use crate::json::to_py;
use crate::network::PyNetwork;
use crate::pyjson::dict_to_map;

/// The one-dimensional navigation task of a run's settings. Made by `RunConfig.builtin()`.
#[pyclass(module = "dnnevo._core", name = "Nav1dTask", frozen)]
pub struct PyNav1dTask {
    inner: Nav1dTask,
}

impl PyNav1dTask {
    pub(crate) fn from_params(params: &serde_json::Value) -> PyResult<Self> {
        Ok(PyNav1dTask {
            inner: Nav1dTask::from_params(params).py_err()?,
        })
    }
}

/// A chain of conditions from Python dicts (`environment`, `goal`, `start`, `landmark`).
fn chain(conditions: &[Bound<'_, PyDict>]) -> PyResult<Vec<Condition>> {
    conditions
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let map = dict_to_map(c.as_any(), &format!("conditions[{k}]"))?;
            serde_json::from_value(serde_json::Value::Object(map))
                .map_err(|e| InvalidArgumentError::new_err(format!("conditions[{k}]: {e}")))
        })
        .collect()
}

/// A lowercase enum variant, or an error naming `what` and the `allowed` values.
fn variant<T: serde::de::DeserializeOwned>(what: &str, text: &str, allowed: &str) -> PyResult<T> {
    serde_json::from_value(serde_json::Value::String(text.into())).map_err(|_| {
        InvalidArgumentError::new_err(format!("{what} is {text:?}; expected {allowed}"))
    })
}

#[pymethods]
impl PyNav1dTask {
    /// The task's settings, every default filled in, as a dict.
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.inner.config())
    }

    /// (size, n_inputs) of the networks the task drives.
    #[getter]
    fn layout(&self) -> (usize, usize) {
        use ctrnn::Task;
        let layout = self.inner.layout();
        (layout.size, layout.n_inputs)
    }

    /// Trials per chain of the task's success check: `trials_per_environment` for a `single`
    /// or chained `goal` task, else 1.
    #[getter]
    fn chain_len(&self) -> usize {
        self.inner.chain_len()
    }

    /// The chains of trials evolution ran in `generation`, as lists of condition dicts.
    fn chains<'py>(
        &self,
        py: Python<'py>,
        seed: AnyInt,
        generation: AnyInt,
    ) -> PyResult<Bound<'py, PyAny>> {
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let generation: u64 = generation.to("generation", "[0, 2**64)")?;
        to_py(py, &self.inner.chains(seed, generation))
    }

    /// `count` fresh chains of `trials` trials, as lists of condition dicts.
    fn fresh_chains<'py>(
        &self,
        py: Python<'py>,
        count: AnyInt,
        trials: AnyInt,
        seed: AnyInt,
    ) -> PyResult<Bound<'py, PyAny>> {
        let count: usize = count.to("count", "[0, 2**64)")?;
        let trials: usize = trials.to("trials", "[0, 2**64)")?;
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        to_py(py, &self.inner.fresh_chains(count, trials, seed))
    }

    /// The trial with the config's exact geometry for `environment` ("far" or "near") and
    /// `goal` ("left" or "right"), as a condition dict.
    fn exact<'py>(
        &self,
        py: Python<'py>,
        environment: &str,
        goal: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let env: Environment = variant("environment", environment, "\"far\" or \"near\"")?;
        let side: Side = variant("goal", goal, "\"left\" or \"right\"")?;
        to_py(py, &Condition::exact(self.inner.config(), env, side))
    }

    /// One chain (a list of condition dicts), recorded step by step, as a dict.
    #[pyo3(signature = (net, conditions, reset=true))]
    fn record<'py>(
        &self,
        py: Python<'py>,
        net: &PyNetwork,
        conditions: Vec<Bound<'py, PyDict>>,
        reset: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let chain = chain(&conditions)?;
        let (task, net) = (&self.inner, &net.inner);
        let record = py.detach(|| task.record(net, &chain, reset)).py_err()?;
        to_py(py, &record)
    }

    /// Assesses a network on `chains` fresh chains, as a dict. Releases the GIL; Ctrl-C
    /// interrupts.
    fn assess<'py>(
        &self,
        py: Python<'py>,
        net: &PyNetwork,
        chains: AnyInt,
        seed: AnyInt,
    ) -> PyResult<Bound<'py, PyAny>> {
        let chains: usize = chains.to("chains", "[0, 2**64)")?;
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let (task, net) = (&self.inner, &net.inner);
        let report = detached(py, f64::INFINITY, |cancel| {
            task.assess_cancellable(net, chains, seed, Some(cancel))
        })?;
        to_py(py, &report)
    }
}

/// A subnetwork as Python passes it: the task it was evolved on and the network.
type PyPart<'py> = (PyRef<'py, PyNav1dTask>, PyRef<'py, PyNetwork>);

fn system(parts: [&PyPart<'_>; 3], persist_state: bool) -> PyResult<System> {
    let [c, f, n] = parts.map(|(task, net)| Part {
        task: task.inner.clone(),
        network: net.inner.clone(),
    });
    Ok(System::new(c, f, n).py_err()?.persist_state(persist_state))
}

/// Assesses the integrated system on fresh environments, as a dict. Releases the GIL; Ctrl-C
/// interrupts.
#[pyfunction]
#[pyo3(signature = (classifier, far, near, environments, trials, seed, persist_state=true))]
#[allow(clippy::too_many_arguments)]
pub fn nav1d_system_assess<'py>(
    py: Python<'py>,
    classifier: PyPart<'py>,
    far: PyPart<'py>,
    near: PyPart<'py>,
    environments: AnyInt,
    trials: AnyInt,
    seed: AnyInt,
    persist_state: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let environments: usize = environments.to("environments", "[0, 2**64)")?;
    let trials: usize = trials.to("trials", "[0, 2**64)")?;
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let system = system([&classifier, &far, &near], persist_state)?;
    let report = detached(py, f64::INFINITY, |cancel| {
        system.assess_cancellable(environments, trials, seed, Some(cancel))
    })?;
    to_py(py, &report)
}

/// One environment of the integrated system, recorded: the classifier's trial, the picked
/// network's trials and the pick, as a dict.
#[pyfunction]
#[pyo3(signature = (classifier, far, near, conditions, persist_state=true))]
pub fn nav1d_system_record<'py>(
    py: Python<'py>,
    classifier: PyPart<'py>,
    far: PyPart<'py>,
    near: PyPart<'py>,
    conditions: Vec<Bound<'py, PyDict>>,
    persist_state: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let system = system([&classifier, &far, &near], persist_state)?;
    let chain = chain(&conditions)?;
    let (a, b, chosen) = py.detach(|| system.record(&chain)).py_err()?;
    to_py(
        py,
        &serde_json::json!({"first": a, "rest": b, "chosen": chosen}),
    )
}
