//! The genetic algorithm of the paper (§2.2): selection, crossover and mutation for one generation.
//!
//! A population is a `P x G` row-major array of genomes (see [`crate::genome`] for the gene
//! order). [`next_generation`] turns the parents and their fitness into the children:
//!
//! 1. the first `elitism` children are exact copies of the best parents (off by default, as in the
//!    paper);
//! 2. every other child c draws only from its own stream,
//!    `Stream::new(seed, generation, Purpose::Reproduce, c, 0)`. With probability
//!    `crossover_rate` it selects two parents and a cut x uniform in `1..=N-1`, taking neurons
//!    `0..x` from the first and the rest from the second; otherwise it selects one parent and
//!    copies it. Then each gene is mutated with probability `mutation_rate` (a per-gene rate):
//!    resampled over its range (`mutation = "uniform"`, the paper's), or moved by a bell-shaped
//!    step of `mutation_scale` times its range's width (`mutation = "creep"`,
//!    [`genome::Mutation::Creep`]).
//!
//! Because no child shares randomness with another, children are built in parallel and the result
//! is the same bits for any number of threads.
//!
//! # Example
//! ```
//! use ctrnn::ga::{initial_population, next_generation, GaConfig};
//! use ctrnn::genome::Layout;
//! let layout = Layout { size: 2, n_inputs: 1 };
//! let config = GaConfig { population: 10, ..GaConfig::default() };
//! let parents = initial_population(layout, &config, 7)?;
//! let fitness: Vec<f64> = (0..10).map(|i| i as f64).collect();
//! let children = next_generation(&parents, &fitness, layout, &config, 7, 0)?;
//! assert_eq!(children.len(), parents.len());
//! # Ok::<(), ctrnn::Error>(())
//! ```

use std::fmt;
use std::str::FromStr;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::genome::{self, Layout, Mutation, Ranges};
use crate::rng::{Purpose, Stream};

/// How parents are chosen from the fitness values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Selection {
    /// Probability proportional to fitness, uniform when every fitness is 0 (the paper's).
    /// Needs every fitness >= 0.
    #[default]
    Proportional,
    /// Linear ranking: probability proportional to rank, worst = 1 and best = P. Any finite
    /// fitness is allowed; equal fitness ranks the lower index higher.
    Rank,
}

impl Selection {
    /// The lowercase name used in configs: `"proportional"` or `"rank"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Selection::Proportional => "proportional",
            Selection::Rank => "rank",
        }
    }
}

impl fmt::Display for Selection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for Selection {
    type Err = Error;

    /// Parses `"proportional"` or `"rank"`.
    fn from_str(s: &str) -> Result<Self> {
        crate::names::parse_name("selection", s).map_err(Error::Config)
    }
}

/// The settings of the genetic algorithm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GaConfig {
    /// Number of individuals P (at least 2). Default 100.
    pub population: usize,
    /// Probability that a child is made by crossover rather than by copying one parent, in [0, 1].
    /// Default 0.5.
    pub crossover_rate: f64,
    /// Probability that each gene of a child is mutated, in [0, 1]. Default 0.025.
    pub mutation_rate: f64,
    /// How a gene mutates. Default [`MutationKind::Uniform`], as in the paper.
    pub mutation: MutationKind,
    /// With [`MutationKind::Creep`], the step's standard deviation as a fraction of the gene's
    /// range, in (0, 1]. Default [`MUTATION_SCALE`].
    pub mutation_scale: f64,
    /// Number of best individuals copied unchanged into the next generation (below
    /// `population`). Default 0, as in the paper.
    pub elitism: usize,
    /// How parents are selected. Default [`Selection::Proportional`], as in the paper.
    pub selection: Selection,
    /// Intervals for the initial draw and for mutation. Default [`Ranges::default`].
    pub ranges: Ranges,
    /// How many of each generation's best individuals, by training fitness, are re-scored on the
    /// task's validation set to choose the champion ([`crate::validation`]); 0 chooses the
    /// champion by training fitness alone. Default 10; absent from a file (checkpoints written
    /// before validation existed), 0.
    #[serde(default)]
    pub validation_candidates: usize,
    /// Whether a candidate must also pass the task's finer validation to become champion
    /// ([`Task::validate_finer`](crate::Task::validate_finer)): its validation is then the worse
    /// of the two ([`crate::validation`]), so a network that is right only at the run's step is
    /// not chosen. Needs `validation_candidates > 0`. Default false; written only when true, so
    /// checkpoints without it read and write unchanged.
    #[serde(default, skip_serializing_if = "is_false")]
    pub champion_step_check: bool,
}

fn is_false(b: &bool) -> bool {
    !b
}

/// [`GaConfig::mutation_scale`]'s default: a creep step's standard deviation is 5% of the
/// gene's range (1.6 for the default weight range of width 32).
pub const MUTATION_SCALE: f64 = 0.05;

