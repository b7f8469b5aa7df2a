//! The generation loop's state: a population, its generation counter and its champion, with
//! ask/tell, a [`Task`] trait for built-in fitness functions, and checkpoints.
//!
//! One generation is: decode the genomes, score them all with a task (or with fitness told from
//! outside), record the statistics and the champion, then breed the next population with
//! [`crate::ga::next_generation`]. Every random draw comes from a stream keyed by the run's seed
//! and the generation, so a run resumed from a checkpoint continues with exactly the same bits.

use std::sync::atomic::AtomicBool;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::ga::{self, check_fitness, GaConfig};
use crate::genome::{self, Layout};
use crate::network::Network;
use crate::rng::{Purpose, Stream};

/// A fitness function that scores a whole generation at once, so that it can drive the
/// population integrator.
///
/// `evaluate` must be a pure function of `(self, networks, generation, seed)`: that is what makes
/// runs reproducible, resumable, and shardable across machines. By default every individual of a
/// generation meets the same trial conditions (common random numbers), drawn from
/// `Stream::new(seed, generation, Purpose::Trial, 0, trial)`.
pub trait Task: Send + Sync {
    /// The network shape the task drives.
    fn layout(&self) -> Layout;
    /// One fitness per network, each finite and >= 0.
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
    /// Statistics of `fitness` (non-empty, finite).
    pub fn of(generation: u64, fitness: &[f64]) -> Stats {
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
    /// The best individual scored so far.
    pub champion: Option<Champion>,
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
        })
    }

    /// Decodes the current population.
    pub fn networks(&self) -> Result<Vec<Network>> {
        self.population
            .par_chunks(self.layout.len())
            .map(|genes| genome::decode(self.layout, genes))
            .collect()
    }

    /// Takes the fitness of the current population, updates the champion, breeds the next
    /// population and advances the generation. Returns the statistics of the scored generation.
    pub fn tell(&mut self, fitness: &[f64]) -> Result<Stats> {
        if fitness.len() != self.config.population {
            return Err(Error::Fitness(format!(
                "got {} fitness values for a population of {}",
                fitness.len(),
                self.config.population
            )));
        }
        check_fitness(fitness, self.config.selection)?;
        let stats = Stats::of(self.generation, fitness);
        if self
            .champion
            .as_ref()
            .is_none_or(|c| stats.best > c.fitness)
        {
            let g = self.layout.len();
            let at = stats.best_index * g;
            self.champion = Some(Champion {
                genes: self.population[at..at + g].to_vec(),
                fitness: stats.best,
                generation: self.generation,
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
        let stats = self.tell(&fitness)?;
        Ok((stats, fitness))
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

    /// Reads a state written by [`to_json`](Self::to_json), checking it is consistent.
    pub fn from_json(text: &str) -> Result<Self> {
        let evo: Evolution = serde_json::from_str(text)
            .map_err(|e| Error::Format(format!("not a valid checkpoint: {e}")))?;
        evo.config.validate()?;
        evo.layout.validate()?;
        if evo.population.len() != evo.config.population * evo.layout.len() {
            return Err(Error::Format(format!(
                "checkpoint population has {} genes; expected {} x {}",
                evo.population.len(),
                evo.config.population,
                evo.layout.len()
            )));
        }
        Ok(evo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fitness: how close neuron 0's firing rate is to 1 after a short run from rest.
    struct Excite;
    impl Task for Excite {
        fn layout(&self) -> Layout {
            Layout {
                size: 2,
                n_inputs: 1,
            }
        }
        fn evaluate(
            &self,
            networks: &[Network],
            _generation: u64,
            _seed: u64,
            _cancel: Option<&AtomicBool>,
        ) -> Result<Vec<f64>> {
            networks
                .iter()
                .map(|n| {
                    let mut n = n.clone();
                    n.run(&[1.0; 5], 5, &crate::Integrator::default())?;
                    Ok(n.outputs()[0])
                })
                .collect()
        }
    }

    fn config() -> GaConfig {
        GaConfig {
            population: 40,
            ..GaConfig::default()
        }
    }

    #[test]
    fn fitness_improves_and_champion_is_kept() {
        let mut evo = Evolution::new(Excite.layout(), config(), 5, &[], Fill::Mutants).unwrap();
        let first = evo.step(&Excite, None).unwrap().0;
        for _ in 0..10 {
            evo.step(&Excite, None).unwrap();
        }
        let champ = evo.champion.clone().unwrap();
        assert!(champ.fitness >= first.best);
        assert_eq!(evo.generation, 11);
    }

    #[test]
    fn checkpoint_resume_is_identical() {
        let mut a = Evolution::new(Excite.layout(), config(), 9, &[], Fill::Mutants).unwrap();
        for _ in 0..3 {
            a.step(&Excite, None).unwrap();
        }
        let mut b = Evolution::from_json(&a.to_json()).unwrap();
        for _ in 0..3 {
            a.step(&Excite, None).unwrap();
            b.step(&Excite, None).unwrap();
        }
        assert_eq!(a, b);
        for (x, y) in a.population.iter().zip(&b.population) {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }

    #[test]
    fn seeding_places_seeds_and_fills() {
        let layout = Excite.layout();
        let net = Network::new(
            vec![1.0, 2.0],
            vec![0.0; 2],
            vec![0.0; 4],
            vec![1.0, 1.0],
            None,
        )
        .unwrap();
        let g = layout.len();
        let evo = Evolution::new(
            layout,
            config(),
            1,
            std::slice::from_ref(&net),
            Fill::Mutants,
        )
        .unwrap();
        assert_eq!(&evo.population[..g], genome::encode(&net).as_slice());
        let close = evo.population[g..]
            .chunks(g)
            .filter(|c| *c == genome::encode(&net).as_slice())
            .count();
        assert!(
            close > 0,
            "with mutation 0.025 some mutants are exact copies"
        );
        let evo = Evolution::new(
            layout,
            config(),
            1,
            std::slice::from_ref(&net),
            Fill::Random,
        )
        .unwrap();
        assert!(evo.population[g..]
            .chunks(g)
            .all(|c| c != genome::encode(&net).as_slice()));
        let wrong = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![0.0], None).unwrap();
        assert!(Evolution::new(layout, config(), 1, &[wrong], Fill::Mutants).is_err());
    }

    #[test]
    fn tell_rejects_nan_and_wrong_length() {
        let mut evo = Evolution::new(Excite.layout(), config(), 1, &[], Fill::Mutants).unwrap();
        let mut f = vec![0.5; 40];
        f[7] = f64::NAN;
        assert!(evo
            .tell(&f)
            .unwrap_err()
            .to_string()
            .contains("individual 7"));
        assert!(evo.tell(&[0.5; 3]).is_err());
        assert_eq!(evo.generation, 0);
    }
}
