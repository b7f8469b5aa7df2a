//! The integrated system of paper §4.2: a classifier network drives the first trial in an
//! environment; its output at the end of that trial (`>= 0.5` means landmark-near) picks the
//! near or the far goal-seeking network, which drives every later trial, its state persisting
//! from trial to trial.

use std::sync::atomic::AtomicBool;

use ctrnn::{Error, Network, Result};
use serde::Serialize;

use super::config::{Nav1dConfig, Objective};
use super::environment::Environment;
use super::task::{Nav1dTask, Record};
use super::world::Condition;

/// One subnetwork of the system: its task (which says which neurons are its motors) and itself.
#[derive(Clone, Debug)]
pub struct Part {
    /// The task the network was evolved on.
    pub task: Nav1dTask,
    /// The network.
    pub network: Network,
}

/// The classifier and the two goal seekers.
#[derive(Clone, Debug)]
pub struct System {
    classifier: Part,
    far: Part,
    near: Part,
    persist_state: bool,
}

/// One environment, as the system went through it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SystemEpisode {
    /// The environment type.
    pub environment: Environment,
    /// Each trial's world.
    pub conditions: Vec<Condition>,
    /// Whether each trial reached the goal.
    pub reached: Vec<bool>,
    /// The classifier's output at the end of the first trial.
    pub classification: f64,
    /// The environment the classifier took it for, which picked the network of the later trials.
    pub chosen: Environment,
}

/// The system judged on fresh environments.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SystemAssessment {
    /// Every environment.
    pub episodes: Vec<SystemEpisode>,
    /// The fraction of all trials that reached the goal.
    pub goal_rate: f64,
    /// The fraction of environments the classifier got right.
    pub classification_rate: f64,
}

/// The world fields every part must agree on.
fn same_world(a: &Nav1dConfig, b: &Nav1dConfig, which: &str) -> Result<()> {
    for (name, x, y) in [
        ("half_length", a.half_length, b.half_length),
        ("landmark_width", a.landmark_width, b.landmark_width),
        ("max_steps", a.max_steps as f64, b.max_steps as f64),
        (
            "reinforcement_steps",
            a.reinforcement_steps as f64,
            b.reinforcement_steps as f64,
        ),
    ] {
        if x != y {
            return Err(Error::Config(format!(
                "the {which} network's {name} is {y} but the classifier's is {x}; the parts \
                 must share one world"
            )));
        }
    }
    if a.world != b.world {
        return Err(Error::Config(format!(
            "the {which} network's world is {:?} but the classifier's is {:?}; the parts must \
             share one world",
            b.world.name(),
            a.world.name()
        )));
    }
    Ok(())
}

impl System {
    /// Assembles the system. The classifier's task gives the world (start, landmark, jitter);
    /// the parts must agree on its size and timing. The classifier's task must have a
    /// classifier neuron inside its network. Each part computes in its own task's precision, the
    /// one it was evolved in, so parts of different precisions may be composed: they share no
    /// state, and the classifier's output is read as a number.
    pub fn new(classifier: Part, far: Part, near: Part) -> Result<Self> {
        let c = classifier.task.config();
        if c.objective != Objective::Classify {
            return Err(Error::Config(format!(
                "the classifier network's task has objective {:?}; it must be \"classify\"",
                c.objective.name()
            )));
        }
        for (which, part, env) in [
            ("far", &far, Environment::Far),
            ("near", &near, Environment::Near),
        ] {
            let p = part.task.config();
            if p.objective != Objective::Goal || !p.environments.contains(&env) {
                return Err(Error::Config(format!(
                    "the {which} network's task has objective {:?} in environments {:?}; it must \
                     be \"goal\" in environments that include {which}",
                    p.objective.name(),
                    p.environments
                )));
            }
        }
        if c.classifier >= classifier.network.size() {
            return Err(Error::InvalidArgument(format!(
                "the classifier network has N = {} but its classifier neuron is {}",
                classifier.network.size(),
                c.classifier
            )));
        }
        same_world(c, far.task.config(), "far")?;
        same_world(c, near.task.config(), "near")?;
        Ok(System {
            classifier,
            far,
            near,
            persist_state: true,
        })
    }

    /// Whether the picked network's state persists from trial to trial (the paper's system, the
    /// default) or is reset at the start of each trial.
    pub fn persist_state(mut self, persist: bool) -> Self {
        self.persist_state = persist;
        self
    }

    fn part(&self, chosen: Environment) -> &Part {
        match chosen {
            Environment::Far => &self.far,
            Environment::Near => &self.near,
        }
    }

    /// Runs every chain (all of the same length, at least 1 trial): the classifier drives trial
    /// 1 from a reset state, and the network it picks drives the rest from a reset state of its
    /// own, which then persists (unless [`persist_state`](Self::persist_state) is off). Chains run
    /// in parallel.
    pub fn run(&self, chains: &[Vec<Condition>]) -> Result<Vec<SystemEpisode>> {
        self.run_cancellable(chains, None)
    }

