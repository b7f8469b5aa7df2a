//! The results of `dnnevo.analysis` as typed objects: `Equilibrium`, `Cycle`, `Event`,
//! `CycleEnd`, `CycleBranch` and `Bifurcation`. Each is built once, in Rust, from the core's own
//! struct (`ctrnn::analysis`), with NumPy arrays for its vectors; `to_dict` gives the struct's
//! serde form. Python adds nothing to them but the `Attractors` pair.

use ctrnn::analysis::{Bifurcation, Cycle, CycleBranch, CycleEnd, Equilibrium, Event, Stability};
use numpy::{Complex64, PyArray1, PyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::{PyComplex, PyDict};
use serde::Serialize;

use crate::json::to_py;
use crate::records::{frozen, matrix, vector};

/// The snake_case name serde gives a unit enum variant, such as "stable_node".
fn name<T: Serialize>(value: &T) -> String {
    match serde_json::to_value(value) {
        Ok(serde_json::Value::String(s)) => s,
        _ => unreachable!("analysis kinds serialise as strings"),
    }
}

/// The stability class names, in the order of [`Stability`].
pub fn stabilities() -> Vec<String> {
    Stability::ALL.iter().map(name).collect()
}

fn complex(py: Python<'_>, pairs: &[[f64; 2]]) -> PyResult<Py<PyArray1<Complex64>>> {
    let z: Vec<Complex64> = pairs
        .iter()
        .map(|&[re, im]| Complex64::new(re, im))
        .collect();
    frozen(py, PyArray1::from_vec(py, z).unbind())
}

/// One equilibrium and its linear stability.
#[pyclass(module = "dnnevo._core", name = "Equilibrium", frozen)]
pub struct PyEquilibrium {
    inner: Equilibrium,
    /// The state v (length N).
    #[pyo3(get)]
    state: Py<PyArrayDyn<f64>>,
    /// The firing rates `f(v - theta)` there.
    #[pyo3(get)]
    outputs: Py<PyArrayDyn<f64>>,
    /// Eigenvalues of the Jacobian of `dv/dt`, largest real part first.
    #[pyo3(get)]
    eigenvalues: Py<PyArray1<Complex64>>,
    /// One of `STABILITIES`.
    #[pyo3(get)]
    stability: String,
}

impl PyEquilibrium {
    pub fn new(py: Python<'_>, e: Equilibrium) -> PyResult<Self> {
        Ok(PyEquilibrium {
            state: vector(py, e.state.clone())?,
            outputs: vector(py, e.outputs.clone())?,
            eigenvalues: complex(py, &e.eigenvalues)?,
            stability: name(&e.stability),
            inner: e,
        })
    }
}

#[pymethods]
impl PyEquilibrium {
    /// How many eigenvalues have a positive real part.
    #[getter]
    fn unstable_dimensions(&self) -> usize {
        self.inner.unstable_dimensions
    }

    /// `1 / min |Re lambda|`: how long the slowest direction takes to approach (or leave) by a
    /// factor e. None when non-hyperbolic.
    #[getter]
    fn time_scale(&self) -> Option<f64> {
        self.inner.time_scale
    }

    /// `max_i tau_i |dv_i/dt|` there (at most the search's tolerance).
    #[getter]
    fn residual(&self) -> f64 {
        self.inner.residual
    }

    /// Whether nearby states approach it (a stable node or focus).
    #[getter]
    fn stable(&self) -> bool {
        matches!(
            self.inner.stability,
            Stability::StableNode | Stability::StableFocus
        )
    }

    /// As plain JSON types (eigenvalues as `[re, im]` pairs).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.inner)
    }

    fn __repr__(&self) -> String {
        format!(
            "Equilibrium(stability={:?}, state={:?})",
            self.stability, self.inner.state
        )
    }
}

