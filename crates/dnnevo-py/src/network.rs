//! `dnnevo.Network`, `dnnevo.Trace` and `dnnevo.compose`.

use ctrnn::genome::{self, Layout, Ranges};
use ctrnn::io::NetworkFile;
use ctrnn::limits::zeros;
use ctrnn::{Integrator, Method, Precision, Purpose, Stream};
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::{PyAny, PyDict, PyTuple};
use serde_json::{Map, Value};

use crate::arrays::{
    arg_err, dense, shape_str, shown, to_numpy, to_numpy_read_only, uint, AnyFloat, AnyInt, Dense,
};
use crate::detach::detached;
use crate::errors::{ConfigError, FormatError, IntoPy, InvalidNetworkError};
use crate::pyjson::{dict_to_map, json_to_py};

/// A continuous-time recurrent neural network of N neurons and M sensors:
///
///     tau_i dv_i/dt = -v_i + sum_j weights[i][j] f(v_j - theta_j) + sum_k sensor_weights[i][k] I_k
///
/// with the firing rate f(x) = 1 / (1 + exp(-x)) (mind the sign: f(v - theta), where Beer-lab
/// code often writes sigma(v + bias)). Build one with `Network(tau, theta, weights,
/// sensor_weights, state=None)`, `Network.random(size, n_inputs, seed=...)` or
/// `Network.load(path)` (docs/network-format.md). `run` integrates it with Euler or RK4 and keeps
/// the final state; `dnnevo.analysis` finds its equilibria, cycles and bifurcations. The
/// attributes are read-only copies: to change a weight, build a new network.
#[pyclass(module = "dnnevo._core", name = "Network")]
#[derive(Clone)]
pub struct PyNetwork {
    pub(crate) inner: ctrnn::Network,
    integrator: Option<Integrator>,
    meta: Map<String, Value>,
}

impl PyNetwork {
    /// Wraps a core network with no file metadata.
    pub fn from_core(inner: ctrnn::Network) -> Self {
        PyNetwork {
            inner,
            integrator: None,
            meta: Map::new(),
        }
    }

    fn file(&self) -> NetworkFile {
        NetworkFile {
            network: self.inner.clone(),
            integrator: self.integrator,
            meta: self.meta.clone(),
        }
    }

    fn from_file(f: NetworkFile) -> Self {
        PyNetwork {
            inner: f.network,
            integrator: f.integrator,
            meta: f.meta,
        }
    }
}

pub(crate) fn net_err(msg: String) -> PyErr {
    InvalidNetworkError::new_err(msg)
}

fn param(obj: &Bound<'_, PyAny>, name: &str, ndim: usize, expected: &str) -> PyResult<Dense> {
    let d = dense(obj, name, net_err)?;
    d.expect_ndim(ndim, name, expected, net_err)?;
    Ok(d)
}

/// The layout of `size` neurons and `n_inputs` sensors given as Python integers: a size of 0 is
/// an `InvalidArgumentError` naming `size`, a layout past the core's limits a `ConfigError`.
fn layout_of(size: &Bound<'_, PyAny>, n_inputs: &Bound<'_, PyAny>) -> PyResult<Layout> {
    let size: usize = uint(size, "size", "[1, 2**64)")?;
    if size == 0 {
        return Err(arg_err(
            "size is 0; a network needs at least 1 neuron".into(),
        ));
    }
    let n_inputs: usize = uint(n_inputs, "n_inputs", "[0, 2**64)")?;
    let layout = Layout { size, n_inputs };
    layout.validate().py_err()?;
    Ok(layout)
}

/// Builds the integrator from keyword arguments, raising `InvalidArgumentError` on bad values.
pub fn integrator(dt: &AnyFloat, substeps: &AnyInt, method: &str) -> PyResult<Integrator> {
    let substeps: usize = substeps.to("substeps", "[1, 2**64)")?;
    let integ = Integrator {
        method: method.parse::<Method>().py_err()?,
        dt: dt.to("dt")?,
        substeps,
    };
    integ.validate().py_err()?;
    Ok(integ)
}

