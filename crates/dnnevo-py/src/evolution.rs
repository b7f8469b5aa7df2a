//! `dnnevo._core.Evolution` (the GA state behind `dnnevo.GeneticAlgorithm` and `dnnevo.evolve`),
//! built-in task evaluation, and thread-count control.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use ctrnn::evolve::Stats;
use ctrnn::genome;
use ctrnn::{Evolution, Network, Task, Validation};
use numpy::PyArrayDyn;
use pyo3::prelude::*;

use pyo3::types::{PyAny, PyDict};
use tasks::RunConfig;

use crate::arrays::{arg_err, dense, shape_str, to_numpy, uint, AnyInt};
use crate::detach::detached;
use crate::errors::{ConfigError, FitnessError, IntoPy};
use crate::network::PyNetwork;
use crate::population::networks_from;
use crate::run_config::PyRunConfig;

/// The GA's state: population, generation and champion, with the run's settings. See
/// `dnnevo.GeneticAlgorithm`.
#[pyclass(module = "dnnevo._core", name = "Evolution")]
pub struct PyEvolution {
    inner: Evolution,
    /// The run's settings, validated once when the run began or was restored.
    run: RunConfig,
    /// The built-in task, built at the first `step` or `champion_success` and kept: a run builds
    /// its task once, so that what the task computes once per run (its validation set) is kept.
    task: Option<Box<dyn Task>>,
}

/// The first field where `found` (the GA state's) differs from `expected` (the config's).
fn first_difference<T: serde::Serialize>(found: &T, expected: &T) -> Option<String> {
    let (serde_json::Value::Object(f), serde_json::Value::Object(e)) = (
        serde_json::to_value(found).ok()?,
        serde_json::to_value(expected).ok()?,
    ) else {
        return None;
    };
    e.iter().find_map(|(key, want)| {
        let got = f.get(key).unwrap_or(&serde_json::Value::Null);
        (got != want).then(|| format!("{key} ({got} in the GA state, {want} in the config)"))
    })
}

