//! The generation loop's state: a population, its generation counter and its champion, with
//! ask/tell, a [`Task`] trait for fitness functions written in Rust (the built-in tasks, or your
//! own: `crates/ctrnn/examples/own_task.rs`), and checkpoints.
//!
//! One generation is: decode the genomes, score them all with a task (or with fitness told from
//! outside), re-score the best candidates on the task's validation set
//! ([`crate::validation`]), record the statistics and the champion, then breed the next
//! population with [`crate::ga::next_generation`]. Every random draw comes from a stream keyed
//! by the run's seed and the generation, so a run resumed from a checkpoint continues with
//! exactly the same bits.

use std::collections::HashMap;
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::ga::{self, check_fitness, GaConfig};
use crate::genome::{self, Layout};
use crate::network::Network;
use crate::rng::{Purpose, Stream};
use crate::validation::{candidates, Validation, STEP_CHECK_FINER};

/// A fitness function that scores a whole generation at once, so that it can drive the
/// population integrator.
///
/// `evaluate` must be a pure function of `(self, networks, generation, seed)`: that is what makes
/// runs reproducible, resumable, and shardable across machines. The task draws its own trial
/// conditions; the convention of the built-in tasks is that every individual of a generation
/// meets the same ones (common random numbers), drawn from
/// `Stream::new(seed, generation, Purpose::Trial, 0, trial)`.
pub trait Task: Send + Sync {
    /// The network shape the task drives.
    fn layout(&self) -> Layout;
    /// One fitness per network, each finite (and >= 0 under proportional selection).
    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>>;

    /// Whether `net` meets the task's success criterion on fresh conditions drawn from `seed`;
    /// `None` (the default) when the task has no criterion.
    fn succeeds(&self, net: &Network, seed: u64) -> Result<Option<bool>> {
        let _ = (net, seed);
        Ok(None)
    }

    /// Each network's [`Validation`] on the run's validation set, drawn from
    /// `Stream::new(seed, 0, Purpose::Validate, 0, t)` and so the same in every generation;
    /// `None` (the default) when the task has none. Must be a pure function of
    /// `(self, network, seed)` for each network, whatever the batch it comes in.
    fn validate(
        &self,
        networks: &[Network],
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        let _ = (networks, seed, cancel);
        Ok(None)
    }

    /// Each network's [`Validation`] on the same validation set as [`validate`](Self::validate),
    /// integrated [`STEP_CHECK_FINER`] times finer ([`Integrator::finer`](crate::Integrator::finer)):
    /// the step check of [`GaConfig::champion_step_check`]. `None` (the default) when the task
    /// has none. The same purity rule as `validate` holds.
    fn validate_finer(
        &self,
        networks: &[Network],
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        let _ = (networks, seed, cancel);
        Ok(None)
    }
}

/// `validations` when each is one a checkpoint can hold (a rate in [0, 1], a finite score), else
/// an error naming the first that is not: a task's validation is checked before the run keeps it.
fn checked(validations: Vec<Validation>) -> Result<Vec<Validation>> {
    match validations
        .iter()
        .find(|v| !(0.0..=1.0).contains(&v.rate) || !v.score.is_finite())
    {
        Some(bad) => Err(Error::Fitness(format!(
            "a validation gave rate {} and score {}; a rate lies in [0, 1] and a score is finite",
            bad.rate, bad.score
        ))),
        None => Ok(validations),
    }
}

/// Summary statistics of one generation's fitness.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    /// The generation these fitnesses belong to (0 is the initial population).
    pub generation: u64,
    /// Highest fitness.
    pub best: f64,
    /// Mean fitness.
    pub mean: f64,
    /// Population standard deviation of the fitness.
    pub std: f64,
    /// Lowest fitness.
    pub min: f64,
    /// Index of the best individual (the lowest index among ties).
    pub best_index: usize,
}

impl Stats {
    /// Statistics of `fitness` (finite values).
    ///
    /// # Panics
    /// If `fitness` is empty: a generation has at least one individual.
    pub fn of(generation: u64, fitness: &[f64]) -> Stats {
        assert!(
            !fitness.is_empty(),
            "Stats::of needs at least one fitness value"
        );
        let n = fitness.len() as f64;
        let mean = fitness.iter().sum::<f64>() / n;
        let var = fitness.iter().map(|f| (f - mean) * (f - mean)).sum::<f64>() / n;
        let mut best_index = 0;
        for (i, &f) in fitness.iter().enumerate() {
            if f > fitness[best_index] {
                best_index = i;
            }
        }
        Stats {
            generation,
            best: fitness[best_index],
            mean,
            std: var.sqrt(),
            min: fitness.iter().copied().fold(f64::INFINITY, f64::min),
            best_index,
        }
    }
}

