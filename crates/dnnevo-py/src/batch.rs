//! `dnnevo.Batch`: many networks stepped one input row per call, for closed-loop tasks.
//!
//! A step reads the caller's float64 or float32 inputs and writes into the caller's output
//! array in place when given, so that a loop of steps copies and allocates nothing.

use ctrnn::Precision;
use numpy::{
    PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::{PyAny, PyDict};

use crate::arrays::{arg_err, dense, shape_str, shown, to_numpy, AnyFloat, AnyInt, Dense};
use crate::detach::detached;
use crate::errors::IntoPy;
use crate::network::integrator;
use crate::population::networks_from;

/// P networks times E replicas, stepped together one time step per call: the core of a
/// closed-loop task, where each step's inputs come from the last step's outputs.
///
/// ``Batch(networks, *, replicas=1, rows=None, dt=0.1, substeps=1, method="euler",
/// precision="f64")`` holds B = P
/// * E rows; row ``p * replicas + e`` is replica ``e`` of ``networks[p]`` (a sequence of Networks
/// of one shape, or a dict of stacked arrays as for ``run_population``). Each row starts from its
/// network's state. With ``rows`` (1 to P * E) it holds only the first ``rows`` of those rows,
/// and ``assign(rows, networks)`` hands rows to other networks (indices into ``networks``), each
/// starting from its new network's state: a rollout keeps fewer rows busy this way, starting a
/// waiting episode in a row whose episode ended. ``network_of`` is each row's network.
///
/// - ``step(inputs, *, active=None, out=None)`` holds ``inputs`` (B, M), float64 or float32, for
///   ``substeps`` steps of ``dt`` and returns every stepped row's firing rates ``f(v - theta)``,
///   (B, N) float64: in ``out`` when given (then nothing is allocated), else in a new array.
///   Rows where the bool array ``active`` (B,) is False keep their state and their entries of
///   ``out``, may hold any input, and cost nothing once they fill whole blocks: the rows still
///   running are moved together. The GIL is released; Ctrl-C stops a long step between blocks
///   of 16 rows and every 1024 integration steps within one.
/// - ``reset(rows=None)`` sets rows to state 0, as every built-in task starts a trial;
///   ``set_states(states, rows=None)`` sets them from (B, N). ``rows`` is a bool mask (B,) or
///   row indices; None is every row.
/// - ``states`` and ``rates`` are (B, N) copies.
///
/// A row gives the same bits as ``Network.run`` fed the same rows of inputs, on every kernel.
/// ``precision="f32"`` computes in single precision, as ``Network.run(..., precision="f32")``
/// does: parameters, states and inputs rounded to float32 when read, states and rates float32
/// values widened to float64.
///
/// >>> import numpy as np, dnnevo
/// >>> nets = [dnnevo.Network.random(3, 1, seed=s) for s in range(4)]
/// >>> batch = dnnevo.Batch(nets, replicas=2)
/// >>> rates = np.empty((batch.rows, batch.size))
/// >>> for t in range(5):
/// ...     _ = batch.step(np.ones((batch.rows, 1)), out=rates)
/// >>> trace = nets[1].copy().run(np.ones((5, 1)))
/// >>> bool((rates[2] == trace.outputs[-1]).all())
/// True
#[pyclass(module = "dnnevo._core", name = "Batch")]
pub struct PyBatch {
    inner: ctrnn::Batch,
}

/// A step's inputs: the caller's own array when it is a C-contiguous float64 or float32 one,
/// else a float64 copy.
enum Inputs<'py> {
    F64(PyReadonlyArray2<'py, f64>),
    F32(PyReadonlyArray2<'py, f32>),
    Copied(Dense),
}

impl<'py> Inputs<'py> {
    fn from(obj: &Bound<'py, PyAny>) -> PyResult<Self> {
        if let Ok(a) = obj.cast::<PyArray2<f64>>() {
            if a.is_c_contiguous() {
                return Ok(Inputs::F64(a.readonly()));
            }
        }
        if let Ok(a) = obj.cast::<PyArray2<f32>>() {
            if a.is_c_contiguous() {
                return Ok(Inputs::F32(a.readonly()));
            }
        }
        Ok(Inputs::Copied(dense(obj, "inputs", arg_err)?))
    }

    fn shape(&self) -> Vec<usize> {
        match self {
            Inputs::F64(a) => a.shape().to_vec(),
            Inputs::F32(a) => a.shape().to_vec(),
            Inputs::Copied(d) => d.shape.clone(),
        }
    }
}

/// A row mask: the caller's own C-contiguous bool array, or a copy of a sequence of bools.
enum Mask<'py> {
    Borrowed(PyReadonlyArray1<'py, bool>),
    Owned(Vec<bool>),
}

impl Mask<'_> {
    fn as_slice(&self) -> PyResult<&[bool]> {
        match self {
            Mask::Borrowed(a) => Ok(a.as_slice()?),
            Mask::Owned(v) => Ok(v),
        }
    }
}

/// [`mask`] without a copy when `obj` is a C-contiguous bool array of the right length.
fn row_mask<'py>(obj: &Bound<'py, PyAny>, name: &str, rows: usize) -> PyResult<Mask<'py>> {
    if let Ok(a) = obj.cast::<PyArray1<bool>>() {
        if a.is_c_contiguous() && a.len() == rows {
            return Ok(Mask::Borrowed(a.readonly()));
        }
    }
    mask(obj, name, rows).map(Mask::Owned)
}

