//! One evolution run's settings, as `dnnevo.EvolutionConfig` writes them: the one place they are
//! checked and the one place their defaults live.
//!
//! Python's `EvolutionConfig` checks types only and takes its defaults from
//! [`RunConfig::default`]; every value check happens in [`RunConfig::validate`], so the two sides
//! cannot disagree about what a valid run is.
//!
//! # Example
//! ```
//! let config = tasks::RunConfig::from_json(r#"{"population": 20, "generations": 5}"#)?;
//! assert_eq!(config.ga().population, 20);
//! assert_eq!(config.layout().size, 5);
//! let e = tasks::RunConfig::from_json(r#"{"elitism": 200}"#).err().unwrap().to_string();
//! assert!(e.contains("elitism is 200; it must be below population = 100"), "{e}");
//! # Ok::<(), ctrnn::Error>(())
//! ```

use ctrnn::ga::MutationKind;
use ctrnn::validation::STEP_CHECK_FINER;
use ctrnn::{
    Error, Fill, GaConfig, Integrator, Layout, Precision, Ranges, Result, Selection, Task,
};
use serde::{Deserialize, Serialize};

use crate::common::{config_from_params, TIME_STEP};
use crate::StepChecked;

/// Everything an evolution run needs besides its seed. Missing fields take their defaults;
/// unknown fields are an error.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RunConfig {
    /// The task's name: a built-in task ([`crate::names`]), or a caller's own (Python's
    /// `python:module.function`), which only the caller can build. Default `"sequence"`.
    pub task: String,
    /// Individuals per generation. Default 100.
    pub population: usize,
    /// Generations to run (at least 1). Default 100.
    pub generations: u64,
    /// See [`GaConfig::crossover_rate`]. Default 0.5.
    pub crossover_rate: f64,
    /// See [`GaConfig::mutation_rate`] (a per-gene rate). Default 0.025.
    pub mutation_rate: f64,
    /// See [`GaConfig::mutation`]. Default uniform, the paper's.
    pub mutation: MutationKind,
    /// See [`GaConfig::mutation_scale`].
    pub mutation_scale: f64,
    /// See [`GaConfig::elitism`]. Default 0, the paper's.
    pub elitism: usize,
    /// See [`GaConfig::validation_candidates`]. Default 10.
    pub validation_candidates: usize,
    /// See [`GaConfig::champion_step_check`]; a built-in task then validates would-be champions
    /// again with its integrator made [`STEP_CHECK_FINER`] times finer ([`StepChecked`]).
    /// Default false.
    pub champion_step_check: bool,
    /// See [`GaConfig::selection`]. Default proportional, the paper's.
    pub selection: Selection,
    /// With seed networks, how the rest of the population is filled. Default mutants.
    pub fill: Fill,
    /// Neurons per network (at least 1). Default 5.
    pub size: usize,
    /// Sensors per network; a built-in task checks it matches. Default 2.
    pub n_inputs: usize,
    /// How a built-in task integrates its networks. Default [`TIME_STEP`].
    pub integrator: Integrator,
    /// The floating-point type a built-in task's networks compute in: `"f64"` (default, the
    /// reference for every published result) or `"f32"`, opt-in single precision (see
    /// [`Precision`]).
    pub precision: Precision,
    /// Gene ranges. Default [`Ranges::default`].
    pub ranges: Ranges,
    /// The task's own settings, passed to it as they are.
    pub task_params: serde_json::Map<String, serde_json::Value>,
}

impl Default for RunConfig {
    fn default() -> Self {
        let ga = GaConfig::default();
        RunConfig {
            task: "sequence".into(),
            population: ga.population,
            generations: 100,
            crossover_rate: ga.crossover_rate,
            mutation_rate: ga.mutation_rate,
            mutation: ga.mutation,
            mutation_scale: ga.mutation_scale,
            elitism: ga.elitism,
            validation_candidates: ga.validation_candidates,
            champion_step_check: ga.champion_step_check,
            selection: ga.selection,
            fill: Fill::default(),
            size: 5,
            n_inputs: 2,
            integrator: TIME_STEP,
            precision: Precision::F64,
            ranges: ga.ranges,
            task_params: serde_json::Map::new(),
        }
    }
}

/// The settings a task's parameters may not hold, because the run config sets them.
const SET_BY_RUN: [&str; 3] = ["size", "integrator", "precision"];

