//! Populations from Python (a sequence of Networks, or stacked parameter arrays) and
//! `dnnevo.run_population`.

use ctrnn::{Inputs, Population, Precision};
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::{PyAny, PyDict};

use crate::arrays::{arg_err, dense, shape_str, to_numpy, AnyFloat, AnyInt, Dense};
use crate::detach::detached;
use crate::errors::IntoPy;
use crate::network::PyNetwork;
use crate::network::{integrator, net_err};

/// Extracts a population: a sequence of Networks, or a dict of stacked parameter arrays.
pub fn networks_from(obj: &Bound<'_, PyAny>) -> PyResult<Vec<ctrnn::Network>> {
    if let Some(d) = as_dict(obj)? {
        let arrays = stacked(&d)?;
        let rows = arrays.rows();
        ctrnn::Params::validate_each(&rows).py_err()?;
        return rows.iter().map(|row| row.to_network().py_err()).collect();
    }
    Ok(network_objects(obj)?
        .iter()
        .map(|net| net.inner.clone())
        .collect())
}

/// Packs a population for the integrator straight from its Python form (as [`networks_from`]),
/// without an owned `Network` per member, to compute in `precision`.
fn population_from(obj: &Bound<'_, PyAny>, precision: Precision) -> PyResult<Population> {
    if let Some(d) = as_dict(obj)? {
        return Population::from_params(&stacked(&d)?.rows(), precision).py_err();
    }
    let objects = network_objects(obj)?;
    let refs: Vec<&ctrnn::Network> = objects.iter().map(|net| &net.inner).collect();
    Population::with_precision(&refs, precision).py_err()
}

/// `obj` as a dict when it is a mapping (stacked arrays: a dict, or any `collections.abc.Mapping`,
/// copied into one), else None (a sequence of Networks).
fn as_dict<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyDict>>> {
    if let Ok(d) = obj.cast::<PyDict>() {
        return Ok(Some(d.clone()));
    }
    if obj.cast::<pyo3::types::PyMapping>().is_err() {
        return Ok(None);
    }
    let copy = PyDict::new(obj.py());
    for item in obj.call_method0("items")?.try_iter()? {
        let (key, value): (Bound<'py, PyAny>, Bound<'py, PyAny>) = item?.extract()?;
        copy.set_item(key, value)?;
    }
    Ok(Some(copy))
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
                "networks[{p}] is of type {}; expected a dnnevo.Network",
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

/// A population as stacked arrays, shapes checked, values not yet.
struct Stacked {
    tau: Dense,
    theta: Dense,
    weights: Dense,
    sensor: Dense,
    /// The given states, or zeros.
    state: Vec<f64>,
    len: usize,
    n: usize,
    m: usize,
}

impl Stacked {
    /// Each network's parameters, borrowed.
    fn rows(&self) -> Vec<ctrnn::Params<'_>> {
        let (n, m) = (self.n, self.m);
        fn row(x: &[f64], p: usize, len: usize) -> &[f64] {
            &x[p * len..(p + 1) * len]
        }
        (0..self.len)
            .map(|p| ctrnn::Params {
                tau: row(&self.tau.data, p, n),
                theta: row(&self.theta.data, p, n),
                weights: row(&self.weights.data, p, n * n),
                sensor_weights: row(&self.sensor.data, p, n * m),
                state: row(&self.state, p, n),
            })
            .collect()
    }
}

/// A population from stacked arrays: tau (P, N), theta (P, N), weights (P, N, N),
/// sensor_weights (P, N, M) and optionally state (P, N).
fn stacked(d: &Bound<'_, PyDict>) -> PyResult<Stacked> {
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
            // An optional array given as None is absent, as `Network(state=None)` is.
            None => Ok(None),
            Some(v) if v.is_none() && key == "state" => Ok(None),
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
    Ok(Stacked {
        tau,
        theta,
        weights,
        sensor,
        state: state.map_or_else(|| vec![0.0; p_len * n], |s| s.data),
        len: p_len,
        n,
        m,
    })
}

/// Integrates P networks of the same N and M together, each through the same `inputs` (T, M)
/// (or its own, (P, T, M)): the states after every input row (P, T, N) with `record`, else the
/// final states (P, N). `networks` is a list of `Network`s or a dict of stacked arrays (`tau`
/// (P, N), `theta` (P, N), `weights` (P, N, N), `sensor_weights` (P, N, M), optionally `state`
/// (P, N)). `precision="f32"` computes in single precision (parameters and inputs rounded to
/// float32 once, states float32 throughout, returned widened to float64); "f64", the default,
/// is the reference. Every kernel (AVX-512, AVX2, portable, NEON) gives the same bits.
#[pyfunction]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments
#[pyo3(signature = (networks, inputs, *, dt=AnyFloat::from(0.1), substeps=AnyInt::from(1), method="euler", record=true, precision="f64"), text_signature = "(networks, inputs, *, dt=0.1, substeps=1, method='euler', record=True, precision='f64')")]
pub fn run_population<'py>(
    py: Python<'py>,
    networks: &Bound<'py, PyAny>,
    inputs: &Bound<'py, PyAny>,
    dt: AnyFloat,
    substeps: AnyInt,
    method: &str,
    record: bool,
    precision: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let integ = integrator(&dt, &substeps, method)?;
    let precision = precision.parse::<Precision>().py_err()?;
    let mut pop = population_from(networks, precision)?;
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
    let cost = p_len as f64 * steps as f64 * (n * n) as f64 * integ.substeps as f64;
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