/// A boolean row mask of length `rows` from a NumPy bool array or a sequence of bools; any other
/// dtype is refused rather than cast (0.5 is not a truth value).
fn mask(obj: &Bound<'_, PyAny>, name: &str, rows: usize) -> PyResult<Vec<bool>> {
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj,))?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if kind != "b" || shape != [rows] {
        return Err(arg_err(format!(
            "{name} is an array of dtype {} and shape {}; expected booleans of shape ({rows},), one per row",
            arr.getattr("dtype")?.str()?,
            shape_str(&shape)
        )));
    }
    let arr = np.call_method1("ascontiguousarray", (arr,))?;
    let arr = arr.cast_into::<PyArray1<bool>>()?;
    Ok(arr.readonly().as_slice()?.to_vec())
}

/// Rows chosen by a boolean mask or by integer indices (each in `[-B, B)`); `None` is every row.
fn chosen_rows(obj: Option<&Bound<'_, PyAny>>, rows: usize) -> PyResult<Option<Vec<bool>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj,))?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    if kind == "b" {
        return mask(obj, "rows", rows).map(Some);
    }
    let ndim: usize = arr.getattr("ndim")?.extract()?;
    let size: usize = arr.getattr("size")?.extract()?;
    // An empty list has dtype float; it chooses no row.
    let integers = kind == "i" || kind == "u" || size == 0;
    if ndim != 1 || !integers {
        return Err(arg_err(format!(
            "rows is an array of dtype {} and {ndim} dimensions; expected a boolean mask of shape ({rows},) \
             or a 1-D array of row indices",
            arr.getattr("dtype")?.str()?
        )));
    }
    let indices: Vec<i64> = arr.call_method0("tolist")?.extract()?;
    let mut out = vec![false; rows];
    for r in indices {
        let at = if r < 0 { r + rows as i64 } else { r };
        if at < 0 || at >= rows as i64 {
            return Err(arg_err(format!(
                "rows holds index {r}; this batch has {rows} rows"
            )));
        }
        out[at as usize] = true;
    }
    Ok(Some(out))
}

/// Indices into `len` items from a 1-D integer array or a sequence of ints (an empty list is no
/// index); a negative one counts from the end, as NumPy's and [`chosen_rows`]' do. One past the
/// end and beyond is left to the caller to name.
fn indices(obj: &Bound<'_, PyAny>, name: &str, len: usize) -> PyResult<Vec<usize>> {
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("asarray", (obj,))?;
    let kind: String = arr.getattr("dtype")?.getattr("kind")?.extract()?;
    let ndim: usize = arr.getattr("ndim")?.extract()?;
    let size: usize = arr.getattr("size")?.extract()?;
    if ndim != 1 || !(kind == "i" || kind == "u" || size == 0) {
        return Err(arg_err(format!(
            "{name} is an array of dtype {} and {ndim} dimensions; expected a 1-D array of indices",
            arr.getattr("dtype")?.str()?
        )));
    }
    let values: Vec<i128> = arr.call_method0("tolist")?.extract()?;
    values
        .into_iter()
        .map(|v| {
            let at = if v < 0 { v + len as i128 } else { v };
            usize::try_from(at).map_err(|_| {
                arg_err(format!(
                    "{name} holds index {v}; there are {len} {name}, so indices run from -{len} to {}",
                    len as i128 - 1
                ))
            })
        })
        .collect()
}

