//! `dnnevo._core.SequenceTask`, the sequence-learning task built once from a run's settings
//! (`RunConfig.builtin()`): trial timings, one recorded trial (`SequenceRecord`), and the success
//! assessment.

use numpy::{PyArray1, PyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use tasks::sequence::{SequenceTask, TrialRecord};
use tasks::RunConfig;

use crate::arrays::{pairs, AnyInt};
use crate::detach::detached;
use crate::errors::IntoPy;
use crate::json::to_py;
use crate::network::PyNetwork;
use crate::records::{flags, integers, matrix, vector};

/// The sequence-learning task of a run's settings. Made by `RunConfig.builtin()`.
#[pyclass(module = "dnnevo._core", name = "SequenceTask", frozen)]
pub struct PySequenceTask {
    inner: SequenceTask,
}

impl PySequenceTask {
    /// The task a run config names; an error in its `task_params` is named as the config
    /// names it.
    pub(crate) fn from_run(run: &RunConfig) -> PyResult<Self> {
        Ok(PySequenceTask {
            inner: run.with_task_params(SequenceTask::from_params).py_err()?,
        })
    }
}

#[pymethods]
impl PySequenceTask {
    /// The task's settings, every default filled in, as a dict.
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.inner.config())
    }

    /// (size, n_inputs) of the networks the task drives.
    #[getter]
    fn layout(&self) -> (usize, usize) {
        crate::layout::layout(&self.inner)
    }

    /// The (delay, gap) of every trigger of a trial, as evolution drew them.
    fn timings(
        &self,
        seed: AnyInt,
        generation: AnyInt,
        trial: AnyInt,
    ) -> PyResult<Vec<(usize, usize)>> {
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let generation: u64 = generation.to("generation", "[0, 2**64)")?;
        let trial: usize = trial.to("trial", "[0, 2**64)")?;
        Ok(self.inner.timings(seed, generation, trial))
    }

    /// The (delay, gap) of every trigger of fresh trial `trial`, as `assess` draws them.
    fn fresh_timings(&self, seed: AnyInt, trial: AnyInt) -> PyResult<Vec<(usize, usize)>> {
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let trial: usize = trial.to("trial", "[0, 2**64)")?;
        Ok(self.inner.assessment_timings(seed, trial))
    }

    /// The order in which a generation's trials run (target-major trial numbers; shuffled when
    /// they are chained).
    fn trial_order(&self, seed: AnyInt, generation: AnyInt) -> PyResult<Vec<usize>> {
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let generation: u64 = generation.to("generation", "[0, 2**64)")?;
        Ok(self.inner.trial_order(seed, generation))
    }

    /// One trial of `pattern` (e.g. "01") with the given timings, recorded step by step. With
    /// `reset` false the trial continues from the network's state.
    #[pyo3(signature = (net, pattern, timing, reset=true))]
    fn trial(
        &self,
        py: Python<'_>,
        net: &PyNetwork,
        pattern: &str,
        timing: Vec<(AnyInt, AnyInt)>,
        reset: bool,
    ) -> PyResult<PySequenceRecord> {
        let timing = pairs(&timing, "timing")?;
        let (task, net) = (&self.inner, &net.inner);
        let record = py
            .detach(|| task.run_pattern(net, pattern, &timing, reset))
            .py_err()?;
        PySequenceRecord::new(py, record)
    }

    /// Assesses a network on fresh timings, `trials_per_target` trials per target: a dict.
    /// Releases the GIL; Ctrl-C interrupts.
    fn assess<'py>(
        &self,
        py: Python<'py>,
        net: &PyNetwork,
        trials_per_target: AnyInt,
        seed: AnyInt,
    ) -> PyResult<Bound<'py, PyAny>> {
        let trials_per_target: usize = trials_per_target.to("trials_per_target", "[0, 2**64)")?;
        let seed: u64 = seed.to("seed", "[0, 2**64)")?;
        let (task, net) = (&self.inner, &net.inner);
        let report = detached(py, f64::INFINITY, |cancel| {
            task.assess_cancellable(net, trials_per_target, seed, Some(cancel))
        })?;
        to_py(py, &report)
    }
}

/// One sequence trial, time step by time step: arrays of length T (`outputs` is (T, N)), and
/// per trigger (`targets`, `r`, `mean_output`, `trigger_correct`).
#[pyclass(module = "dnnevo._core", name = "SequenceRecord", frozen)]
pub struct PySequenceRecord {
    /// The target sequence, such as "01".
    #[pyo3(get)]
    target: String,
    /// Trigger input (input 0) during each time step.
    #[pyo3(get)]
    trigger: Py<PyArrayDyn<f64>>,
    /// Reinforcement input (input 1) during each time step.
    #[pyo3(get)]
    reinforcement: Py<PyArrayDyn<f64>>,
    /// The output neuron's firing rate after each time step.
    #[pyo3(get)]
    output: Py<PyArrayDyn<f64>>,
    /// Every neuron's firing rate after each time step, (T, N).
    #[pyo3(get)]
    outputs: Py<PyArrayDyn<f64>>,
    /// The expected bit of each trigger.
    #[pyo3(get)]
    targets: Py<PyArray1<i64>>,
    /// The reinforcement earned by each trigger.
    #[pyo3(get)]
    r: Py<PyArrayDyn<f64>>,
    /// The mean output over each trigger's window.
    #[pyo3(get)]
    mean_output: Py<PyArrayDyn<f64>>,
    /// Whether each trigger's mean output was on the expected bit's side of 0.5.
    #[pyo3(get)]
    trigger_correct: Py<PyArray1<bool>>,
    /// The state at the end of the trial, to continue from with `reset=False`.
    #[pyo3(get)]
    final_state: Py<PyArrayDyn<f64>>,
}

impl PySequenceRecord {
    fn new(py: Python<'_>, record: TrialRecord) -> PyResult<Self> {
        let size = record.final_state.len();
        Ok(PySequenceRecord {
            target: record.target,
            trigger: vector(py, record.trigger)?,
            reinforcement: vector(py, record.reinforcement)?,
            output: vector(py, record.output)?,
            outputs: matrix(py, record.outputs, size)?,
            targets: integers(py, &record.targets)?,
            r: vector(py, record.r)?,
            mean_output: vector(py, record.mean_output)?,
            trigger_correct: flags(py, record.trigger_correct)?,
            final_state: vector(py, record.final_state)?,
        })
    }
}

#[pymethods]
impl PySequenceRecord {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "SequenceRecord(target={:?}, steps={}, triggers={})",
            self.target,
            self.output.bind(py).len(),
            self.targets.bind(py).len()
        )
    }
}