/// The best individual seen so far.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Champion {
    /// Its genome.
    pub genes: Vec<f64>,
    /// Its fitness.
    pub fitness: f64,
    /// The generation in which it was scored.
    pub generation: u64,
    /// Its score on the validation set, when the champion was chosen by validation (absent in
    /// checkpoints written before validation existed).
    #[serde(default)]
    pub validation: Option<Validation>,
}

/// The validations of the last generation's candidates, by genome, so that a candidate carried
/// over unchanged (an elite) is not re-validated. Validation is a pure function of the genome, so
/// this changes speed, never results; it is not part of a checkpoint and never compared.
#[derive(Clone, Debug, Default)]
pub struct ValidationCache {
    /// At the run's integration step.
    run: HashMap<Vec<u64>, Validation>,
    /// At the step check's finer step ([`Task::validate_finer`]).
    finer: HashMap<Vec<u64>, Validation>,
}

impl PartialEq for ValidationCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

fn genome_key(genes: &[f64]) -> Vec<u64> {
    genes.iter().map(|g| g.to_bits()).collect()
}

/// How to fill the initial population beyond the given seed networks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Fill {
    /// Mutated copies of the seed networks, taken in turn (default).
    #[default]
    Mutants,
    /// Random individuals, as in an unseeded run.
    Random,
}

/// An evolution in progress: everything needed to continue it bit for bit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evolution {
    /// The GA settings.
    pub config: GaConfig,
    /// The genome layout.
    pub layout: Layout,
    /// The run's seed.
    pub seed: u64,
    /// The generation the current population belongs to.
    pub generation: u64,
    /// The current population, `population x layout.len()` row-major.
    pub population: Vec<f64>,
    /// The best individual scored so far: by validation when the task has a validation set and
    /// `config.validation_candidates > 0`, else by training fitness.
    pub champion: Option<Champion>,
    /// Validations of the last generation's candidates (not saved).
    #[serde(skip)]
    pub cache: ValidationCache,
}

impl Evolution {
    /// A new run: the initial population is drawn uniformly over the ranges, or seeded.
    ///
    /// With `seeds`, individual i < seeds.len() is seed i (its exact genome, which may be a
    /// composite made with [`compose`](crate::compose)); the rest are filled as `fill` says,
    /// mutants using the config's mutation rate.
    pub fn new(
        layout: Layout,
        config: GaConfig,
        seed: u64,
        seeds: &[Network],
        fill: Fill,
    ) -> Result<Self> {
        config.validate()?;
        layout.validate()?;
        check_population_size(layout, &config)?;
        let g = layout.len();
        let mut population = ga::initial_population(layout, &config, seed)?;
        if seeds.len() > config.population {
            return Err(Error::Config(format!(
                "{} seed networks do not fit in a population of {}",
                seeds.len(),
                config.population
            )));
        }
        let genomes: Vec<Vec<f64>> = seeds
            .iter()
            .enumerate()
            .map(|(k, net)| {
                let genes = genome::encode(net);
                if genes.len() != g {
                    return Err(Error::Config(format!(
                        "seed network {k} has N = {}, M = {}; the run needs N = {}, M = {}",
                        net.size(),
                        net.n_inputs(),
                        layout.size,
                        layout.n_inputs
                    )));
                }
                Ok(genes)
            })
            .collect::<Result<_>>()?;
        if !genomes.is_empty() {
            population
                .par_chunks_mut(g)
                .enumerate()
                .for_each(|(i, child)| {
                    if i < genomes.len() {
                        child.copy_from_slice(&genomes[i]);
                    } else if fill == Fill::Mutants {
                        child.copy_from_slice(&genomes[i % genomes.len()]);
                        let mut stream = Stream::new(seed, 0, Purpose::Seeding, i as u64, 0);
                        genome::mutate(
                            layout,
                            &config.ranges,
                            child,
                            config.mutation_rate,
                            config.mutation(),
                            &mut stream,
                        );
                    }
                });
        }
        Ok(Evolution {
            config,
            layout,
            seed,
            generation: 0,
            population,
            champion: None,
            cache: ValidationCache::default(),
        })
    }

    /// Decodes the current population.
    pub fn networks(&self) -> Result<Vec<Network>> {
        self.population
            .par_chunks(self.layout.len())
            .map(|genes| genome::decode(self.layout, genes))
            .collect()
    }