/// An integrator block as the network file has it, from a dict with exactly `method`, `dt` and
/// `substeps`; any other dict is an `InvalidArgumentError` that names what is wrong.
fn integrator_from_dict(d: &Bound<'_, PyAny>) -> PyResult<Integrator> {
    if !d.is_instance_of::<PyDict>() {
        return Err(arg_err(format!(
            "integrator must be a dict with method, dt and substeps, not {}",
            d.get_type().name()?
        )));
    }
    let map = dict_to_map(d, "integrator")?;
    let integ: Integrator = serde_json::from_value(Value::Object(map))
        .map_err(|e| arg_err(format!("integrator: {e}")))?;
    integ.validate().py_err()?;
    Ok(integ)
}

/// The kinds of parameter a range bounds.
const RANGE_KINDS: [&str; 4] = ["tau", "theta", "weights", "sensor_weights"];

/// Parameter ranges from a dict such as `{"tau": (0.5, 10.0)}` (a pair as a tuple or a list, as
/// config.toml's `[ranges]` reads), or from an object with those four attributes, such as
/// `dnnevo.Ranges`; missing kinds keep their default.
pub fn ranges_from(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Ranges> {
    let mut ranges = Ranges::default();
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(ranges);
    };
    let dict = match obj.cast::<PyDict>() {
        Ok(d) => d.clone(),
        Err(_) if RANGE_KINDS.iter().all(|k| obj.hasattr(*k).unwrap_or(false)) => {
            let d = PyDict::new(obj.py());
            for k in RANGE_KINDS {
                d.set_item(k, obj.getattr(k)?)?;
            }
            d
        }
        Err(_) => {
            return Err(ConfigError::new_err(
                "ranges must be a dict such as {\"tau\": (0.5, 10.0)} or a dnnevo.Ranges",
            ))
        }
    };
    for (key, value) in dict.iter() {
        let key: String = key.extract()?;
        let pair = value
            .extract::<(f64, f64)>()
            .ok()
            .or_else(|| match value.extract::<Vec<f64>>() {
                Ok(v) if v.len() == 2 => Some((v[0], v[1])),
                _ => None,
            })
            .ok_or_else(|| {
                ConfigError::new_err(format!(
                    "ranges[{key:?}] must be a pair [low, high]; it is {}",
                    shown(&value)
                ))
            })?;
        match key.as_str() {
            "tau" => ranges.tau = pair,
            "theta" => ranges.theta = pair,
            "weights" => ranges.weights = pair,
            "sensor_weights" => ranges.sensor_weights = pair,
            _ => {
                return Err(ConfigError::new_err(format!(
                    "ranges has unknown key {key:?}; expected tau, theta, weights or sensor_weights"
                )))
            }
        }
    }
    ranges.validate().py_err()?;
    Ok(ranges)
}

#[pymethods]
impl PyNetwork {
    #[new]
    #[pyo3(signature = (tau, theta, weights, sensor_weights, state=None))]
    fn new(
        tau: &Bound<'_, PyAny>,
        theta: &Bound<'_, PyAny>,
        weights: &Bound<'_, PyAny>,
        sensor_weights: &Bound<'_, PyAny>,
        state: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let tau = param(tau, "tau", 1, "(N,)")?;
        let n = tau.data.len();
        if n == 0 {
            return Err(net_err(
                "tau is empty; a network needs at least 1 neuron".into(),
            ));
        }
        let theta = param(theta, "theta", 1, "(N,)")?;
        let weights = param(weights, "weights", 2, "(N, N)")?;
        if weights.shape != [n, n] {
            return Err(net_err(format!(
                "weights has shape {}; expected (N, N) = ({n}, {n})",
                shape_str(&weights.shape)
            )));
        }
        let sensor = dense(sensor_weights, "sensor_weights", net_err)?;
        // An empty 1-D array means no sensors.
        let sensor_ok = match sensor.shape.as_slice() {
            [0] => true,
            [rows, _] => *rows == n,
            _ => false,
        };
        if !sensor_ok {
            return Err(net_err(format!(
                "sensor_weights has shape {}; expected (N, M) with N = {n}",
                shape_str(&sensor.shape)
            )));
        }
        let state = state
            .filter(|s| !s.is_none())
            .map(|s| param(s, "state", 1, "(N,)"))
            .transpose()?;
        let inner = ctrnn::Network::new(
            tau.data,
            theta.data,
            weights.data,
            sensor.data,
            state.map(|s| s.data),
        )
        .py_err()?;
        Ok(PyNetwork::from_core(inner))
    }

