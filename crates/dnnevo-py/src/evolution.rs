//! `dnnevo._core.Evolution` (the GA state behind `dnnevo.GeneticAlgorithm` and `dnnevo.evolve`),
//! built-in task evaluation, and thread-count control.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use ctrnn::evolve::Stats;
use ctrnn::genome::{self, Layout};
use ctrnn::names::parse_name;
use ctrnn::{Evolution, Fill, GaConfig, Task};
use numpy::PyArrayDyn;
use pyo3::prelude::*;
use pyo3::types::{PyAny, PyDict};

use crate::arrays::{arg_err, dense, shape_str, to_numpy, uint};
use crate::detach::detached;
use crate::errors::{ConfigError, FitnessError, IntoPy};
use crate::network::PyNetwork;
use crate::population::networks_from;

/// The GA's state: population, generation and champion. See `dnnevo.GeneticAlgorithm`.
#[pyclass(module = "dnnevo._core", name = "Evolution")]
pub struct PyEvolution {
    inner: Evolution,
    /// The task `step` last built, with its name and parameters: a run builds its task once, so
    /// that what the task computes once per run (its validation set) is kept.
    task: Option<(String, String, Box<dyn Task>)>,
}

fn config_from_json(text: &str) -> PyResult<GaConfig> {
    let config: GaConfig = serde_json::from_str(text)
        .map_err(|e| ConfigError::new_err(format!("GA settings: {e}")))?;
    config.validate().py_err()?;
    Ok(config)
}

fn stats_dict<'py>(py: Python<'py>, s: &Stats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("generation", s.generation)?;
    d.set_item("best", s.best)?;
    d.set_item("mean", s.mean)?;
    d.set_item("std", s.std)?;
    d.set_item("min", s.min)?;
    d.set_item("best_index", s.best_index)?;
    Ok(d)
}

/// Builds a built-in task from its name and JSON parameters.
fn build_task(name: &str, params: &str) -> PyResult<Box<dyn Task>> {
    let params: serde_json::Value = serde_json::from_str(params)
        .map_err(|e| ConfigError::new_err(format!("task parameters: {e}")))?;
    tasks::registry::build(name, &params).py_err()
}

/// A rayon pool per requested thread count, built once; `None` is rayon's global pool.
fn pool(threads: Option<usize>) -> PyResult<Option<Arc<rayon::ThreadPool>>> {
    static POOLS: Mutex<Option<HashMap<usize, Arc<rayon::ThreadPool>>>> = Mutex::new(None);
    let Some(n) = threads else { return Ok(None) };
    if n == 0 {
        return Err(arg_err("threads is 0; it must be >= 1".into()));
    }
    let mut pools = POOLS.lock().unwrap_or_else(|e| e.into_inner());
    let map = pools.get_or_insert_with(HashMap::new);
    if let Some(p) = map.get(&n) {
        return Ok(Some(p.clone()));
    }
    let p = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| arg_err(format!("cannot start {n} threads: {e}")))?,
    );
    map.insert(n, p.clone());
    Ok(Some(p))
}

/// Runs `f` on the pool for `threads`, or directly.
fn on_pool<T: Send>(threads: Option<&Arc<rayon::ThreadPool>>, f: impl FnOnce() -> T + Send) -> T {
    match threads {
        Some(p) => p.install(f),
        None => f(),
    }
}