#[pymethods]
impl PyBatch {
    #[new]
    #[pyo3(signature = (networks, *, replicas=AnyInt::from(1), rows=None, dt=AnyFloat::from(0.1), substeps=AnyInt::from(1), method="euler", precision="f64"), text_signature = "(networks, *, replicas=1, rows=None, dt=0.1, substeps=1, method='euler', precision='f64')")]
    fn new(
        networks: &Bound<'_, PyAny>,
        replicas: AnyInt,
        rows: Option<AnyInt>,
        dt: AnyFloat,
        substeps: AnyInt,
        method: &str,
        precision: &str,
    ) -> PyResult<Self> {
        let integ = integrator(&dt, &substeps, method)?;
        let precision = precision.parse::<Precision>().py_err()?;
        let replicas: usize = replicas.to("replicas", "[1, 2**64)")?;
        let nets = networks_from(networks)?;
        let all = (nets.len() as u128).saturating_mul(replicas as u128);
        let rows = match rows {
            None => usize::try_from(all).unwrap_or(usize::MAX),
            Some(rows) => rows.to("rows", "[1, 2**64)")?,
        };
        let inner = ctrnn::Batch::with_rows_in(&nets, replicas, rows, integ, precision);
        Ok(PyBatch {
            inner: inner.py_err()?,
        })
    }

