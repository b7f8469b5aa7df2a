//! Your own task in Rust: evolve a network whose first neuron oscillates, save the champion in
//! the network file format, load it back and find its equilibria.
//!
//! ```text
//! cargo run --release -p ctrnn --example own_task
//! ```
//!
//! A task is a [`Task`]: the network shape it drives and one fitness per network for a whole
//! generation. It must be a pure function of `(networks, generation, seed)`, which is what makes
//! a run reproducible to the bit, with any number of threads, and resumable from a checkpoint.
//! So anything random (here, the starting state of each trial) is drawn from a
//! [`Stream`] keyed by the seed, the generation and the trial, the same for every network.

use std::sync::atomic::AtomicBool;

use ctrnn::analysis::{equilibria, EquilibriumSearch};
use ctrnn::io::{self, NetworkFile};
use ctrnn::{
    Evolution, Fill, GaConfig, Integrator, Layout, Network, Purpose, Result, Selection, Stream,
    Task,
};

/// Trials per network per generation.
const TRIALS: u64 = 3;
/// Input rows per trial: 40 time units at the default step (dt 0.1).
const STEPS: usize = 400;

/// Reward a first neuron whose firing rate keeps swinging: the mean absolute change of its rate
/// per time unit over the second half of each trial, from a random starting state.
struct Oscillate;

impl Task for Oscillate {
    fn layout(&self) -> Layout {
        Layout {
            size: 3,
            n_inputs: 0,
        }
    }

    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        _cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        let integ = Integrator::default();
        networks
            .iter()
            .map(|net| {
                let mut total = 0.0;
                for trial in 0..TRIALS {
                    // The same starting states for every network of this generation.
                    let mut s = Stream::new(seed, generation, Purpose::Trial, 0, trial);
                    let start: Vec<f64> = (0..net.size()).map(|_| s.range(-2.0, 2.0)).collect();
                    let mut net = net.clone();
                    net.set_state(Some(&start))?;
                    total += swing(&mut net, &integ)?;
                }
                Ok(total / TRIALS as f64)
            })
            .collect()
    }
}

/// The mean absolute change per time unit of neuron 0's firing rate over the second half of a
/// trial of [`STEPS`] rows (no inputs).
fn swing(net: &mut Network, integ: &Integrator) -> Result<f64> {
    let n = net.size();
    let states = net.run(&[], STEPS, integ)?; // STEPS x N states, row by row
    let rate = |t: usize| 1.0 / (1.0 + (-(states[t * n] - net.theta()[0])).exp());
    let change: f64 = (STEPS / 2..STEPS)
        .map(|t| (rate(t) - rate(t - 1)).abs())
        .sum();
    Ok(change / (STEPS / 2) as f64 / (integ.dt * integ.substeps as f64))
}

fn main() -> Result<()> {
    let config = GaConfig {
        population: 60,
        selection: Selection::Rank,
        elitism: 2,
        ..GaConfig::default()
    };
    let seed = 1;
    let mut run = Evolution::new(Oscillate.layout(), config, seed, &[], Fill::Random)?;
    for _ in 0..40 {
        let (stats, _fitness) = run.step(&Oscillate, None)?;
        if stats.generation % 10 == 9 {
            println!(
                "generation {:>3}: best {:.4}, mean {:.4}",
                stats.generation, stats.best, stats.mean
            );
        }
    }
    // A checkpoint is the run's whole state as JSON; from_json continues it bit for bit.
    let again = Evolution::from_json(&run.to_json())?;
    assert_eq!(again.population, run.population);

    let champion = run.champion_network()?.expect("40 generations were scored");
    let path = std::env::temp_dir().join(format!("own-task-{}.json", std::process::id()));
    let mut file = NetworkFile::new(champion);
    file.integrator = Some(Integrator::default());
    file.meta.insert("task".into(), "oscillate".into());
    io::save(&path, &file)?;
    let loaded = io::load(&path)?;
    std::fs::remove_file(&path).ok();
    assert_eq!(loaded.network, file.network);

    let mut net = loaded.network;
    net.set_state(None)?; // from rest
    println!(
        "champion swing from rest: {:.4}",
        swing(&mut net, &Integrator::default())?
    );
    for e in equilibria(&net, &[], &EquilibriumSearch::default())? {
        println!("equilibrium at rates {:.3?}: {:?}", e.outputs, e.stability);
    }
    Ok(())
}