    /// [`run`](Self::run) that stops with [`Error::Interrupted`] soon after `cancel` is set.
    pub fn run_cancellable(
        &self,
        chains: &[Vec<Condition>],
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<SystemEpisode>> {
        if chains
            .iter()
            .any(|c| c.is_empty() || c.len() != chains[0].len())
        {
            return Err(Error::InvalidArgument(
                "the chains must all have the same number of trials, at least 1".into(),
            ));
        }
        let firsts: Vec<Vec<Condition>> = chains.iter().map(|c| c[..1].to_vec()).collect();
        let first = self
            .classifier
            .task
            .episodes_of(&[&self.classifier.network], &firsts, cancel)?
            .concat();
        let chosen: Vec<Environment> = first
            .iter()
            .map(|e| {
                if e.classification[0] >= 0.5 {
                    Environment::Near
                } else {
                    Environment::Far
                }
            })
            .collect();
        let mut rest: Vec<Option<Vec<bool>>> = vec![None; chains.len()];
        for env in [Environment::Far, Environment::Near] {
            let picked: Vec<usize> = (0..chains.len()).filter(|&e| chosen[e] == env).collect();
            let tails: Vec<Vec<Condition>> =
                picked.iter().map(|&e| chains[e][1..].to_vec()).collect();
            let part = self.part(env);
            let k = chains[0].len() - 1;
            let reached: Vec<Vec<bool>> = if k == 0 {
                vec![vec![]; picked.len()]
            } else if self.persist_state {
                let episodes = part.task.episodes_of(&[&part.network], &tails, cancel)?;
                let episodes = episodes.concat();
                episodes.into_iter().map(|ep| ep.reached).collect()
            } else {
                let singles: Vec<Vec<Condition>> =
                    tails.iter().flatten().map(|c| vec![*c]).collect();
                let episodes = part.task.episodes_of(&[&part.network], &singles, cancel)?;
                let episodes = episodes.concat();
                let flat: Vec<bool> = episodes.iter().map(|ep| ep.reached[0]).collect();
                flat.chunks(k).map(<[bool]>::to_vec).collect()
            };
            for (&e, r) in picked.iter().zip(reached) {
                rest[e] = Some(r);
            }
        }
        Ok(chains
            .iter()
            .zip(first)
            .zip(chosen)
            .zip(rest)
            .map(|(((chain, first), chosen), rest)| SystemEpisode {
                environment: chain[0].environment,
                conditions: chain.clone(),
                reached: [first.reached, rest.unwrap_or_default()].concat(),
                classification: first.classification[0],
                chosen,
            })
            .collect())
    }

    /// Judges the system on `environments` fresh environments of `trials` trials each, drawn by
    /// the classifier's task ([`Nav1dTask::fresh_chains`]).
    pub fn assess(
        &self,
        environments: usize,
        trials: usize,
        seed: u64,
    ) -> Result<SystemAssessment> {
        self.assess_cancellable(environments, trials, seed, None)
    }

    /// [`assess`](Self::assess) that stops with [`Error::Interrupted`] soon after `cancel` is set.
    pub fn assess_cancellable(
        &self,
        environments: usize,
        trials: usize,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<SystemAssessment> {
        if environments == 0 || trials == 0 {
            return Err(Error::InvalidArgument(format!(
                "environments is {environments} and trials is {trials}; both must be >= 1"
            )));
        }
        let chains = self
            .classifier
            .task
            .fresh_chains(environments, trials, seed);
        let episodes = self.run_cancellable(&chains, cancel)?;
        let reached: usize = episodes
            .iter()
            .map(|e| e.reached.iter().filter(|&&r| r).count())
            .sum();
        let right = episodes
            .iter()
            .filter(|e| e.chosen == e.environment)
            .count();
        Ok(SystemAssessment {
            goal_rate: reached as f64 / (environments * trials) as f64,
            classification_rate: right as f64 / environments as f64,
            episodes,
        })
    }

    /// One chain, recorded: the classifier's first trial, and the picked network's later trials
    /// (empty for a chain of one trial).
    pub fn record(&self, chain: &[Condition]) -> Result<(Record, Record, Environment)> {
        let Some(first) = chain.first() else {
            return Err(Error::InvalidArgument(
                "the chain has no trials; the system needs at least 1".into(),
            ));
        };
        let c = &self.classifier;
        let a = c
            .task
            .record(&c.network, std::slice::from_ref(first), true)?;
        let chosen = if a.classification[0] >= 0.5 {
            Environment::Near
        } else {
            Environment::Far
        };
        let part = self.part(chosen);
        let b = if self.persist_state {
            part.task.record(&part.network, &chain[1..], true)?
        } else {
            let mut joined: Option<Record> = None;
            for c in &chain[1..] {
                let r = part
                    .task
                    .record(&part.network, std::slice::from_ref(c), true)?;
                joined = Some(match joined {
                    None => r,
                    Some(j) => j.then(r),
                });
            }
            match joined {
                Some(j) => j,
                None => part.task.record(&part.network, &[], true)?,
            }
        };
        Ok((a, b, chosen))
    }
}