/// One attracting limit cycle.
#[pyclass(module = "dnnevo._core", name = "Cycle", frozen)]
pub struct PyCycle {
    inner: Cycle,
    /// Per neuron, max minus min of the state over one period.
    #[pyo3(get)]
    amplitude: Py<PyArrayDyn<f64>>,
    /// Per neuron, the mean firing rate over one period.
    #[pyo3(get)]
    mean_outputs: Py<PyArrayDyn<f64>>,
    /// Per neuron, the lowest and highest firing rate over one period, shape (N, 2).
    #[pyo3(get)]
    output_range: Py<PyArrayDyn<f64>>,
    /// Floquet multipliers, largest modulus first; one of them is 1 (along the orbit).
    #[pyo3(get)]
    multipliers: Py<PyArray1<Complex64>>,
    /// States along one period, shape (K, N).
    #[pyo3(get)]
    orbit: Py<PyArrayDyn<f64>>,
}

impl PyCycle {
    pub fn new(py: Python<'_>, c: Cycle) -> PyResult<Self> {
        let n = c.amplitude.len();
        Ok(PyCycle {
            amplitude: vector(py, c.amplitude.clone())?,
            mean_outputs: vector(py, c.mean_outputs.clone())?,
            output_range: matrix(py, c.output_range.clone(), 2)?,
            multipliers: complex(py, &c.multipliers)?,
            orbit: matrix(py, c.orbit.clone(), n)?,
            inner: c,
        })
    }
}

#[pymethods]
impl PyCycle {
    /// The period, in units of simulated time.
    #[getter]
    fn period(&self) -> f64 {
        self.inner.period
    }

    /// Upward crossings of the Poincaré section per period (1 for a simple loop).
    #[getter]
    fn crossings(&self) -> usize {
        self.inner.crossings
    }

    /// The neuron whose level defines the section.
    #[getter]
    fn section_neuron(&self) -> usize {
        self.inner.section_neuron
    }

    /// The largest modulus other than the trivial multiplier: below 1 for a stable cycle, and the
    /// factor by which a perturbation shrinks per period.
    #[getter]
    fn max_multiplier(&self) -> f64 {
        self.inner.max_multiplier
    }

    /// Whether every non-trivial multiplier lies inside the unit circle.
    #[getter]
    fn stable(&self) -> bool {
        self.inner.stable
    }

    /// As plain JSON types; `orbit=False` leaves the orbit out.
    #[pyo3(signature = (*, orbit=true))]
    fn to_dict<'py>(&self, py: Python<'py>, orbit: bool) -> PyResult<Bound<'py, PyAny>> {
        let d = to_py(py, &self.inner)?;
        if !orbit {
            d.cast::<PyDict>()?.del_item("orbit")?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "Cycle(period={}, stable={}, max_multiplier={})",
            self.inner.period, self.inner.stable, self.inner.max_multiplier
        )
    }
}

/// A fold or Hopf point of a sweep.
#[pyclass(module = "dnnevo._core", name = "Event", frozen)]
pub struct PyEvent {
    inner: Event,
    /// `"fold"` or `"hopf"`.
    #[pyo3(get)]
    kind: String,
    /// The equilibrium there: two events at nearly the same value are told apart by it (two
    /// folds at one value are two different pairs of equilibria meeting).
    #[pyo3(get)]
    state: Py<PyArrayDyn<f64>>,
    /// The firing rates `f(v - theta)` at `state`.
    #[pyo3(get)]
    outputs: Py<PyArrayDyn<f64>>,
}

#[pymethods]
impl PyEvent {
    /// The input value where it happens.
    #[getter]
    fn value(&self) -> f64 {
        self.inner.value
    }

    /// The critical eigenvalue: real and near 0 (fold), or near `i omega` (Hopf).
    #[getter]
    fn eigenvalue<'py>(&self, py: Python<'py>) -> Bound<'py, PyComplex> {
        let [re, im] = self.inner.eigenvalue;
        PyComplex::from_doubles(py, re, im)
    }

    /// As plain JSON types.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.inner)
    }

    fn __repr__(&self) -> String {
        format!("Event(kind={:?}, value={})", self.kind, self.inner.value)
    }
}

