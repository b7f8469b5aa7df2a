//! `dnnevo.Network`, `dnnevo.Trace`, `dnnevo.compose` and `dnnevo.run_population`.

use ctrnn::genome::{self, Layout, Ranges};
use ctrnn::io::NetworkFile;
use ctrnn::{Inputs, Integrator, Method, Population, Purpose, Stream};
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::{PyAny, PyDict, PyTuple};
use serde_json::{Map, Value};

use crate::arrays::{arg_err, dense, shape_str, to_numpy, uint, AnyInt, Dense};
use crate::detach::detached;
use crate::errors::{ConfigError, FormatError, IntoPy, InvalidNetworkError};

/// A continuous-time recurrent neural network (see the module docs of `dnnevo`).
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

fn net_err(msg: String) -> PyErr {
    InvalidNetworkError::new_err(msg)
}

fn param(obj: &Bound<'_, PyAny>, name: &str, ndim: usize, expected: &str) -> PyResult<Dense> {
    let d = dense(obj, name, net_err)?;
    d.expect_ndim(ndim, name, expected, net_err)?;
    Ok(d)
}

/// Builds the integrator from keyword arguments, raising `InvalidArgumentError` on bad values.
pub fn integrator(dt: f64, substeps: &AnyInt, method: &str) -> PyResult<Integrator> {
    let substeps: usize = substeps.to("substeps", "[1, 2**64)")?;
    let integ = Integrator {
        method: method.parse::<Method>().py_err()?,
        dt,
        substeps,
    };
    integ.validate().py_err()?;
    Ok(integ)
}