    /// Rows B: networks * replicas, or as many as `rows` said.
    #[getter]
    fn rows(&self) -> usize {
        self.inner.rows()
    }
    /// Networks P.
    #[getter]
    fn networks(&self) -> usize {
        self.inner.networks()
    }
    /// Replicas E per network.
    #[getter]
    fn replicas(&self) -> usize {
        self.inner.replicas()
    }
    /// Neurons per network N.
    #[getter]
    fn size(&self) -> usize {
        self.inner.size()
    }
    /// Sensors per network M.
    #[getter]
    fn n_inputs(&self) -> usize {
        self.inner.n_inputs()
    }
    /// The precision it computes in, "f64" or "f32".
    #[getter]
    fn precision(&self) -> &'static str {
        self.inner.precision().name()
    }
    /// The integration settings, {"method": ..., "dt": ..., "substeps": ...}.
    #[getter]
    fn integrator<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let i = self.inner.integrator();
        let d = PyDict::new(py);
        d.set_item("method", i.method.name())?;
        d.set_item("dt", i.dt)?;
        d.set_item("substeps", i.substeps)?;
        Ok(d)
    }

    /// Every row's state, a (B, N) copy.
    #[getter]
    fn states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (b, n) = (self.inner.rows(), self.inner.size());
        to_numpy(py, self.inner.states(), &[b, n])
    }

    /// Every row's firing rates f(v - theta), a (B, N) copy.
    #[getter]
    fn rates<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let (b, n) = (self.inner.rows(), self.inner.size());
        to_numpy(py, self.inner.rates(), &[b, n])
    }

    /// Holds one row of inputs per row for `substeps` steps and returns every row's rates.
    #[pyo3(signature = (inputs, *, active=None, out=None), text_signature = "($self, inputs, *, active=None, out=None)")]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        inputs: &Bound<'py, PyAny>,
        active: Option<&Bound<'py, PyAny>>,
        out: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (b, n, m) = (self.inner.rows(), self.inner.size(), self.inner.n_inputs());
        let x = Inputs::from(inputs)?;
        if x.shape() != [b, m] {
            return Err(arg_err(format!(
                "inputs has shape {}; expected (B, M) = ({b}, {m})",
                shape_str(&x.shape())
            )));
        }
        let active = active
            .filter(|a| !a.is_none())
            .map(|a| row_mask(a, "active", b))
            .transpose()?;
        let out = match out.filter(|o| !o.is_none()) {
            Some(o) => {
                let arr = o.cast::<PyArray2<f64>>().map_err(|_| {
                    arg_err(format!(
                        "out is {}; expected a float64 NumPy array of shape (B, N) = ({b}, {n})",
                        shown(&o)
                    ))
                })?;
                if arr.shape() != [b, n] || !arr.is_c_contiguous() {
                    return Err(arg_err(format!(
                        "out has shape {}{}; expected a C-contiguous array of shape (B, N) = ({b}, {n})",
                        shape_str(arr.shape()),
                        if arr.is_c_contiguous() { "" } else { " and is not C-contiguous" }
                    )));
                }
                o.clone()
            }
            None => PyArray2::<f64>::zeros(py, [b, n], false).into_any(),
        };
        let arr = out.cast::<PyArray2<f64>>()?;
        let mut rates = arr
            .try_readwrite()
            .map_err(|e| arg_err(format!("out cannot be written: {e}")))?;
        let rates = rates.as_slice_mut()?;
        let integ = *self.inner.integrator();
        let cost = b as f64 * (n * n.max(1)) as f64 * integ.substeps as f64;
        let batch = &mut self.inner;
        let active = active.as_ref().map(Mask::as_slice).transpose()?;
        match &x {
            Inputs::F64(a) => {
                let x = a.as_slice()?;
                detached(py, cost, |cancel| {
                    batch.step(x, active, rates, Some(cancel))
                })?
            }
            Inputs::F32(a) => {
                let x = a.as_slice()?;
                detached(py, cost, |cancel| {
                    batch.step(x, active, rates, Some(cancel))
                })?
            }
            Inputs::Copied(d) => {
                let x = d.data.as_slice();
                detached(py, cost, |cancel| {
                    batch.step(x, active, rates, Some(cancel))
                })?
            }
        }
        Ok(out)
    }

    /// The network each row runs, an index into the batch's networks, a (B,) int64 copy.
    #[getter]
    fn network_of<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let of: Vec<i64> = self.inner.network_of().iter().map(|&p| p as i64).collect();
        PyArray1::from_vec(py, of)
    }

    /// Gives row `rows[i]` to network `networks[i]` (row and network indices, 1-D integer arrays
    /// of one length, a negative index counting from the end); those rows start from their new
    /// network's state, the others keep theirs.
    #[pyo3(signature = (rows, networks), text_signature = "($self, rows, networks)")]
    fn assign(&mut self, rows: &Bound<'_, PyAny>, networks: &Bound<'_, PyAny>) -> PyResult<()> {
        let rows = indices(rows, "rows", self.inner.rows())?;
        let networks = indices(networks, "networks", self.inner.networks())?;
        self.inner.assign(&rows, &networks).py_err()
    }

    /// Sets the chosen rows' states to zero (every row when `rows` is None). `rows` is a boolean
    /// mask of shape (B,) or row indices, a negative one counting from the end.
    #[pyo3(signature = (rows=None), text_signature = "($self, rows=None)")]
    fn reset(&mut self, rows: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let chosen = chosen_rows(rows, self.inner.rows())?;
        self.inner.reset(chosen.as_deref()).py_err()
    }

    /// Sets the chosen rows' states from `states` (B, N) (every row when `rows` is None; chosen as
    /// in `reset`).
    #[pyo3(signature = (states, rows=None), text_signature = "($self, states, rows=None)")]
    fn set_states(
        &mut self,
        states: &Bound<'_, PyAny>,
        rows: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let (b, n) = (self.inner.rows(), self.inner.size());
        let s = dense(states, "states", arg_err)?;
        if s.shape != [b, n] {
            return Err(arg_err(format!(
                "states has shape {}; expected (B, N) = ({b}, {n})",
                shape_str(&s.shape)
            )));
        }
        let chosen = chosen_rows(rows, b)?;
        self.inner.set_states(&s.data, chosen.as_deref()).py_err()
    }

    fn __len__(&self) -> usize {
        self.inner.rows()
    }

    fn __repr__(&self) -> String {
        let i = self.inner.integrator();
        format!(
            "Batch(networks={}, replicas={}, size={}, n_inputs={}, method='{}', dt={}, substeps={}, precision='{}')",
            self.inner.networks(),
            self.inner.replicas(),
            self.inner.size(),
            self.inner.n_inputs(),
            i.method.name(),
            i.dt,
            i.substeps,
            self.inner.precision().name()
        )
    }
}