/// Where a cycle branch appears or disappears in a sweep.
#[pyclass(module = "dnnevo._core", name = "CycleEnd", frozen)]
pub struct PyCycleEnd {
    inner: CycleEnd,
    /// `"hopf"` (the cycle shrinks onto an equilibrium at a Hopf point of the sweep) or `"lost"`
    /// (it stops being found: a fold of cycles, a homoclinic orbit, or a change the search
    /// missed).
    #[pyo3(get)]
    kind: String,
}

#[pymethods]
impl PyCycleEnd {
    /// The input value of the end: the Hopf point's, or the last value (by bisection) where the
    /// cycle was still found.
    #[getter]
    fn value(&self) -> f64 {
        self.inner.value
    }

    /// The swept value next to the end where the cycle was found.
    #[getter]
    fn with_cycle(&self) -> f64 {
        self.inner.with_cycle
    }

    /// The swept value next to the end, on the other side, where it was not.
    #[getter]
    fn without_cycle(&self) -> f64 {
        self.inner.without_cycle
    }

    /// The period at the end: `2 pi / omega` of a Hopf point's eigenvalues `±i omega`, or the last
    /// cycle the bisection found. A lost cycle whose period grows towards its end ends at a
    /// homoclinic orbit or a saddle-node on the cycle; one whose period stays finite, at a fold
    /// of cycles.
    #[getter]
    fn period(&self) -> f64 {
        self.inner.period
    }

    /// As plain JSON types.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.inner)
    }

    fn __repr__(&self) -> String {
        format!("CycleEnd(kind={:?}, value={})", self.kind, self.inner.value)
    }
}

fn cycle_end(py: Python<'_>, end: &Option<CycleEnd>) -> PyResult<Option<Py<PyCycleEnd>>> {
    end.as_ref()
        .map(|e| {
            let kind = name(&e.kind);
            Py::new(
                py,
                PyCycleEnd {
                    inner: e.clone(),
                    kind,
                },
            )
        })
        .transpose()
}

/// One attracting cycle followed across consecutive swept values.
#[pyclass(module = "dnnevo._core", name = "CycleBranch", frozen)]
pub struct PyCycleBranch {
    inner: CycleBranch,
    /// Where it appears (in sweep order), None if it is there at the first value.
    #[pyo3(get)]
    start: Option<Py<PyCycleEnd>>,
    /// Where it disappears, None if it is there at the last value.
    #[pyo3(get)]
    end: Option<Py<PyCycleEnd>>,
}

#[pymethods]
impl PyCycleBranch {
    /// Its number, in order of appearance in the sweep (`Bifurcation.cycle_branch` refers to it).
    #[getter]
    fn id(&self) -> usize {
        self.inner.id
    }

    /// Index of the first swept value with the cycle.
    #[getter]
    fn first(&self) -> usize {
        self.inner.first
    }

    /// Index of the last swept value with the cycle.
    #[getter]
    fn last(&self) -> usize {
        self.inner.last
    }

    /// As plain JSON types.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.inner)
    }

    fn __repr__(&self) -> String {
        format!(
            "CycleBranch(id={}, first={}, last={})",
            self.inner.id, self.inner.first, self.inner.last
        )
    }
}

/// A sweep of input `index`: the equilibria at each value and the events between them.
#[pyclass(module = "dnnevo._core", name = "Bifurcation", frozen)]
pub struct PyBifurcation {
    inner: Bifurcation,
    base: Vec<f64>,
    /// The other inputs' values (entry `index` is swept).
    #[pyo3(get)]
    input: Py<PyArrayDyn<f64>>,
    /// The swept values.
    #[pyo3(get)]
    values: Py<PyArrayDyn<f64>>,
    /// The equilibria at each value, sorted by state.
    #[pyo3(get)]
    equilibria: Vec<Vec<Py<PyEquilibrium>>>,
    /// Folds and Hopf points, by input value.
    #[pyo3(get)]
    events: Vec<Py<PyEvent>>,
    /// The attracting cycles at each value (empty lists unless the sweep searched for them).
    #[pyo3(get)]
    cycles: Vec<Vec<Py<PyCycle>>>,
    /// The cycles followed across values, by id.
    #[pyo3(get)]
    branches: Vec<Py<PyCycleBranch>>,
}