#[pymethods]
impl PyEvolution {
    /// A new run. `config` is the GA settings as JSON (population, crossover_rate, mutation_rate,
    /// elitism, selection, ranges); `seeds` are networks placed first in the initial population.
    #[new]
    #[pyo3(signature = (config, size, n_inputs, seed, seeds=None, fill="mutants"))]
    fn new(
        config: &str,
        size: &Bound<'_, PyAny>,
        n_inputs: &Bound<'_, PyAny>,
        seed: &Bound<'_, PyAny>,
        seeds: Option<&Bound<'_, PyAny>>,
        fill: &str,
    ) -> PyResult<Self> {
        let size: usize = uint(size, "size", "[1, 2**64)")?;
        let n_inputs: usize = uint(n_inputs, "n_inputs", "[0, 2**64)")?;
        let seed: u64 = uint(seed, "seed", "[0, 2**64)")?;
        let config = config_from_json(config)?;
        let fill: Fill = parse_name("fill", fill).map_err(ConfigError::new_err)?;
        let seeds = match seeds.filter(|s| !s.is_none()) {
            Some(s) if s.len()? > 0 => networks_from(s)?,
            _ => Vec::new(),
        };
        let layout = Layout { size, n_inputs };
        let inner = Evolution::new(layout, config, seed, &seeds, fill).py_err()?;
        Ok(PyEvolution { inner, task: None })
    }

    /// The generation the current population belongs to.
    #[getter]
    fn generation(&self) -> u64 {
        self.inner.generation
    }
    /// The run's seed.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.seed
    }
    /// Genes per individual.
    #[getter]
    fn genome_length(&self) -> usize {
        self.inner.layout.len()
    }

    /// The current population's genomes, shape (P, G).
    fn genomes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let shape = [self.inner.config.population, self.inner.layout.len()];
        to_numpy(py, self.inner.population.clone(), &shape)
    }

    /// The current population as networks.
    fn networks(&self) -> PyResult<Vec<PyNetwork>> {
        Ok(self
            .inner
            .networks()
            .py_err()?
            .into_iter()
            .map(PyNetwork::from_core)
            .collect())
    }

    /// Takes the current population's fitness and breeds the next generation.
    fn tell<'py>(
        &mut self,
        py: Python<'py>,
        fitness: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let f = dense(fitness, "fitness", FitnessError::new_err)?;
        if f.shape.len() != 1 {
            return Err(FitnessError::new_err(format!(
                "fitness has shape {}; expected (P,) = ({},)",
                shape_str(&f.shape),
                self.inner.config.population
            )));
        }
        let inner = &mut self.inner;
        let stats = py.detach(|| inner.tell(&f.data)).py_err()?;
        stats_dict(py, &stats)
    }

    /// Scores the current population with a built-in task and breeds the next generation.
    /// Returns the statistics and the fitness values. Releases the GIL; Ctrl-C interrupts.
    #[pyo3(signature = (task, params, threads=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        task: &str,
        params: &str,
        threads: Option<usize>,
    ) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyArrayDyn<f64>>)> {
        if !matches!(&self.task, Some((n, p, _)) if n == task && p == params) {
            self.task = Some((
                task.to_owned(),
                params.to_owned(),
                build_task(task, params)?,
            ));
        }
        let Some((_, _, task)) = &self.task else {
            unreachable!("the task was just built")
        };
        let pool = pool(threads)?;
        let inner = &mut self.inner;
        let (stats, fitness) = detached(py, f64::INFINITY, |cancel| {
            on_pool(pool.as_ref(), || inner.step(task.as_ref(), Some(cancel)))
        })?;
        let n = fitness.len();
        Ok((stats_dict(py, &stats)?, to_numpy(py, fitness, &[n])?))
    }

    /// The fitness of the best individual so far, or None.
    #[getter]
    fn champion_fitness(&self) -> Option<f64> {
        self.inner.champion.as_ref().map(|c| c.fitness)
    }

    /// The best individual so far as (network, fitness, generation), or None.
    fn champion(&self) -> PyResult<Option<(PyNetwork, f64, u64)>> {
        let Some(c) = &self.inner.champion else {
            return Ok(None);
        };
        let net = genome::decode(self.inner.layout, &c.genes).py_err()?;
        Ok(Some((PyNetwork::from_core(net), c.fitness, c.generation)))
    }

    /// The champion's validation `(rate, score)`, or None when it was not chosen by validation.
    fn champion_validation(&self) -> Option<(f64, f64)> {
        let v = self.inner.champion.as_ref()?.validation?;
        Some((v.rate, v.score))
    }

    /// The complete state as JSON (floats exact).
    fn to_json(&self) -> String {
        self.inner.to_json()
    }

    /// Restores a state written by `to_json`.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(PyEvolution {
            inner: Evolution::from_json(text).py_err()?,
            task: None,
        })
    }
}