/// Parameter ranges from a dict such as `{"tau": (0.5, 10.0)}`; missing kinds keep their default.
pub fn ranges_from(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Ranges> {
    let mut ranges = Ranges::default();
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(ranges);
    };
    let dict = obj.cast::<PyDict>().map_err(|_| {
        ConfigError::new_err("ranges must be a dict such as {\"tau\": (0.5, 10.0)}")
    })?;
    for (key, value) in dict.iter() {
        let key: String = key.extract()?;
        let pair: (f64, f64) = value.extract().map_err(|_| {
            ConfigError::new_err(format!("ranges[{key:?}] must be a pair (low, high)"))
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

fn json_module(py: Python<'_>) -> PyResult<Bound<'_, PyModule>> {
    py.import("json")
}

/// Converts a Python dict (JSON-compatible) to a JSON object; the error for a value JSON cannot
/// hold (NaN, infinity, an object) names where it is, e.g. `theta[0]`.
fn dict_to_map(d: &Bound<'_, PyAny>, what: &str) -> PyResult<Map<String, Value>> {
    match to_value(d, String::new(), 0).map_err(|e| FormatError::new_err(format!("{what}: {e}")))? {
        Value::Object(m) => Ok(m),
        _ => Err(FormatError::new_err(format!("{what} must be a dict"))),
    }
}

/// The deepest nesting of lists and dicts accepted in meta and network dicts: serde_json's own
/// limit when it reads a file back, so whatever is saved can be loaded.
pub const MAX_JSON_DEPTH: usize = 128;

/// A Python value as JSON; the error says where the first unrepresentable value is.
fn to_value(obj: &Bound<'_, PyAny>, path: String, depth: usize) -> Result<Value, String> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyList, PyString, PyTuple};
    let at = |p: &str| {
        if p.is_empty() {
            "the top level".to_string()
        } else {
            p.to_string()
        }
    };
    if depth > MAX_JSON_DEPTH {
        return Err(format!(
            "{} nests lists and dicts deeper than {MAX_JSON_DEPTH}",
            at(&path)
        ));
    }
    if obj.is_none() {
        Ok(Value::Null)
    } else if let Ok(b) = obj.cast::<PyBool>() {
        Ok(Value::Bool(b.is_true()))
    } else if let Ok(i) = obj.cast::<PyInt>() {
        i.extract::<i64>()
            .map(Value::from)
            .map_err(|_| format!("{} is an integer too large for JSON", at(&path)))
    } else if let Ok(f) = obj.cast::<PyFloat>() {
        let x = f.value();
        serde_json::Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| format!("{} is {x}; every value must be finite", at(&path)))
    } else if let Ok(s) = obj.cast::<PyString>() {
        Ok(Value::String(s.to_string()))
    } else if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = Map::new();
        for (k, v) in d.iter() {
            let key = k
                .cast::<PyString>()
                .map_err(|_| format!("a key of {} is not a string", at(&path)))?
                .to_string();
            let sub = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            map.insert(key, to_value(&v, sub, depth + 1)?);
        }
        Ok(Value::Object(map))
    } else if obj.is_instance_of::<PyList>()
        || obj.is_instance_of::<PyTuple>()
        || obj.hasattr("tolist").unwrap_or(false)
    {
        let seq = if obj.hasattr("tolist").unwrap_or(false) {
            obj.call_method0("tolist").map_err(|e| e.to_string())?
        } else {
            obj.clone()
        };
        if !(seq.is_instance_of::<PyList>() || seq.is_instance_of::<PyTuple>()) {
            return to_value(&seq, path, depth + 1);
        }
        let mut items = Vec::new();
        for (k, item) in seq.try_iter().map_err(|e| e.to_string())?.enumerate() {
            let item = item.map_err(|e| e.to_string())?;
            items.push(to_value(&item, format!("{path}[{k}]"), depth + 1)?);
        }
        Ok(Value::Array(items))
    } else {
        let kind = obj
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_default();
        Err(format!("{} is a {kind}, which JSON cannot hold", at(&path)))
    }
}

fn json_to_py<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    json_module(py)?.call_method1("loads", (text,))
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
        let size: usize = uint(size, "size", "[1, 2**64)")?;
        let n_inputs: usize = uint(n_inputs, "n_inputs", "[0, 2**64)")?;
        let seed: u64 = uint(seed, "seed", "[0, 2**64)")?;
        let ranges = ranges_from(ranges)?;
        let layout = Layout { size, n_inputs };
        layout.validate().py_err()?;
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
        to_numpy(py, self.inner.tau().to_vec(), &[self.inner.size()])
    }
    /// Thresholds, shape (N,).
    #[getter]
    fn theta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        to_numpy(py, self.inner.theta().to_vec(), &[self.inner.size()])
    }
    /// Weights, shape (N, N); `weights[i][j]` is from neuron j to neuron i.
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let n = self.inner.size();
        to_numpy(py, self.inner.weights().to_vec(), &[n, n])
    }
    /// Sensor weights, shape (N, M).
    #[getter]
    fn sensor_weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let shape = [self.inner.size(), self.inner.n_inputs()];
        to_numpy(py, self.inner.sensor_weights().to_vec(), &shape)
    }
    /// The state v, shape (N,).
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        to_numpy(py, self.inner.state().to_vec(), &[self.inner.size()])
    }
    /// Firing rates f(v - theta) of the current state, shape (N,).
    #[getter]
    fn outputs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        to_numpy(py, self.inner.outputs(), &[self.inner.size()])
    }
    /// The `meta` object of the file the network came from (a copy).
    #[getter]
    fn meta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &Value::Object(self.meta.clone()).to_string())
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

    /// Integrates through the rows of `inputs` (T, M), each held for `substeps` steps of `dt`.
    #[pyo3(signature = (inputs, *, dt=0.1, substeps=AnyInt::from(1), method="euler"), text_signature = "($self, inputs, *, dt=0.1, substeps=1, method='euler')")]
    fn run(
        &mut self,
        py: Python<'_>,
        inputs: &Bound<'_, PyAny>,
        dt: f64,
        substeps: AnyInt,
        method: &str,
    ) -> PyResult<PyTrace> {
        let integ = integrator(dt, &substeps, method)?;
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
        let cost = (steps * n * n.max(1) * integ.substeps) as f64;
        let net = &mut self.inner;
        let states = detached(py, cost, |cancel| {
            net.run_cancellable(&x.data, steps, &integ, Some(cancel))
        })?;
        let theta = self.inner.theta();
        let outputs: Vec<f64> = states
            .iter()
            .enumerate()
            .map(|(k, v)| ctrnn::math::sigmoid(v - theta[k % n]))
            .collect();
        let row_time = dt * integ.substeps as f64;
        let time: Vec<f64> = (1..=steps).map(|t| t as f64 * row_time).collect();
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

    /// Writes the network file atomically; `meta` entries are added to the network's own.
    #[pyo3(signature = (path, *, meta=None))]
    fn save(&self, path: std::path::PathBuf, meta: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let mut file = self.file();
        if let Some(m) = meta.filter(|m| !m.is_none()) {
            file.meta.extend(dict_to_map(m, "meta")?);
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
#[pyo3(signature = (a, b, *, cross_scale=0.0, seed=AnyInt::from(0), member=AnyInt::from(0)), text_signature = "(a, b, *, cross_scale=0.0, seed=0, member=0)")]
pub fn compose(
    a: &PyNetwork,
    b: &PyNetwork,
    cross_scale: f64,
    seed: AnyInt,
    member: AnyInt,
) -> PyResult<PyNetwork> {
    let seed: u64 = seed.to("seed", "[0, 2**64)")?;
    let member: u64 = member.to("member", "[0, 2**64)")?;
    let mut stream = Stream::new(seed, 0, Purpose::Seeding, member, 1);
    Ok(PyNetwork::from_core(
        ctrnn::compose_with(&a.inner, &b.inner, cross_scale, &mut stream).py_err()?,
    ))
}

/// Extracts a population: a sequence of Networks, or a dict of stacked parameter arrays.
pub fn networks_from(obj: &Bound<'_, PyAny>) -> PyResult<Vec<ctrnn::Network>> {
    if let Ok(d) = obj.cast::<PyDict>() {
        return stacked(d);
    }
    Ok(network_objects(obj)?
        .iter()
        .map(|net| net.inner.clone())
        .collect())
}

/// Packs a population for the integrator straight from its Python form (as [`networks_from`]),
/// without copying each `Network` first.
fn population_from(obj: &Bound<'_, PyAny>) -> PyResult<Population> {
    if let Ok(d) = obj.cast::<PyDict>() {
        return Population::new(&stacked(d)?).py_err();
    }
    let objects = network_objects(obj)?;
    let refs: Vec<&ctrnn::Network> = objects.iter().map(|net| &net.inner).collect();
    Population::new(&refs).py_err()
}

/// Borrows every item of a non-empty sequence of Networks.
fn network_objects<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Vec<PyRef<'py, PyNetwork>>> {
    let mut nets = Vec::new();
    for (p, item) in obj
        .try_iter()
        .map_err(|_| arg_err("networks must be a sequence of Network or a dict of arrays".into()))?
        .enumerate()
    {
        let item = item?;
        let net = item.cast::<PyNetwork>().map_err(|_| {
            arg_err(format!(
                "networks[{p}] is a {}; expected a dnnevo.Network",
                item.get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ))
        })?;
        nets.push(net.borrow());
    }
    if nets.is_empty() {
        return Err(arg_err(
            "networks is empty; expected at least 1 network".into(),
        ));
    }
    Ok(nets)
}

/// A population from stacked arrays: tau (P, N), theta (P, N), weights (P, N, N),
/// sensor_weights (P, N, M) and optionally state (P, N).
fn stacked(d: &Bound<'_, PyDict>) -> PyResult<Vec<ctrnn::Network>> {
    const KEYS: [&str; 5] = ["tau", "theta", "weights", "sensor_weights", "state"];
    for key in d.keys() {
        let name = key.str()?.to_string();
        if !key.is_instance_of::<pyo3::types::PyString>() || !KEYS.contains(&name.as_str()) {
            return Err(net_err(format!(
                "the dict has an unknown key {}; expected {}",
                key.repr()?,
                KEYS.join(", ")
            )));
        }
    }
    let get = |key: &str, ndim: usize, shape: &str| -> PyResult<Option<Dense>> {
        match d.get_item(key)? {
            None => Ok(None),
            Some(v) => {
                let x = dense(&v, key, net_err)?;
                x.expect_ndim(ndim, key, shape, net_err)?;
                Ok(Some(x))
            }
        }
    };
    let need = |key: &str, ndim: usize, shape: &str| -> PyResult<Dense> {
        get(key, ndim, shape)?
            .ok_or_else(|| net_err(format!("the dict has no {key:?} array; expected {shape}")))
    };
    let tau = need("tau", 2, "(P, N)")?;
    let (p_len, n) = (tau.shape[0], tau.shape[1]);
    let theta = need("theta", 2, "(P, N)")?;
    let weights = need("weights", 3, "(P, N, N)")?;
    let sensor = need("sensor_weights", 3, "(P, N, M)")?;
    let state = get("state", 2, "(P, N)")?;
    let m = sensor.shape[2];
    let check = |x: &Dense, key: &str, want: &[usize]| -> PyResult<()> {
        if x.shape == want {
            Ok(())
        } else {
            Err(net_err(format!(
                "{key} has shape {}; expected {}",
                shape_str(&x.shape),
                shape_str(want)
            )))
        }
    };
    check(&theta, "theta", &[p_len, n])?;
    check(&weights, "weights", &[p_len, n, n])?;
    check(&sensor, "sensor_weights", &[p_len, n, m])?;
    if let Some(s) = &state {
        check(s, "state", &[p_len, n])?;
    }
    (0..p_len)
        .map(|p| {
            let row = |x: &Dense, len: usize| x.data[p * len..(p + 1) * len].to_vec();
            ctrnn::Network::new(
                row(&tau, n),
                row(&theta, n),
                row(&weights, n * n),
                row(&sensor, n * m),
                state.as_ref().map(|s| row(s, n)),
            )
            .map_err(|e| {
                net_err(format!(
                    "network {p}: {}",
                    e.to_string().trim_start_matches("invalid network: ")
                ))
            })
        })
        .collect()
}

/// Integrates P networks of the same shape together; see `dnnevo.run_population`.
#[pyfunction]
#[pyo3(signature = (networks, inputs, *, dt=0.1, substeps=AnyInt::from(1), method="euler", record=true), text_signature = "(networks, inputs, *, dt=0.1, substeps=1, method='euler', record=True)")]
pub fn run_population<'py>(
    py: Python<'py>,
    networks: &Bound<'py, PyAny>,
    inputs: &Bound<'py, PyAny>,
    dt: f64,
    substeps: AnyInt,
    method: &str,
    record: bool,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let integ = integrator(dt, &substeps, method)?;
    let mut pop = population_from(networks)?;
    let (p_len, n, m) = (pop.len(), pop.size(), pop.n_inputs());
    let x = dense(inputs, "inputs", arg_err)?;
    let (steps, shared) = match x.shape.as_slice() {
        [t, k] if *k == m => (*t, true),
        [p, t, k] if *p == p_len && *k == m => (*t, false),
        _ => {
            return Err(arg_err(format!(
                "inputs has shape {}; expected (T, M) or (P, T, M) with P = {p_len}, M = {m}",
                shape_str(&x.shape)
            )))
        }
    };
    let cost = (p_len * steps * n * n * integ.substeps) as f64;
    let out = detached(py, cost, |cancel| {
        let inputs = if shared {
            Inputs::Shared(&x.data)
        } else {
            Inputs::PerNetwork(&x.data)
        };
        pop.run(inputs, steps, &integ, record, Some(cancel))
    })?;
    if record {
        to_numpy(py, out, &[p_len, steps, n])
    } else {
        to_numpy(py, out, &[p_len, n])
    }
}