fn objects<T, U: pyo3::PyClass + Into<pyo3::PyClassInitializer<U>>>(
    py: Python<'_>,
    items: &[T],
    make: impl Fn(Python<'_>, T) -> PyResult<U>,
) -> PyResult<Vec<Py<U>>>
where
    T: Clone,
{
    items
        .iter()
        .map(|x| Py::new(py, make(py, x.clone())?))
        .collect()
}

impl PyBifurcation {
    /// `base` is the input vector the sweep held the other inputs at.
    pub fn new(py: Python<'_>, b: Bifurcation, base: Vec<f64>) -> PyResult<Self> {
        let equilibria = b
            .equilibria
            .iter()
            .map(|row| objects(py, row, PyEquilibrium::new))
            .collect::<PyResult<_>>()?;
        let cycles = b
            .cycles
            .iter()
            .map(|row| objects(py, row, PyCycle::new))
            .collect::<PyResult<_>>()?;
        let events = objects(py, &b.events, |py, e: Event| {
            Ok(PyEvent {
                kind: name(&e.kind),
                state: vector(py, e.state.clone())?,
                outputs: vector(py, e.outputs.clone())?,
                inner: e,
            })
        })?;
        let branches = objects(py, &b.branches, |py, c: CycleBranch| {
            Ok(PyCycleBranch {
                start: cycle_end(py, &c.start)?,
                end: cycle_end(py, &c.end)?,
                inner: c,
            })
        })?;
        Ok(PyBifurcation {
            input: vector(py, base.clone())?,
            values: vector(py, b.values.clone())?,
            base,
            equilibria,
            events,
            cycles,
            branches,
            inner: b,
        })
    }

    fn even_values(&self) -> Vec<f64> {
        let rows = self.inner.values.iter().zip(&self.inner.equilibria);
        rows.filter(|(_, row)| row.len() % 2 == 0)
            .map(|(&v, _)| v)
            .collect()
    }
}

#[pymethods]
impl PyBifurcation {
    /// The index of the swept input.
    #[getter]
    fn index(&self) -> usize {
        self.inner.input
    }

    /// The branch id of each cycle, parallel to `cycles`: an index into `branches`.
    #[getter]
    fn cycle_branch(&self) -> Vec<Vec<usize>> {
        self.inner.cycle_branch.clone()
    }

    /// The values where the first search found an even number of equilibria and searched again
    /// with `RETRY_STARTS` (or the sweep's `retry_starts`) starts.
    #[getter]
    fn retried(&self) -> Vec<f64> {
        self.inner.retried.clone()
    }

    /// The values where the count of equilibria is still even: some were missed there.
    #[getter]
    fn even(&self) -> Vec<f64> {
        self.even_values()
    }

    /// As plain JSON types (cycles without their orbits).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        #[derive(Serialize)]
        struct Plain<'a> {
            index: usize,
            input: &'a [f64],
            values: &'a [f64],
            equilibria: &'a [Vec<Equilibrium>],
            cycles: Vec<Vec<serde_json::Value>>,
            cycle_branch: &'a [Vec<usize>],
            branches: &'a [CycleBranch],
            events: &'a [Event],
            retried: &'a [f64],
            even: Vec<f64>,
        }
        let without_orbit = |c: &Cycle| {
            let mut v = serde_json::to_value(c).expect("cycles always serialise");
            if let Some(map) = v.as_object_mut() {
                map.remove("orbit");
            }
            v
        };
        let b = &self.inner;
        let plain = Plain {
            index: b.input,
            input: &self.base,
            values: &b.values,
            equilibria: &b.equilibria,
            cycles: b
                .cycles
                .iter()
                .map(|row| row.iter().map(without_orbit).collect())
                .collect(),
            cycle_branch: &b.cycle_branch,
            branches: &b.branches,
            events: &b.events,
            retried: &b.retried,
            even: self.even_values(),
        };
        to_py(py, &plain)
    }

    fn __repr__(&self) -> String {
        format!(
            "Bifurcation(index={}, values={}, events={})",
            self.inner.input,
            self.inner.values.len(),
            self.inner.events.len()
        )
    }
}