impl RunConfig {
    /// Reads and validates a config from JSON text. Errors name the field (`integrator.dt`).
    pub fn from_json(text: &str) -> Result<Self> {
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| Error::Config(format!("config: not valid JSON: {e}")))?;
        let config: RunConfig = config_from_params("config", &value)?;
        config.validate()?;
        Ok(config)
    }

    /// Checks every value; the first problem is an [`Error::Config`] that names its field.
    pub fn validate(&self) -> Result<()> {
        if self.task.is_empty() {
            return Err(Error::Config("task is empty; expected a task name".into()));
        }
        if self.generations == 0 {
            return Err(Error::Config(
                "generations is 0; it must be at least 1".into(),
            ));
        }
        if self.size == 0 {
            return Err(Error::Config("size is 0; it must be at least 1".into()));
        }
        self.ga().validate()?;
        self.integrator.validate().map_err(|e| match e {
            Error::InvalidArgument(m) => Error::Config(format!("integrator.{m}")),
            other => other,
        })?;
        // Every network the run makes has a time constant in ranges.tau.
        self.integrator
            .check_step(self.ranges.tau.0, "the lower end of ranges.tau")
            .map_err(|e| match e {
                Error::InvalidArgument(m) => Error::Config(format!("integrator.{m}")),
                other => other,
            })?;
        if self.champion_step_check {
            self.finer_integrator()?;
        }
        if let Some(key) = SET_BY_RUN
            .iter()
            .find(|k| self.task_params.contains_key(**k))
        {
            return Err(Error::Config(format!(
                "task_params.{key} is set; set {key} at the top level of the config"
            )));
        }
        Ok(())
    }

    /// `build(task_params())`: a task built from this config's parameters, its errors named as
    /// the config names them (see [`RunConfig::task_params`]).
    pub fn with_task_params<T>(
        &self,
        build: impl FnOnce(&serde_json::Value) -> Result<T>,
    ) -> Result<T> {
        build(&self.task_params()).map_err(|e| self.in_task_params(e))
    }

    /// A task's error about one of its parameters, named as the config names it
    /// (`sequence: task_params.triggers: ...`, `task_params.triggers is 0; ...`): the task sees
    /// `task_params` beside the settings the run sets ([`SET_BY_RUN`]), and its errors start
    /// with the field, after the task's name when the field could not be read. Only a field the
    /// config sets is recognised: an error that starts with a default field is left as it is.
    fn in_task_params(&self, e: Error) -> Error {
        let Error::Config(message) = &e else {
            return e;
        };
        let head = format!("{}: ", self.task);
        let (head, rest) = match message.strip_prefix(&head) {
            Some(rest) => (head.as_str(), rest),
            None => ("", message.as_str()),
        };
        let names_a_param = self.task_params.keys().any(|key| {
            !key.is_empty()
                && rest
                    .strip_prefix(key.as_str())
                    .is_some_and(|after| after.starts_with([':', '.', ' ', '[']))
        });
        if names_a_param {
            Error::Config(format!("{head}task_params.{rest}"))
        } else {
            e
        }
    }

    /// The step check's integrator: the run's, [`STEP_CHECK_FINER`] times finer.
    fn finer_integrator(&self) -> Result<Integrator> {
        self.integrator
            .finer(STEP_CHECK_FINER)
            .map_err(|e| match e {
                Error::InvalidArgument(m) => Error::Config(format!(
                    "champion_step_check: integrator.{m}, so it cannot be made \
                     {STEP_CHECK_FINER}x finer"
                )),
                other => other,
            })
    }

    /// The genetic algorithm's part.
    pub fn ga(&self) -> GaConfig {
        GaConfig {
            population: self.population,
            crossover_rate: self.crossover_rate,
            mutation_rate: self.mutation_rate,
            mutation: self.mutation,
            mutation_scale: self.mutation_scale,
            elitism: self.elitism,
            selection: self.selection,
            ranges: self.ranges,
            validation_candidates: self.validation_candidates,
            champion_step_check: self.champion_step_check,
        }
    }

    /// The networks' shape.
    pub fn layout(&self) -> Layout {
        Layout {
            size: self.size,
            n_inputs: self.n_inputs,
        }
    }

    /// The parameters a built-in task is built from: `size`, `integrator`, `precision`, then
    /// `task_params`.
    pub fn task_params(&self) -> serde_json::Value {
        let mut params = self.task_params.clone();
        params.insert("size".into(), self.size.into());
        let integrator = serde_json::to_value(self.integrator).expect("settings always serialise");
        params.insert("integrator".into(), integrator);
        params.insert("precision".into(), self.precision.name().into());
        serde_json::Value::Object(params)
    }

    /// Builds the built-in task this config names, paired with its finer copy when
    /// `champion_step_check` is on; a caller's own task name is an error.
    pub fn build_task(&self) -> Result<Box<dyn Task>> {
        let task = self.with_task_params(|params| crate::build(&self.task, params))?;
        if !self.champion_step_check {
            return Ok(task);
        }
        let finer = RunConfig {
            integrator: self.finer_integrator()?,
            ..self.clone()
        };
        let finer = finer.with_task_params(|params| crate::build(&self.task, params))?;
        Ok(Box::new(StepChecked::new(task, finer)))
    }
}