/// How a gene mutates: the names used in configs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MutationKind {
    /// Resampled uniformly over its range (the paper's).
    #[default]
    Uniform,
    /// Moved by a bell-shaped step scaled by `mutation_scale` ([`Mutation::Creep`]).
    Creep,
}

/// [`GaConfig::validation_candidates`]'s default.
pub const VALIDATION_CANDIDATES: usize = 10;

impl Default for GaConfig {
    fn default() -> Self {
        GaConfig {
            population: 100,
            crossover_rate: 0.5,
            mutation_rate: 0.025,
            mutation: MutationKind::Uniform,
            mutation_scale: MUTATION_SCALE,
            elitism: 0,
            selection: Selection::Proportional,
            ranges: Ranges::default(),
            validation_candidates: VALIDATION_CANDIDATES,
            champion_step_check: false,
        }
    }
}

impl GaConfig {
    /// The mutation operator these settings name.
    pub fn mutation(&self) -> Mutation {
        match self.mutation {
            MutationKind::Uniform => Mutation::Uniform,
            MutationKind::Creep => Mutation::Creep {
                scale: self.mutation_scale,
            },
        }
    }

    /// Checks every setting; the error names the setting, its value and what is allowed.
    ///
    /// # Example
    /// ```
    /// use ctrnn::ga::GaConfig;
    /// let bad = GaConfig { crossover_rate: 1.5, ..GaConfig::default() };
    /// assert_eq!(
    ///     bad.validate().unwrap_err().to_string(),
    ///     "invalid config: crossover_rate is 1.5; it must be in [0, 1]"
    /// );
    /// ```
    pub fn validate(&self) -> Result<()> {
        if self.population < 2 {
            return Err(Error::Config(format!(
                "population is {}; it must be at least 2",
                self.population
            )));
        }
        for (name, rate) in [
            ("crossover_rate", self.crossover_rate),
            ("mutation_rate", self.mutation_rate),
        ] {
            if !(rate.is_finite() && (0.0..=1.0).contains(&rate)) {
                return Err(Error::Config(format!(
                    "{name} is {rate}; it must be in [0, 1]"
                )));
            }
        }
        if !(self.mutation_scale.is_finite()
            && self.mutation_scale > 0.0
            && self.mutation_scale <= 1.0)
        {
            return Err(Error::Config(format!(
                "mutation_scale is {}; it must be in (0, 1]",
                self.mutation_scale
            )));
        }
        if self.champion_step_check && self.validation_candidates == 0 {
            return Err(Error::Config(
                "champion_step_check is on but validation_candidates is 0; the step check \
                 re-validates the validated candidates, so it needs validation_candidates >= 1"
                    .into(),
            ));
        }
        if self.elitism >= self.population {
            return Err(Error::Config(format!(
                "elitism is {}; it must be below population = {}",
                self.elitism, self.population
            )));
        }
        self.ranges.validate()
    }
}

/// Checks that `fitness` can be selected on: every value finite, and every value >= 0 for
/// proportional selection. Errors name the individual.
pub fn check_fitness(fitness: &[f64], selection: Selection) -> Result<()> {
    if let Some(i) = fitness.iter().position(|f| !f.is_finite()) {
        return Err(Error::Fitness(format!(
            "fitness of individual {i} is {}; every fitness must be finite",
            fitness[i]
        )));
    }
    if selection == Selection::Proportional {
        if let Some(i) = fitness.iter().position(|&f| f < 0.0) {
            return Err(Error::Fitness(format!(
                "fitness of individual {i} is {}; proportional selection needs every fitness \
                 >= 0 (use selection = \"rank\" for negative fitness)",
                fitness[i]
            )));
        }
    }
    Ok(())
}

/// Draws parent indices with fixed probabilities, built once per generation.
///
/// Holds the prefix sums of the selection weights; each draw is one uniform and a binary search.
#[derive(Clone, Debug)]
pub struct Selector {
    /// `cumulative[i]` = sum of the weights of individuals `0..=i`.
    cumulative: Vec<f64>,
    /// The last individual with a positive weight (guards against rounding at the top end).
    last: usize,
}

impl Selector {
    /// The selector for `fitness` under `selection`, after [`check_fitness`].
    ///
    /// Proportional: weight = fitness, or 1 for everyone when every fitness is 0.
    /// Rank: weight = rank, worst = 1 and best = P, equal fitness ranking the lower index higher.
    pub fn new(fitness: &[f64], selection: Selection) -> Result<Selector> {
        if fitness.is_empty() {
            return Err(Error::Fitness(
                "there are no fitness values; selection needs at least 1 individual".into(),
            ));
        }
        check_fitness(fitness, selection)?;
        let weights: Vec<f64> = match selection {
            Selection::Proportional => {
                if fitness.iter().all(|&f| f == 0.0) {
                    vec![1.0; fitness.len()]
                } else {
                    fitness.to_vec()
                }
            }
            Selection::Rank => {
                // Worst first; among equal fitness the higher index first, so it ranks lower.
                let mut order: Vec<usize> = (0..fitness.len()).collect();
                order.sort_by(|&a, &b| fitness[a].total_cmp(&fitness[b]).then(b.cmp(&a)));
                let mut w = vec![0.0; fitness.len()];
                for (rank0, &i) in order.iter().enumerate() {
                    w[i] = (rank0 + 1) as f64;
                }
                w
            }
        };
        let mut total = 0.0;
        let cumulative: Vec<f64> = weights
            .iter()
            .map(|w| {
                total += w;
                total
            })
            .collect();
        if !total.is_finite() {
            return Err(Error::Fitness(format!(
                "the fitness values sum to {total}; they are too large to select on"
            )));
        }
        let last = weights.iter().rposition(|&w| w > 0.0).unwrap_or(0);
        Ok(Selector { cumulative, last })
    }