    /// The network that the genome `genes` (G,) encodes, with its state at zero: one block per
    /// neuron, in order, of its tau, its theta, its M sensor weights and its N incoming weights
    /// (`weights[i][:]`), so G = N (2 + M + N), in model units, as dnnevo's genetic algorithm
    /// evolves them. The exact inverse of [`genome`](Self::genome): for an optimiser of one's
    /// own. A wrong length, a non-finite gene or a time constant that is not positive is named
    /// with its gene and neuron.
    #[staticmethod]
    #[pyo3(signature = (genes, *, size, n_inputs))]
    fn from_genome(
        genes: &Bound<'_, PyAny>,
        size: &Bound<'_, PyAny>,
        n_inputs: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let layout = layout_of(size, n_inputs)?;
        let g = dense(genes, "genes", arg_err)?;
        g.expect_ndim(1, "genes", "(G,)", arg_err)?;
        Ok(PyNetwork::from_core(
            genome::decode(layout, &g.data).py_err()?,
        ))
    }

    /// The network's genome, shape (G,): the inverse of [`from_genome`](Self::from_genome)
    /// (its state is not part of it).
    fn genome<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let genes = genome::encode(&self.inner);
        let n = genes.len();
        to_numpy(py, genes, &[n])
    }

    /// A network with every parameter drawn uniformly over its range (default ranges: tau
    /// [0.5, 10], theta, weights and sensor_weights [-16, 16]); the state is zero.
    #[staticmethod]
    #[pyo3(signature = (size, n_inputs, *, seed, ranges=None))]
    fn random(
        size: &Bound<'_, PyAny>,
        n_inputs: &Bound<'_, PyAny>,
        seed: &Bound<'_, PyAny>,
        ranges: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let layout = layout_of(size, n_inputs)?;
        let seed: u64 = uint(seed, "seed", "[0, 2**64)")?;
        let ranges = ranges_from(ranges)?;
        let mut stream = Stream::new(seed, 0, Purpose::Init, 0, 0);
        let genes = genome::random(layout, &ranges, &mut stream);
        Ok(PyNetwork::from_core(
            genome::decode(layout, &genes).py_err()?,
        ))
    }

    /// Number of neurons N.
    #[getter]
    fn size(&self) -> usize {
        self.inner.size()
    }
    /// Number of sensors M.
    #[getter]
    fn n_inputs(&self) -> usize {
        self.inner.n_inputs()
    }
    /// Time constants, shape (N,).
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        to_numpy_read_only(py, self.inner.tau().to_vec(), &[self.inner.size()])
    }
    /// Thresholds, shape (N,).
    #[getter]
    fn theta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        to_numpy_read_only(py, self.inner.theta().to_vec(), &[self.inner.size()])
    }
    /// Weights, shape (N, N); `weights[i][j]` is from neuron j to neuron i.
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let n = self.inner.size();
        to_numpy_read_only(py, self.inner.weights().to_vec(), &[n, n])
    }
    /// Sensor weights, shape (N, M).
    #[getter]
    fn sensor_weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let shape = [self.inner.size(), self.inner.n_inputs()];
        to_numpy_read_only(py, self.inner.sensor_weights().to_vec(), &shape)
    }
    /// The state v, shape (N,).
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        to_numpy_read_only(py, self.inner.state().to_vec(), &[self.inner.size()])
    }
    /// Firing rates f(v - theta) of the current state, shape (N,).
    #[getter]
    fn outputs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        to_numpy_read_only(py, self.inner.outputs(), &[self.inner.size()])
    }
    /// The `meta` object of the file the network came from (a copy).
    #[getter]
    fn meta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &Value::Object(self.meta.clone()).to_string())
    }
    /// How the network is meant to be run, `{"method", "dt", "substeps"}`, from the file or dict
    /// it was read from; None if it had none (`save(integrator=...)` writes one into the file,
    /// not into this network). `run` does not read it: `net.run(inputs, **net.integrator)` does
    /// (with `precision=net.meta["precision"]` for a champion evolved in `f32`).
    #[getter]
    fn integrator<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.integrator
            .map(|i| json_to_py(py, &serde_json::json!(i).to_string()))
            .transpose()
    }

    /// Sets the state to `state`, or to zeros.
    #[pyo3(signature = (state=None))]
    fn reset(&mut self, state: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let state = state
            .filter(|s| !s.is_none())
            .map(|s| param(s, "state", 1, "(N,)"))
            .transpose()?;
        if let Some(s) = &state {
            if s.data.len() != self.inner.size() {
                return Err(net_err(format!(
                    "state has shape {}; expected (N,) = ({},)",
                    shape_str(&s.shape),
                    self.inner.size()
                )));
            }
        }
        self.inner
            .set_state(state.as_ref().map(|s| s.data.as_slice()))
            .py_err()
    }

    /// Integrates through the rows of `inputs` (T, M), each held for `substeps` steps of `dt`
    /// with `method` ("euler" or "rk4"), in `precision` ("f64" or "f32": see
    /// `run_population`), and keeps the final state (the next call goes on from it; `reset`
    /// starts again). Returns a `Trace`: the states and firing rates after every input row.
    #[pyo3(signature = (inputs, *, dt=AnyFloat::from(0.1), substeps=AnyInt::from(1), method="euler", precision="f64"), text_signature = "($self, inputs, *, dt=0.1, substeps=1, method='euler', precision='f64')")]
    fn run(
        &mut self,
        py: Python<'_>,
        inputs: &Bound<'_, PyAny>,
        dt: AnyFloat,
        substeps: AnyInt,
        method: &str,
        precision: &str,
    ) -> PyResult<PyTrace> {
        let integ = integrator(&dt, &substeps, method)?;
        let precision = precision.parse::<Precision>().py_err()?;
        let (n, m) = (self.inner.size(), self.inner.n_inputs());
        let x = dense(inputs, "inputs", arg_err)?;
        let steps = match x.shape.as_slice() {
            [t, k] if *k == m => *t,
            _ => {
                return Err(arg_err(format!(
                    "inputs has shape {}; expected (T, M) with M = {m}",
                    shape_str(&x.shape)
                )))
            }
        };
        let cost = steps as f64 * (n * n.max(1)) as f64 * integ.substeps as f64;
        let net = &mut self.inner;
        let states = detached(py, cost, |cancel| {
            net.run_in(&x.data, steps, &integ, precision, Some(cancel))
        })?;
        let theta = self.inner.theta();
        // Reserved, not assumed: a long run's arrays fail with an error, not an abort.
        let mut outputs = zeros(states.len(), "recorded outputs").py_err()?;
        for (k, (out, &v)) in outputs.iter_mut().zip(&states).enumerate() {
            let theta = theta[k % n];
            *out = match precision {
                Precision::F64 => ctrnn::math::sigmoid(v - theta),
                Precision::F32 => ctrnn::math::sigmoid_f32(v as f32 - theta as f32) as f64,
            };
        }
        let row_time = integ.dt * integ.substeps as f64;
        let mut time = zeros(steps, "recorded times").py_err()?;
        for (t, out) in time.iter_mut().enumerate() {
            *out = (t + 1) as f64 * row_time;
        }
        Ok(PyTrace {
            states: to_numpy(py, states, &[steps, n])?.unbind(),
            outputs: to_numpy(py, outputs, &[steps, n])?.unbind(),
            inputs: to_numpy(py, x.data, &[steps, m])?.unbind(),
            time: to_numpy(py, time, &[steps])?.unbind(),
        })
    }

    /// The network as a JSON string in the `dnnevo-network` format.
    fn to_json(&self) -> String {
        ctrnn::io::to_json(&self.file())
    }

    /// Reads a network from a `dnnevo-network` JSON string.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Self::from_file(ctrnn::io::from_json(text).py_err()?))
    }

    /// The network as a dict in the `dnnevo-network` format.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.to_json())
    }

    /// Reads a network from a dict in the `dnnevo-network` format.
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyAny>) -> PyResult<Self> {
        if !d.is_instance_of::<PyDict>() {
            return Err(FormatError::new_err(format!(
                "expected a dict, got {}",
                d.get_type().name()?
            )));
        }
        let map = dict_to_map(d, "the network dict")?;
        Self::from_json(&Value::Object(map).to_string())
    }

    /// Writes the network file atomically; `meta` entries are added to the network's own, and
    /// `integrator` (`{"method", "dt", "substeps"}`, all three) replaces its own.
    #[pyo3(signature = (path, *, meta=None, integrator=None))]
    fn save(
        &self,
        path: std::path::PathBuf,
        meta: Option<&Bound<'_, PyAny>>,
        integrator: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut file = self.file();
        if let Some(m) = meta.filter(|m| !m.is_none()) {
            file.meta.extend(dict_to_map(m, "meta")?);
        }
        if let Some(i) = integrator.filter(|i| !i.is_none()) {
            file.integrator = Some(integrator_from_dict(i)?);
        }
        ctrnn::io::save(&path, &file).py_err()
    }

    /// Reads a network file.
    #[staticmethod]
    fn load(path: std::path::PathBuf) -> PyResult<Self> {
        Ok(Self::from_file(ctrnn::io::load(&path).py_err()?))
    }

    /// An independent copy.
    fn copy(&self) -> Self {
        self.clone()
    }
    fn __copy__(&self) -> Self {
        self.clone()
    }
    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let from_json = py.get_type::<Self>().getattr("from_json")?;
        let args = PyTuple::new(py, [slf.borrow().to_json()])?;
        PyTuple::new(py, [from_json, args.into_any()])
    }
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Self>()
            .is_ok_and(|o| o.borrow().inner == self.inner)
    }
    fn __repr__(&self) -> String {
        format!(
            "Network(size={}, n_inputs={})",
            self.inner.size(),
            self.inner.n_inputs()
        )
    }
}