    /// Takes the fitness of the current population, updates the champion (by training fitness:
    /// fitness told from outside has no validation set), breeds the next population and advances
    /// the generation. Returns the statistics of the scored generation.
    pub fn tell(&mut self, fitness: &[f64]) -> Result<Stats> {
        self.check(fitness)?;
        self.tell_validated(fitness, None)
    }

    /// [`tell`](Self::tell) for fitness scored outside, with the champion chosen by validation
    /// as [`step`](Self::step) chooses it: `validate` scores the networks it is given (of the
    /// top `config.validation_candidates` by fitness, those the last generation did not already
    /// validate) on the caller's validation set, which must be the same at every generation.
    /// Each rate must lie in [0, 1] and each score be finite.
    pub fn tell_validating(
        &mut self,
        fitness: &[f64],
        mut validate: impl FnMut(&[Network]) -> Result<Vec<Validation>>,
    ) -> Result<Stats> {
        self.check(fitness)?;
        let nets = self.networks()?;
        let validated = self.validate_with(&nets, fitness, |batch| validate(batch).map(Some))?;
        self.tell_validated(fitness, validated.as_deref())
    }

    /// Checks that the state is consistent and that `fitness` fits the population and can be
    /// selected on.
    fn check(&self, fitness: &[f64]) -> Result<()> {
        self.check_consistent("the evolution's", Error::Config)?;
        if fitness.len() != self.config.population {
            return Err(Error::Fitness(format!(
                "got {} for a population of {}",
                crate::error::counted(fitness.len(), "fitness value"),
                self.config.population
            )));
        }
        check_fitness(fitness, self.config.selection)
    }

    /// [`tell`](Self::tell), with the champion chosen among `validated` (candidate index and its
    /// validation, best training fitness first) when given: the first candidate with the best
    /// validation becomes champion if it beats the champion's. The caller has run
    /// [`check`](Self::check) on `fitness`.
    fn tell_validated(
        &mut self,
        fitness: &[f64],
        validated: Option<&[(usize, Validation)]>,
    ) -> Result<Stats> {
        let stats = Stats::of(self.generation, fitness);
        let pick = match validated {
            None => self
                .champion
                .as_ref()
                .is_none_or(|c| stats.best > c.fitness)
                .then_some((stats.best_index, None)),
            Some(list) => {
                let mut best: Option<&(usize, Validation)> = None;
                for item in list {
                    if best.is_none_or(|b| item.1.beats(&b.1)) {
                        best = Some(item);
                    }
                }
                best.filter(|(_, v)| {
                    self.champion
                        .as_ref()
                        .and_then(|c| c.validation)
                        .is_none_or(|cv| v.beats(&cv))
                })
                .map(|&(i, v)| (i, Some(v)))
            }
        };
        if let Some((index, validation)) = pick {
            let g = self.layout.len();
            let at = index * g;
            self.champion = Some(Champion {
                genes: self.population[at..at + g].to_vec(),
                fitness: fitness[index],
                generation: self.generation,
                validation,
            });
        }
        self.population = ga::next_generation(
            &self.population,
            fitness,
            self.layout,
            &self.config,
            self.seed,
            self.generation,
        )?;
        self.generation += 1;
        Ok(stats)
    }

    /// Scores the current population with `task`, then [`tell`](Self::tell)s the result.
    /// Returns the statistics and the fitness values.
    pub fn step(
        &mut self,
        task: &dyn Task,
        cancel: Option<&AtomicBool>,
    ) -> Result<(Stats, Vec<f64>)> {
        if task.layout() != self.layout {
            return Err(Error::Config(format!(
                "the task drives networks with N = {}, M = {}; the run evolves N = {}, M = {}",
                task.layout().size,
                task.layout().n_inputs,
                self.layout.size,
                self.layout.n_inputs
            )));
        }
        let nets = self.networks()?;
        let fitness = task.evaluate(&nets, self.generation, self.seed, cancel)?;
        self.check(&fitness)?;
        let validated = match self.validate(task, &nets, &fitness, cancel)? {
            Some(list) if self.config.champion_step_check => {
                Some(self.step_check(task, &nets, list, cancel)?)
            }
            other => other,
        };
        let stats = self.tell_validated(&fitness, validated.as_deref())?;
        Ok((stats, fitness))
    }

