//! `dnnevo._core.Nav1dTask`, the one-dimensional navigation task built once from a run's
//! settings (`RunConfig.builtin()`): trial conditions, a recorded chain of trials, the success
//! assessment; and the integrated system of three such networks. Conditions and records are
//! typed objects (`Nav1dCondition`, `Nav1dRecord`), reports Python values.

use numpy::{PyArray1, PyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use tasks::nav1d::{Condition, Environment, Nav1dTask, Part, Record, Side, System};
use tasks::RunConfig;

use crate::arrays::AnyInt;
use crate::detach::detached;
use crate::errors::{IntoPy, InvalidArgumentError};
use crate::json::to_py;
use crate::network::PyNetwork;
use crate::records::{flags, integers, matrix, vector};

/// The one-dimensional navigation task of a run's settings. Made by `RunConfig.builtin()`.
#[pyclass(module = "dnnevo._core", name = "Nav1dTask", frozen)]
pub struct PyNav1dTask {
    inner: Nav1dTask,
}

impl PyNav1dTask {
    /// The task a run config names; an error in its `task_params` is named as the config
    /// names it.
    pub(crate) fn from_run(run: &RunConfig) -> PyResult<Self> {
        Ok(PyNav1dTask {
            inner: run.with_task_params(Nav1dTask::from_params).py_err()?,
        })
    }
}

/// A chain of conditions as the core's.
fn chain(conditions: &[PyRef<'_, PyNav1dCondition>]) -> Vec<Condition> {
    conditions.iter().map(|c| c.inner).collect()
}

/// A lowercase enum variant's name, as serde writes it.
fn name<T: serde::Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(s)) => s,
        _ => unreachable!("the task's enums serialise as lowercase names"),
    }
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
        crate::layout::layout(&self.inner)
    }

    /// Trials per chain of the task's success check: `trials_per_environment` for a `single`
    /// or chained `goal` task, else 1.
    #[getter]
    fn chain_len(&self) -> usize {
        self.inner.chain_len()
    }

    /// The chains of trials evolution ran in `generation`.
    fn chains(&self, seed: AnyInt, generation: AnyInt) -> PyResult<Vec<Vec<PyNav1dCondition>>> {
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let generation: u64 = generation.to("generation", "[0, 2**64)")?;
        Ok(conditions(self.inner.chains(seed, generation)))
    }

    /// `count` fresh chains of `trials` trials.
    fn fresh_chains(
        &self,
        count: AnyInt,
        trials: AnyInt,
        seed: AnyInt,
    ) -> PyResult<Vec<Vec<PyNav1dCondition>>> {
        let count: usize = count.to("count", "[0, 2**64)")?;
        let trials: usize = trials.to("trials", "[0, 2**64)")?;
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        Ok(conditions(self.inner.fresh_chains(count, trials, seed)))
    }

    /// The trial with the config's exact geometry for `environment` ("far" or "near") and
    /// `goal` ("left" or "right").
    fn exact(&self, environment: &str, goal: &str) -> PyResult<PyNav1dCondition> {
        let env: Environment = variant("environment", environment, "\"far\" or \"near\"")?;
        let side: Side = variant("goal", goal, "\"left\" or \"right\"")?;
        Ok(PyNav1dCondition {
            inner: Condition::exact(self.inner.config(), env, side),
        })
    }

    /// One chain of trials, recorded step by step; with `reset` false it starts from the
    /// network's state.
    #[pyo3(signature = (net, conditions, reset=true))]
    fn record(
        &self,
        py: Python<'_>,
        net: &PyNetwork,
        conditions: Vec<PyRef<'_, PyNav1dCondition>>,
        reset: bool,
    ) -> PyResult<PyNav1dRecord> {
        let chain = chain(&conditions);
        let (task, net) = (&self.inner, &net.inner);
        let record = py.detach(|| task.record(net, &chain, reset)).py_err()?;
        PyNav1dRecord::new(py, record)
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
/// network's trials, and the pick ("far" or "near").
#[pyfunction]
#[pyo3(signature = (classifier, far, near, conditions, persist_state=true))]
pub fn nav1d_system_record<'py>(
    py: Python<'py>,
    classifier: PyPart<'py>,
    far: PyPart<'py>,
    near: PyPart<'py>,
    conditions: Vec<PyRef<'py, PyNav1dCondition>>,
    persist_state: bool,
) -> PyResult<(PyNav1dRecord, PyNav1dRecord, String)> {
    let system = system([&classifier, &far, &near], persist_state)?;
    let chain = chain(&conditions);
    let (a, b, chosen) = py.detach(|| system.record(&chain)).py_err()?;
    Ok((
        PyNav1dRecord::new(py, a)?,
        PyNav1dRecord::new(py, b)?,
        name(&chosen),
    ))
}

fn conditions(chains: Vec<Vec<Condition>>) -> Vec<Vec<PyNav1dCondition>> {
    chains
        .into_iter()
        .map(|c| {
            c.into_iter()
                .map(|inner| PyNav1dCondition { inner })
                .collect()
        })
        .collect()
}