/// The record of a run: states, outputs and inputs after each input row, and their times.
#[pyclass(module = "dnnevo._core", name = "Trace", frozen, get_all)]
pub struct PyTrace {
    /// States after each row, shape (T, N).
    states: Py<PyArrayDyn<f64>>,
    /// Firing rates f(v - theta) after each row, shape (T, N).
    outputs: Py<PyArrayDyn<f64>>,
    /// The inputs, shape (T, M).
    inputs: Py<PyArrayDyn<f64>>,
    /// Simulated time at the end of each row, shape (T,).
    time: Py<PyArrayDyn<f64>>,
}

#[pymethods]
impl PyTrace {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let shape = self.states.bind(py).getattr("shape")?.repr()?;
        Ok(format!("Trace(states.shape={shape})"))
    }
}

/// The fully interconnected network of `a` then `b` (paper §5.3). The cross weights are 0, or,
/// with `cross_scale > 0`, each drawn uniformly in [-cross_scale, cross_scale] from the seeding
/// stream `(seed, 0, Seeding, member, 1)`, so each member of a seeded population gets its own.
#[pyfunction]
#[pyo3(signature = (a, b, *, cross_scale=AnyFloat::from(0.0), seed=AnyInt::from(0), member=AnyInt::from(0)), text_signature = "(a, b, *, cross_scale=0.0, seed=0, member=0)")]
pub fn compose(
    a: &PyNetwork,
    b: &PyNetwork,
    cross_scale: AnyFloat,
    seed: AnyInt,
    member: AnyInt,
) -> PyResult<PyNetwork> {
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let member: u64 = member.to("member", "[0, 2**64)")?;
    let mut stream = Stream::new(seed, 0, Purpose::Seeding, member, 1);
    Ok(PyNetwork::from_core(
        ctrnn::compose_with(
            &a.inner,
            &b.inner,
            cross_scale.to("cross_scale")?,
            &mut stream,
        )
        .py_err()?,
    ))
}