/// Scores networks or genomes with a built-in task: a pure function of (task, parameters,
/// genomes, generation, seed), bit-identical to the scores inside a run.
#[pyfunction]
#[pyo3(signature = (task, params, population, *, generation, seed, threads=None))]
pub fn evaluate<'py>(
    py: Python<'py>,
    task: &str,
    params: &str,
    population: &Bound<'py, PyAny>,
    generation: &Bound<'py, PyAny>,
    seed: &Bound<'py, PyAny>,
    threads: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let generation: u64 = uint(generation, "generation", "[0, 2**64)")?;
    let seed: u64 = uint(seed, "seed", "[0, 2**64)")?;
    let threads: Option<usize> = match threads.filter(|t| !t.is_none()) {
        Some(t) => Some(uint(t, "threads", "[1, 2**64)")?),
        None => None,
    };
    let task = build_task(task, params)?;
    let layout = task.layout();
    let nets = if population.cast::<PyDict>().is_err() && population.hasattr("shape")? {
        let g = dense(population, "genomes", arg_err)?;
        match g.shape.as_slice() {
            [_, len] if *len == layout.len() => g
                .data
                .chunks(layout.len())
                .map(|genes| genome::decode(layout, genes))
                .collect::<ctrnn::Result<Vec<_>>>()
                .py_err()?,
            _ => {
                return Err(arg_err(format!(
                    "genomes has shape {}; expected (P, G) with G = {}",
                    shape_str(&g.shape),
                    layout.len()
                )))
            }
        }
    } else {
        networks_from(population)?
    };
    let pool = pool(threads)?;
    let fitness = detached(py, f64::INFINITY, |cancel| {
        on_pool(pool.as_ref(), || {
            task.evaluate(&nets, generation, seed, Some(cancel))
        })
    })?;
    let n = fitness.len();
    to_numpy(py, fitness, &[n])
}

/// (size, n_inputs) of the networks a built-in task drives.
#[pyfunction]
pub fn task_layout(task: &str, params: &str) -> PyResult<(usize, usize)> {
    let layout = build_task(task, params)?.layout();
    Ok((layout.size, layout.n_inputs))
}

/// Whether `net` meets the built-in task's success criterion on fresh conditions from `seed`
/// (None when the task has none).
#[pyfunction]
pub fn task_success(
    py: Python<'_>,
    task: &str,
    params: &str,
    net: &PyNetwork,
    seed: &Bound<'_, PyAny>,
) -> PyResult<Option<bool>> {
    let seed: u64 = uint(seed, "seed", "[0, 2**64)")?;
    let task = build_task(task, params)?;
    let net = &net.inner;
    py.detach(|| task.succeeds(net, seed)).py_err()
}

/// The names of the built-in tasks.
#[pyfunction]
pub fn task_names() -> Vec<&'static str> {
    tasks::registry::names().to_vec()
}

/// Decodes one genome into a network.
#[pyfunction]
pub fn decode(size: usize, n_inputs: usize, genes: &Bound<'_, PyAny>) -> PyResult<PyNetwork> {
    let g = dense(genes, "genes", arg_err)?;
    let net = genome::decode(Layout { size, n_inputs }, &g.data).py_err()?;
    Ok(PyNetwork::from_core(net))
}

/// Encodes a network as its genome, shape (G,).
#[pyfunction]
pub fn encode<'py>(py: Python<'py>, net: &PyNetwork) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let genes = genome::encode(&net.inner);
    let n = genes.len();
    to_numpy(py, genes, &[n])
}