    /// The top `config.validation_candidates` of `fitness` with their validations, best
    /// training fitness first; `None` when there are no candidates or the task has no validation
    /// set. Candidates the last generation validated are taken from the cache.
    fn validate(
        &mut self,
        task: &dyn Task,
        nets: &[Network],
        fitness: &[f64],
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<(usize, Validation)>>> {
        let seed = self.seed;
        self.validate_with(nets, fitness, |batch| task.validate(batch, seed, cancel))
    }

    /// [`validate`](Self::validate) with the validation set behind `scores`, which validates the
    /// networks it is given (None: there is no validation set).
    fn validate_with(
        &mut self,
        nets: &[Network],
        fitness: &[f64],
        mut scores: impl FnMut(&[Network]) -> Result<Option<Vec<Validation>>>,
    ) -> Result<Option<Vec<(usize, Validation)>>> {
        let chosen = candidates(fitness, self.config.validation_candidates);
        if chosen.is_empty() {
            return Ok(None);
        }
        let g = self.layout.len();
        let keys: Vec<Vec<u64>> = chosen
            .iter()
            .map(|&i| genome_key(&self.population[i * g..(i + 1) * g]))
            .collect();
        // Each genome once: not one the last generation validated, nor a copy of a candidate
        // before it (a GA's best are often copies of one parent).
        let mut asked = std::collections::HashSet::with_capacity(chosen.len());
        let fresh: Vec<usize> = (0..chosen.len())
            .filter(|&k| !self.cache.run.contains_key(&keys[k]) && asked.insert(&keys[k]))
            .collect();
        let batch: Vec<Network> = fresh.iter().map(|&k| nets[chosen[k]].clone()).collect();
        let scores = if batch.is_empty() {
            Vec::new()
        } else {
            match scores(&batch)? {
                Some(v) if v.len() == batch.len() => checked(v)?,
                Some(v) => {
                    return Err(Error::Fitness(format!(
                        "the task validated {}; it was given {}",
                        crate::error::counted(v.len(), "network"),
                        batch.len()
                    )))
                }
                None => return Ok(None),
            }
        };
        let mut cache = HashMap::with_capacity(chosen.len());
        for (k, v) in fresh.iter().zip(scores) {
            cache.insert(keys[*k].clone(), v);
        }
        let mut out = Vec::with_capacity(chosen.len());
        for (k, &i) in chosen.iter().enumerate() {
            let v = match cache.get(&keys[k]) {
                Some(v) => *v,
                None => self.cache.run[&keys[k]],
            };
            cache.insert(keys[k].clone(), v);
            out.push((i, v));
        }
        self.cache.run = cache;
        Ok(Some(out))
    }

    /// The step check ([`GaConfig::champion_step_check`]): of the `validated` candidates, the
    /// one whose [`worse`](Validation::worse) validation at the run's step and at the task's
    /// finer step is best and beats the champion's, alone with that validation; empty when none
    /// does. Candidates are checked best validation first, and only while their validation at
    /// the run's step could still win (the worse of two is never better than either), so a
    /// generation usually checks none or one.
    fn step_check(
        &mut self,
        task: &dyn Task,
        nets: &[Network],
        mut validated: Vec<(usize, Validation)>,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<(usize, Validation)>> {
        validated.sort_by(|a, b| {
            if a.1.beats(&b.1) {
                std::cmp::Ordering::Less
            } else if b.1.beats(&a.1) {
                std::cmp::Ordering::Greater
            } else {
                std::cmp::Ordering::Equal
            }
        });
        let g = self.layout.len();
        let mut bar = self.champion.as_ref().and_then(|c| c.validation);
        let mut chosen = Vec::new();
        let mut finer = HashMap::new();
        for (i, at_run_step) in validated {
            if bar.is_some_and(|b| !at_run_step.beats(&b)) {
                break;
            }
            let key = genome_key(&self.population[i * g..(i + 1) * g]);
            // A copy of a candidate checked before, this generation or the last, is not checked again.
            let at_finer_step = match finer.get(&key).or_else(|| self.cache.finer.get(&key)) {
                Some(v) => *v,
                None => self.validate_one_finer(task, &nets[i], cancel)?,
            };
            finer.insert(key, at_finer_step);
            let both = at_run_step.worse(&at_finer_step);
            if bar.is_none_or(|b| both.beats(&b)) {
                chosen = vec![(i, both)];
                bar = Some(both);
            }
        }
        self.cache.finer = finer;
        Ok(chosen)
    }

    /// `net`'s validation at the task's finer step; an error when the task has none.
    fn validate_one_finer(
        &self,
        task: &dyn Task,
        net: &Network,
        cancel: Option<&AtomicBool>,
    ) -> Result<Validation> {
        match task.validate_finer(std::slice::from_ref(net), self.seed, cancel)? {
            Some(v) if v.len() == 1 => Ok(checked(v)?[0]),
            Some(v) => Err(Error::Fitness(format!(
                "the task validated {} networks at the finer step; it was given 1",
                v.len()
            ))),
            None => Err(Error::Config(format!(
                "champion_step_check is on, but the task has no validation {STEP_CHECK_FINER}x \
                 finer to check champions with"
            ))),
        }
    }

    /// The champion as a network, if any generation has been scored.
    pub fn champion_network(&self) -> Result<Option<Network>> {
        self.champion
            .as_ref()
            .map(|c| genome::decode(self.layout, &c.genes))
            .transpose()
    }

    /// The whole state as JSON (floats exact).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("an evolution state always serialises")
    }

    /// Reads a state written by [`to_json`](Self::to_json), checking it is consistent: every
    /// genome of the population and the champion's decode to a network of the layout, and the
    /// champion was scored in a generation already run, with a validation rate in [0, 1] and a
    /// finite score. So a state that reads continues without an error the file caused.
    pub fn from_json(text: &str) -> Result<Self> {
        let evo: Evolution = serde_json::from_str(text)
            .map_err(|e| Error::Format(format!("not a valid checkpoint: {e}")))?;
        evo.check_consistent("checkpoint", Error::Format)?;
        Ok(evo)
    }

    /// Checks that the state is consistent, as [`from_json`](Self::from_json) and every
    /// [`tell`](Self::tell) do (the fields are public, so a caller may have changed them): the
    /// config and layout are valid, every genome of the population and the champion's decode to
    /// a network of the layout, and the champion was scored in a generation already run, with a
    /// validation rate in [0, 1] and a finite score. `what` names the state in the message, which
    /// `error` makes into an error.
    fn check_consistent(&self, what: &str, error: fn(String) -> Error) -> Result<()> {
        self.config.validate()?;
        self.layout.validate()?;
        check_population_size(self.layout, &self.config)?;
        if self.population.len() != self.config.population * self.layout.len() {
            return Err(error(format!(
                "{what} population has {} genes; expected {} x {}",
                self.population.len(),
                self.config.population,
                self.layout.len()
            )));
        }
        if self.generation == u64::MAX {
            return Err(error(format!(
                "{what} generation is {}; no generation can follow it",
                self.generation
            )));
        }
        let bad = |part: &str, e: Error| error(format!("{what} {part}: {}", crate::io::strip(e)));
        if let Some((i, e)) = self
            .population
            .chunks(self.layout.len())
            .enumerate()
            .find_map(|(i, genes)| {
                genome::check_genes(self.layout, genes)
                    .err()
                    .map(|e| (i, e))
            })
        {
            return Err(bad(&format!("population[{i}]"), e));
        }
        if let Some(c) = &self.champion {
            genome::check_genes(self.layout, &c.genes).map_err(|e| bad("champion", e))?;
            if !c.fitness.is_finite() {
                return Err(error(format!(
                    "{what} champion has fitness {}; a fitness is finite",
                    c.fitness
                )));
            }
            if c.generation >= self.generation {
                return Err(error(format!(
                    "{what} champion was scored in generation {}; the state is at generation \
                     {}, so it can only come from an earlier one",
                    c.generation, self.generation
                )));
            }
            if let Some(v) = c.validation {
                if !((0.0..=1.0).contains(&v.rate) && v.score.is_finite()) {
                    return Err(error(format!(
                        "{what} champion has validation rate {} and score {}; a rate lies in \
                         [0, 1] and a score is finite",
                        v.rate, v.score
                    )));
                }
            }
        }
        Ok(())
    }
}

/// The most genes a population may hold: 2^27, 1 GiB of `f64` (the breeding step holds two
/// such arrays).
pub const MAX_POPULATION_GENES: usize = 1 << 27;

/// Refuses a population too large to allocate, saying what it would need.
fn check_population_size(layout: Layout, config: &GaConfig) -> Result<()> {
    let genes = config.population.checked_mul(layout.len());
    match genes {
        Some(g) if g <= MAX_POPULATION_GENES => Ok(()),
        _ => Err(Error::Config(format!(
            "a population of {} networks of {} parameters needs {}; the limit is \
             {MAX_POPULATION_GENES} parameters (1 GiB)",
            config.population,
            layout.len(),
            genome::bytes(genes.map(|g| g as f64 * 8.0)),
        ))),
    }
}