/// One trial's world: environment "far" or "near", goal "left" or "right", the agent's start
/// and the landmark's centre.
#[pyclass(module = "dnnevo._core", name = "Nav1dCondition", frozen, eq)]
#[derive(Clone, PartialEq)]
pub struct PyNav1dCondition {
    inner: Condition,
}

#[pymethods]
impl PyNav1dCondition {
    #[new]
    fn new(environment: &str, goal: &str, start: f64, landmark: f64) -> PyResult<Self> {
        for (what, value) in [("start", start), ("landmark", landmark)] {
            if !value.is_finite() {
                return Err(InvalidArgumentError::new_err(format!(
                    "{what} is {value}; it must be a finite number"
                )));
            }
        }
        Ok(PyNav1dCondition {
            inner: Condition {
                environment: variant("environment", environment, "\"far\" or \"near\"")?,
                goal: variant("goal", goal, "\"left\" or \"right\"")?,
                start,
                landmark,
            },
        })
    }

    /// "far" or "near": where the landmark is relative to the goal.
    #[getter]
    fn environment(&self) -> String {
        name(&self.inner.environment)
    }
    /// "left" or "right": the goal's end.
    #[getter]
    fn goal(&self) -> String {
        name(&self.inner.goal)
    }
    /// The agent's start position.
    #[getter]
    fn start(&self) -> f64 {
        self.inner.start
    }
    /// The landmark's centre.
    #[getter]
    fn landmark(&self) -> f64 {
        self.inner.landmark
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        // Equal conditions hash alike: -0.0 == 0.0, so both hash as 0.0.
        let bits = |v: f64| (v + 0.0).to_bits();
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (
            self.environment(),
            self.goal(),
            bits(self.inner.start),
            bits(self.inner.landmark),
        )
            .hash(&mut h);
        h.finish()
    }

    fn __repr__(&self) -> String {
        format!(
            "Nav1dCondition(environment={:?}, goal={:?}, start={:?}, landmark={:?})",
            self.environment(),
            self.goal(),
            self.inner.start,
            self.inner.landmark
        )
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let c = slf.get();
        let args =
            (c.environment(), c.goal(), c.inner.start, c.inner.landmark).into_pyobject(py)?;
        PyTuple::new(py, [slf.get_type().into_any(), args.into_any()])
    }
}

/// A chain of trials, time step by time step: arrays of length T (`outputs` is (T, N)), and per
/// trial `conditions`, `reached` and `classification` (the classifier's output at the trial's
/// end, NaN for a network without one).
#[pyclass(module = "dnnevo._core", name = "Nav1dRecord", frozen)]
pub struct PyNav1dRecord {
    /// Each trial's world.
    #[pyo3(get)]
    conditions: Vec<Py<PyNav1dCondition>>,
    /// The agent's position after each time step.
    #[pyo3(get)]
    x: Py<PyArrayDyn<f64>>,
    /// The landmark input during each time step (the fraction of its integration steps that
    /// read 1).
    #[pyo3(get)]
    landmark: Py<PyArrayDyn<f64>>,
    /// The reinforcement input during each time step.
    #[pyo3(get)]
    reinforcement: Py<PyArrayDyn<f64>>,
    /// Every neuron's firing rate after each time step, (T, N).
    #[pyo3(get)]
    outputs: Py<PyArrayDyn<f64>>,
    /// The trial each time step belongs to.
    #[pyo3(get)]
    trial: Py<PyArray1<i64>>,
    /// Whether the agent was moving (false during the reinforcement period).
    #[pyo3(get)]
    moving: Py<PyArray1<bool>>,
    /// Whether each trial reached the goal.
    #[pyo3(get)]
    reached: Vec<bool>,
    /// The classifier's output at the end of each trial.
    #[pyo3(get)]
    classification: Vec<f64>,
    /// The state after the last time step.
    #[pyo3(get)]
    final_state: Py<PyArrayDyn<f64>>,
}

impl PyNav1dRecord {
    fn new(py: Python<'_>, record: Record) -> PyResult<Self> {
        let size = record.final_state.len();
        Ok(PyNav1dRecord {
            conditions: record
                .conditions
                .into_iter()
                .map(|inner| Py::new(py, PyNav1dCondition { inner }))
                .collect::<PyResult<_>>()?,
            x: vector(py, record.x)?,
            landmark: vector(py, record.landmark)?,
            reinforcement: vector(py, record.reinforcement)?,
            outputs: matrix(py, record.outputs, size)?,
            trial: integers(py, &record.trial)?,
            moving: flags(py, record.moving)?,
            reached: record.reached,
            classification: record.classification,
            final_state: vector(py, record.final_state)?,
        })
    }
}

#[pymethods]
impl PyNav1dRecord {
    fn __repr__(&self) -> String {
        format!(
            "Nav1dRecord(trials={}, reached={:?})",
            self.conditions.len(),
            self.reached
        )
    }
}