    /// Draws one individual: a single uniform from `stream`, then a binary search.
    pub fn pick(&self, stream: &mut Stream) -> usize {
        let total = self.cumulative[self.cumulative.len() - 1];
        let u = stream.uniform() * total;
        // The first individual whose cumulative weight exceeds u; zero weights are never chosen.
        let i = self.cumulative.partition_point(|&c| c <= u);
        i.min(self.last)
    }

    /// The probability of picking each individual.
    pub fn probabilities(&self) -> Vec<f64> {
        let total = self.cumulative[self.cumulative.len() - 1];
        let mut prev = 0.0;
        self.cumulative
            .iter()
            .map(|&c| {
                let p = (c - prev) / total;
                prev = c;
                p
            })
            .collect()
    }
}

/// Indices of the `k` best individuals, best first; equal fitness puts the lower index first.
fn best_indices(fitness: &[f64], k: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..fitness.len()).collect();
    order.sort_by(|&a, &b| fitness[b].total_cmp(&fitness[a]).then(a.cmp(&b)));
    order.truncate(k);
    order
}

/// The initial population, `population x G` row-major: individual i is
/// [`genome::random`] drawn from `Stream::new(seed, 0, Purpose::Init, i, 0)`.
pub fn initial_population(layout: Layout, config: &GaConfig, seed: u64) -> Result<Vec<f64>> {
    config.validate()?;
    layout.validate()?;
    let g = layout.len();
    let mut genes = vec![0.0; config.population * g];
    genes.par_chunks_mut(g).enumerate().for_each(|(i, row)| {
        let mut stream = Stream::new(seed, 0, Purpose::Init, i as u64, 0);
        row.copy_from_slice(&genome::random(layout, &config.ranges, &mut stream));
    });
    Ok(genes)
}

/// Builds generation `generation + 1` from `parents` (`P x G` row-major, P = `config.population`)
/// and their `fitness`, returning the `P x G` children. See the module docs for the operators.
///
/// The result depends only on the arguments, not on the number of threads.
pub fn next_generation(
    parents: &[f64],
    fitness: &[f64],
    layout: Layout,
    config: &GaConfig,
    seed: u64,
    generation: u64,
) -> Result<Vec<f64>> {
    config.validate()?;
    layout.validate()?;
    let (p, g) = (config.population, layout.len());
    if fitness.len() != p {
        return Err(Error::InvalidArgument(format!(
            "fitness has {}; expected population = {p}",
            crate::error::counted(fitness.len(), "value")
        )));
    }
    if parents.len() != p * g {
        return Err(Error::InvalidArgument(format!(
            "parents has {}; expected population x genome length = {p} x {g} = {}",
            crate::error::counted(parents.len(), "value"),
            p * g
        )));
    }
    let selector = Selector::new(fitness, config.selection)?;
    let parent = |i: usize| &parents[i * g..(i + 1) * g];
    let per = layout.genes_per_neuron();

    let mut children = vec![0.0; p * g];
    let (elites, rest) = children.split_at_mut(config.elitism * g);
    for (row, best) in elites
        .chunks_exact_mut(g)
        .zip(best_indices(fitness, config.elitism))
    {
        row.copy_from_slice(parent(best));
    }
    rest.par_chunks_mut(g).enumerate().for_each(|(k, child)| {
        let c = config.elitism + k;
        let mut stream = Stream::new(seed, generation, Purpose::Reproduce, c as u64, 0);
        if stream.bernoulli(config.crossover_rate) {
            let a = selector.pick(&mut stream);
            let b = selector.pick(&mut stream);
            if layout.size == 1 {
                child.copy_from_slice(parent(a));
            } else {
                let x = stream.range_inclusive_int(1, layout.size as u64 - 1) as usize;
                let cut = x * per;
                child[..cut].copy_from_slice(&parent(a)[..cut]);
                child[cut..].copy_from_slice(&parent(b)[cut..]);
            }
        } else {
            child.copy_from_slice(parent(selector.pick(&mut stream)));
        }
        genome::mutate(
            layout,
            &config.ranges,
            child,
            config.mutation_rate,
            config.mutation(),
            &mut stream,
        );
    });
    Ok(children)
}