/// `validate(networks)` for the networks of `batch`, read back as one `Validation` each.
fn validations(validate: &Bound<'_, PyAny>, batch: &[Network]) -> PyResult<Vec<Validation>> {
    let nets: Vec<PyNetwork> = batch.iter().cloned().map(PyNetwork::from_core).collect();
    let out = validate.call1((nets,))?;
    let n = batch.len();
    let pair = || {
        FitnessError::new_err(format!(
            "validate returned {}; expected (rates, scores), two arrays of shape ({n},)",
            out.get_type()
                .name()
                .map(|t| t.to_string())
                .unwrap_or_default()
        ))
    };
    let (rates, scores): (Bound<'_, PyAny>, Bound<'_, PyAny>) =
        out.extract().map_err(|_| pair())?;
    let rates = dense(&rates, "validate's rates", FitnessError::new_err)?;
    let scores = dense(&scores, "validate's scores", FitnessError::new_err)?;
    for (what, a) in [("rates", &rates), ("scores", &scores)] {
        if a.shape != [n] {
            return Err(FitnessError::new_err(format!(
                "validate returned {what} of shape {}; expected ({n},), one per network",
                shape_str(&a.shape)
            )));
        }
    }
    Ok(rates
        .data
        .iter()
        .zip(&scores.data)
        .map(|(&rate, &score)| Validation { rate, score })
        .collect())
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

/// The number of threads of the process's shared rayon pool, which `Batch`, robot fleets and
/// every call without `threads` use. With `threads`, the pool is first sized to that many, which
/// takes only before its first use: after, it keeps its size, and the result says so.
#[pyfunction]
#[pyo3(signature = (threads=None), text_signature = "(threads=None)")]
pub fn process_threads(threads: Option<&Bound<'_, PyAny>>) -> PyResult<usize> {
    if let Some(t) = threads.filter(|t| !t.is_none()) {
        let n: usize = uint(t, "threads", "[1, 2**64)")?;
        if n == 0 {
            return Err(arg_err("threads is 0; it must be >= 1".into()));
        }
        // An error here only means the pool is running already; the count below tells.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    Ok(rayon::current_num_threads())
}

/// Runs `f` on the pool for `threads`, or directly.
fn on_pool<T: Send>(threads: Option<&Arc<rayon::ThreadPool>>, f: impl FnOnce() -> T + Send) -> T {
    match threads {
        Some(p) => p.install(f),
        None => f(),
    }
}

impl PyEvolution {
    /// The run's built-in task, built on first use.
    fn task(&mut self) -> PyResult<&dyn Task> {
        if self.task.is_none() {
            self.task = Some(self.run.build_task().py_err()?);
        }
        Ok(self.task.as_deref().expect("the task was just built"))
    }
}

#[pymethods]
impl PyEvolution {
    /// A new run with the settings `config` (`EvolutionConfig.native`); `seeds` are networks
    /// placed first in the initial population.
    #[new]
    #[pyo3(signature = (config, seed, seeds=None))]
    fn new(
        config: &PyRunConfig,
        seed: &Bound<'_, PyAny>,
        seeds: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let seed: u64 = uint(seed, "seed", "[0, 2**64)")?;
        let run = config.run.clone();
        let seeds = match seeds.filter(|s| !s.is_none()) {
            Some(s) if s.len()? > 0 => networks_from(s)?,
            _ => Vec::new(),
        };
        let inner = Evolution::new(run.layout(), run.ga(), seed, &seeds, run.fill).py_err()?;
        Ok(PyEvolution {
            inner,
            run,
            task: None,
        })
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

    /// Takes the current population's fitness and breeds the next generation. With `validate`,
    /// a callable `validate(networks) -> (rates, scores)`, the champion is chosen by validation
    /// among the top `validation_candidates`, as for a built-in task. While `validate` runs, the
    /// GA is not borrowed: the callable may read it (it sees the generation being scored), and
    /// the new state replaces the old only when everything succeeded.
    #[pyo3(signature = (fitness, validate=None))]
    fn tell<'py>(
        slf: &Bound<'py, Self>,
        fitness: &Bound<'py, PyAny>,
        validate: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let py = slf.py();
        let population = slf.borrow().inner.config.population;
        let f = dense(fitness, "fitness", FitnessError::new_err)?;
        if f.shape.len() != 1 {
            return Err(FitnessError::new_err(format!(
                "fitness has shape {}; expected (P,) = ({population},)",
                shape_str(&f.shape)
            )));
        }
        let stats = match validate.filter(|v| !v.is_none()) {
            None => {
                let mut this = slf.borrow_mut();
                let inner = &mut this.inner;
                py.detach(|| inner.tell(&f.data)).py_err()?
            }
            Some(validate) => {
                let mut next = slf.borrow().inner.clone();
                // A Python error inside `validate` is kept whole and raised as it was.
                let mut raised: Option<PyErr> = None;
                let told = next.tell_validating(&f.data, |batch| {
                    validations(validate, batch).map_err(|e| {
                        let text = e.to_string();
                        raised = Some(e);
                        ctrnn::Error::Fitness(text)
                    })
                });
                let stats = match (raised, told) {
                    (Some(e), _) => return Err(e),
                    (None, told) => told.py_err()?,
                };
                slf.borrow_mut().inner = next;
                stats
            }
        };
        stats_dict(py, &stats)
    }

    /// Scores the current population with the run's built-in task and breeds the next
    /// generation. Returns the statistics and the fitness values. Releases the GIL; Ctrl-C
    /// interrupts.
    #[pyo3(signature = (threads=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        threads: Option<AnyInt>,
    ) -> PyResult<(Bound<'py, PyDict>, Bound<'py, PyArrayDyn<f64>>)> {
        let threads: Option<usize> = threads.map(|t| t.to("threads", "[1, 2**64)")).transpose()?;
        let pool = pool(threads)?;
        self.task()?;
        let (Some(task), inner) = (self.task.as_deref(), &mut self.inner) else {
            unreachable!("the task was just built")
        };
        let (stats, fitness) = detached(py, f64::INFINITY, |cancel| {
            on_pool(pool.as_ref(), || inner.step(task, Some(cancel)))
        })?;
        let n = fitness.len();
        Ok((stats_dict(py, &stats)?, to_numpy(py, fitness, &[n])?))
    }

    /// Whether the champion meets the run's built-in task's success criterion on fresh
    /// conditions from `seed`; None when there is no champion or the task has no criterion.
    fn champion_success(
        &mut self,
        py: Python<'_>,
        seed: &Bound<'_, PyAny>,
    ) -> PyResult<Option<bool>> {
        let seed: u64 = uint(seed, "seed", "[0, 2**64)")?;
        let Some(c) = &self.inner.champion else {
            return Ok(None);
        };
        let net = genome::decode(self.inner.layout, &c.genes).py_err()?;
        let task = self.task()?;
        py.detach(|| task.succeeds(&net, seed)).py_err()
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

    /// Restores a state written by `to_json`, with the run's settings (`config`, as for `new`),
    /// which must agree with the state's own GA settings and layout.
    #[staticmethod]
    fn from_json(text: &str, config: &PyRunConfig) -> PyResult<Self> {
        let inner = Evolution::from_json(text).py_err()?;
        let run = config.run.clone();
        let difference = first_difference(&inner.config, &run.ga())
            .or_else(|| first_difference(&inner.layout, &run.layout()));
        if let Some(d) = difference {
            return Err(ConfigError::new_err(format!(
                "the GA state disagrees with its config at {d}"
            )));
        }
        Ok(PyEvolution {
            inner,
            run,
            task: None,
        })
    }
}

/// Scores networks or genomes with a run's built-in task: a pure function of (config,
/// genomes, generation, seed), bit-identical to the scores inside a run.
#[pyfunction]
#[pyo3(signature = (config, population, *, generation, seed, threads=None))]
pub fn evaluate<'py>(
    py: Python<'py>,
    config: &PyRunConfig,
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
    let task = config.run.build_task().py_err()?;
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

/// The names of the built-in tasks.
#[pyfunction]
pub fn task_names() -> Vec<&'static str> {
    tasks::registry::names().to_vec()
}
