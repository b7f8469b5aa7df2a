//! The one-dimensional navigation task: its trial conditions, the fitness of a generation, a
//! recorded chain of trials for figures, and the success assessment on fresh conditions.

use std::sync::atomic::AtomicBool;

use ctrnn::{
    Elem, Error, Lanes, Layout, Network, Purpose, Result, Stream, Task, Validation, LANES,
};
use serde::Serialize;

use super::config::{Nav1dConfig, Objective};
use super::environment::Environment;
use super::world::{run_chains, Condition, Side};
use crate::common::{check_inputs, config_from_params, in_precision, lane_state};
use crate::lanes::{by_block, by_pair, pairs};
use crate::Aggregate;

/// The fraction of scored trials a network must get right on fresh conditions to have solved its
/// objective.
pub const SUCCESS_RATE: f64 = 0.95;

/// Fresh chains a run uses to check whether its champion has succeeded yet (`dnnevo sweep`'s
/// "first success" generation). `dnnevo evaluate` uses as many as asked.
pub const SUCCESS_CHAINS: usize = 40;

/// The one-dimensional navigation task: a validated [`Nav1dConfig`].
#[derive(Clone, Debug, PartialEq)]
pub struct Nav1dTask {
    config: Nav1dConfig,
}

/// One chain of trials in one environment, as it went.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Episode {
    /// The environment type.
    pub environment: Environment,
    /// Each trial's world.
    pub conditions: Vec<Condition>,
    /// Whether each trial reached the goal.
    pub reached: Vec<bool>,
    /// The classifier's output at the end of each trial's reinforcement period.
    pub classification: Vec<f64>,
}

/// A network judged on fresh conditions.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Assessment {
    /// What was scored.
    pub objective: Objective,
    /// Every chain.
    pub episodes: Vec<Episode>,
    /// The fraction of scored trials done right: the goal reached (`goal`; trials 2.. with
    /// `single`) or the environment classified right (`classify`).
    pub rate: f64,
    /// The rate success needs, [`SUCCESS_RATE`].
    pub required: f64,
    /// Whether `rate >= required`.
    pub success: bool,
}

/// One chain of one network, time step by time step (all of length T; `outputs` is T x N).
///
/// Time steps are counted from the start of each trial's moving phase and of its reinforcement
/// period. The moving phase of the continuous world can end inside a time step; that partial time
/// step is the phase's last entry, so a trial that moves for `s` time steps (a fraction counts as
/// one) has `s + reinforcement_steps` entries. Outcomes come from every integration step, not
/// from these samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Record {
    /// Each trial's world.
    pub conditions: Vec<Condition>,
    /// The agent's position after each time step.
    pub x: Vec<f64>,
    /// The landmark input during each time step: the fraction of its integration steps that
    /// read 1 (in the stepped world, 0 or 1).
    pub landmark: Vec<f64>,
    /// The reinforcement input during each time step.
    pub reinforcement: Vec<f64>,
    /// Every neuron's firing rate after each time step.
    pub outputs: Vec<Vec<f64>>,
    /// The trial each time step belongs to.
    pub trial: Vec<usize>,
    /// Whether the agent was moving (false during the reinforcement period).
    pub moving: Vec<bool>,
    /// Whether each trial reached the goal.
    pub reached: Vec<bool>,
    /// The classifier's output at the end of each trial.
    pub classification: Vec<f64>,
    /// The state after the last time step.
    pub final_state: Vec<f64>,
}

impl Record {
    /// This record followed by `next`, whose trials are renumbered to come after this one's.
    pub fn then(mut self, next: Record) -> Record {
        let offset = self.conditions.len();
        self.conditions.extend(next.conditions);
        self.x.extend(next.x);
        self.landmark.extend(next.landmark);
        self.reinforcement.extend(next.reinforcement);
        self.outputs.extend(next.outputs);
        self.trial.extend(next.trial.iter().map(|t| t + offset));
        self.moving.extend(next.moving);
        self.reached.extend(next.reached);
        self.classification.extend(next.classification);
        self.final_state = next.final_state;
        self
    }
}

/// The sides in the order the fixed trial sets list them.
const SIDES: [Side; 2] = [Side::Left, Side::Right];

fn side(stream: &mut Stream) -> Side {
    if stream.bernoulli(0.5) {
        Side::Right
    } else {
        Side::Left
    }
}

impl Nav1dTask {
    /// The task for `config`, which is validated.
    pub fn new(config: Nav1dConfig) -> Result<Self> {
        config.validate()?;
        Ok(Nav1dTask { config })
    }

    /// The task from a JSON object of [`Nav1dConfig`] fields (`null` means all defaults).
    pub fn from_params(params: &serde_json::Value) -> Result<Self> {
        Nav1dTask::new(config_from_params("nav1d", params)?)
    }

    /// The config.
    pub fn config(&self) -> &Nav1dConfig {
        &self.config
    }

    /// Trials per chain of the success check: `trials_per_environment` with `single` or a
    /// `chained` goal task, else 1.
    pub fn chain_len(&self) -> usize {
        match self.config.objective {
            Objective::Single => self.config.trials_per_environment,
            Objective::Goal if self.config.chained => self.config.trials_per_environment,
            _ => 1,
        }
    }

    /// The chains every individual of `generation` runs (common random numbers).
    ///
    /// - `goal` and `classify`: for each environment in `environments`, a goal-left then a
    ///   goal-right trial, each a chain of its own; chain `t` draws its jitter from
    ///   `Stream::new(seed, generation, Purpose::Trial, 0, t)`. A `chained` goal task runs, for
    ///   each environment, the chains (left, right) and (right, left) instead, each trial's
    ///   jitter drawn in turn from its chain's stream.
    /// - `single`: for each environment, `chains_per_environment` chains; each trial of chain `t`
    ///   draws its goal side (right with probability 1/2), then its jitter, from that stream.
    pub fn chains(&self, seed: u64, generation: u64) -> Vec<Vec<Condition>> {
        let c = &self.config;
        let stream = |t: usize| Stream::new(seed, generation, Purpose::Trial, 0, t as u64);
        match c.objective {
            Objective::Goal if c.chained => c
                .environments
                .iter()
                .flat_map(|&env| [(env, SIDES), (env, [SIDES[1], SIDES[0]])])
                .enumerate()
                .map(|(t, (env, goals))| {
                    let mut s = stream(t);
                    goals
                        .iter()
                        .map(|&goal| Condition::drawn(c, env, goal, &mut s))
                        .collect()
                })
                .collect(),
            Objective::Goal | Objective::Classify => c
                .environments
                .iter()
                .flat_map(|&env| SIDES.map(|goal| (env, goal)))
                .enumerate()
                .map(|(t, (env, goal))| vec![Condition::drawn(c, env, goal, &mut stream(t))])
                .collect(),
            Objective::Single => c
                .environments
                .iter()
                .flat_map(|&env| std::iter::repeat_n(env, c.chains_per_environment))
                .enumerate()
                .map(|(t, env)| {
                    let mut s = stream(t);
                    (0..c.trials_per_environment)
                        .map(|_| {
                            let goal = side(&mut s);
                            Condition::drawn(c, env, goal, &mut s)
                        })
                        .collect()
                })
                .collect(),
        }
    }

    /// `count` fresh chains of `trials` trials for assessments, chain `e` drawn from
    /// `Stream::new(seed, 0, Purpose::Evaluate, 0, e)`: its environment uniformly from
    /// `environments`, then for each trial its goal side and jitter.
    pub fn fresh_chains(&self, count: usize, trials: usize, seed: u64) -> Vec<Vec<Condition>> {
        self.chains_from(Purpose::Evaluate, count, trials, seed)
    }

    /// [`fresh_chains`](Self::fresh_chains) drawn from `purpose`'s streams.
    pub fn chains_from(
        &self,
        purpose: Purpose,
        count: usize,
        trials: usize,
        seed: u64,
    ) -> Vec<Vec<Condition>> {
        let c = &self.config;
        (0..count)
            .map(|e| {
                let mut s = Stream::new(seed, 0, purpose, 0, e as u64);
                let env = c.environments[s.below(c.environments.len() as u64) as usize];
                (0..trials)
                    .map(|_| {
                        let goal = side(&mut s);
                        Condition::drawn(c, env, goal, &mut s)
                    })
                    .collect()
            })
            .collect()
    }

    /// Trial `t` of a chain, judged: its score and whether it was done right, or `None` for a
    /// trial the objective does not score (the first trial with `single`).
    pub fn judge(
        &self,
        t: usize,
        condition: &Condition,
        reached: bool,
        classification: f64,
    ) -> Option<(f64, bool)> {
        let goal = f64::from(u8::from(reached));
        let classified = match condition.environment {
            Environment::Near => (classification, classification >= 0.5),
            Environment::Far => (1.0 - classification, classification < 0.5),
        };
        match self.config.objective {
            Objective::Goal => Some((goal, reached)),
            Objective::Single => {
                let w = self.config.classify_weight;
                (t > 0).then_some(((1.0 - w) * goal + w * classified.0, reached))
            }
            Objective::Classify => Some(classified),
        }
    }

    /// The fitness of every network in `generation`: the mean score over the scored trials of
    /// [`chains`](Self::chains), or, as `aggregate` says, the worst environment type's mean
    /// score; with `sharing`, of the shared scores (see [`Nav1dConfig::sharing`]). Blocks of
    /// [`LANES`] networks run in parallel. Stops with [`Error::Interrupted`] between chains once
    /// `cancel` is set.
    pub fn scores(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        self.check(networks)?;
        if networks.is_empty() {
            return Ok(vec![]);
        }
        let chains = self.chains(seed, generation);
        let types = &self.config.environments;
        let type_of = |chain: &[Condition]| types.iter().position(|&e| e == chain[0].environment);
        // The environment type of each scored trial, in the order the chains run them.
        let trial_types: Vec<usize> = chains
            .iter()
            .flat_map(|chain| {
                let of_type = type_of(chain).unwrap_or(0);
                (0..chain.len())
                    .filter(|&t| self.judge(t, &chain[t], false, 0.0).is_some())
                    .map(move |_| of_type)
            })
            .collect();
        let scores = in_precision!(self.config.precision, E => by_block::<E, _, _>(
            networks,
            chains.len(),
            cancel,
            |len| vec![(Vec::with_capacity(trial_types.len()), 0usize); len],
            |scores, _, block, c| {
                let chain = &chains[c];
                let outcome = run_chains(
                    &self.config,
                    block,
                    [chain.as_slice(); LANES],
                    true,
                    |_, _, _| {},
                )?;
                for (t, condition) in chain.iter().enumerate() {
                    for (l, (lane, near_first)) in scores.iter_mut().enumerate() {
                        let (r, c) = (outcome.reached[t][l], outcome.classification[t][l]);
                        if let Some((score, _)) = self.judge(t, condition, r, c) {
                            lane.push(score);
                        }
                        if t == 0 && r && condition.environment == Environment::Near {
                            *near_first += 1;
                        }
                    }
                }
                Ok(())
            },
            |scores| scores,
        ))?;
        let (mut scores, near_first): (Vec<Vec<f64>>, Vec<usize>) = scores.into_iter().unzip();
        if self.config.sharing {
            share(&mut scores);
        }
        let aggregate = self.config.aggregate;
        let near_chains = chains
            .iter()
            .filter(|chain| chain[0].environment == Environment::Near)
            .count();
        let bonus = |reached: usize| match (self.config.near_first_weight, near_chains) {
            (w, n) if w > 0.0 && n > 0 => w * reached as f64 / n as f64,
            _ => 0.0,
        };
        Ok(scores
            .iter()
            .zip(near_first)
            .map(|(s, n)| fitness(s, &trial_types, types.len(), aggregate) + bonus(n))
            .collect())
    }

    /// Runs `net` through each of `chains` (all of the same length), [`LANES`] chains at a time in
    /// parallel, each from a reset state.
    pub fn episodes(&self, net: &Network, chains: &[Vec<Condition>]) -> Result<Vec<Episode>> {
        Ok(self.episodes_of(&[net], chains, None)?.concat())
    }

    /// [`episodes`](Self::episodes) of every network of `nets` (`out[network][chain]`):
    /// (network, chain) pairs run [`LANES`] at a time in parallel; a lane's results do not
    /// depend on its neighbours.
    pub(crate) fn episodes_of(
        &self,
        nets: &[&Network],
        chains: &[Vec<Condition>],
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<Vec<Episode>>> {
        for net in nets {
            self.check(std::slice::from_ref(*net))?;
        }
        let Some(first) = chains.first() else {
            return Ok(vec![vec![]; nets.len()]);
        };
        if let Some(e) = chains.iter().position(|c| c.len() != first.len()) {
            return Err(Error::InvalidArgument(format!(
                "chain {e} has {} trials and chain 0 has {}; every chain must have as many",
                chains[e].len(),
                first.len()
            )));
        }
        let pairs = pairs(nets.len(), chains.len());
        let groups: Vec<&[(usize, usize)]> = pairs.chunks(LANES).collect();
        let episodes = in_precision!(self.config.precision, E => by_pair::<E, _>(nets, &groups, cancel, |lanes, lane_pairs, len| {
            let lane_chains = lane_pairs.map(|(_, e)| chains[e].as_slice());
            let outcome = run_chains(&self.config, lanes, lane_chains, true, |_, _, _| {})?;
            Ok(lane_pairs[..len]
                .iter()
                .enumerate()
                .map(|(l, &(_, e))| {
                    let chain = &chains[e];
                    Episode {
                        environment: chain.first().map_or(Environment::Far, |c| c.environment),
                        conditions: chain.clone(),
                        reached: outcome.reached.iter().map(|r| r[l]).collect(),
                        classification: outcome.classification.iter().map(|c| c[l]).collect(),
                    }
                })
                .collect())
        }))?;
        Ok(episodes
            .chunks(chains.len())
            .map(<[Episode]>::to_vec)
            .collect())
    }

    /// The mean score of the scored trials of `episodes` (0 when none is scored).
    fn mean_score(&self, episodes: &[Episode]) -> f64 {
        let (mut total, mut scored) = (0.0, 0usize);
        for ep in episodes {
            for (t, c) in ep.conditions.iter().enumerate() {
                if let Some((score, _)) = self.judge(t, c, ep.reached[t], ep.classification[t]) {
                    scored += 1;
                    total += score;
                }
            }
        }
        if scored == 0 {
            0.0
        } else {
            total / scored as f64
        }
    }

    /// The fraction of scored trials of `episodes` done right (0 when none is scored).
    pub fn rate(&self, episodes: &[Episode]) -> f64 {
        let (mut right, mut scored) = (0usize, 0usize);
        for ep in episodes {
            for (t, c) in ep.conditions.iter().enumerate() {
                if let Some((_, ok)) = self.judge(t, c, ep.reached[t], ep.classification[t]) {
                    scored += 1;
                    right += usize::from(ok);
                }
            }
        }
        if scored == 0 {
            0.0
        } else {
            right as f64 / scored as f64
        }
    }

    /// Judges `net` on `chains` fresh chains of [`chain_len`](Self::chain_len) trials from
    /// [`fresh_chains`](Self::fresh_chains): it succeeds when at least [`SUCCESS_RATE`] of the
    /// scored trials are done right.
    pub fn assess(&self, net: &Network, chains: usize, seed: u64) -> Result<Assessment> {
        self.assess_cancellable(net, chains, seed, None)
    }

    /// [`assess`](Self::assess) that stops with [`Error::Interrupted`] soon after `cancel` is set.
    pub fn assess_cancellable(
        &self,
        net: &Network,
        chains: usize,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Assessment> {
        if chains == 0 {
            return Err(Error::InvalidArgument(
                "chains is 0; assessing needs at least 1".into(),
            ));
        }
        let fresh = self.fresh_chains(chains, self.chain_len(), seed);
        let episodes = self.episodes_of(&[net], &fresh, cancel)?.concat();
        let rate = self.rate(&episodes);
        Ok(Assessment {
            objective: self.config.objective,
            episodes,
            rate,
            required: SUCCESS_RATE,
            success: rate >= SUCCESS_RATE,
        })
    }

    /// Runs `net` through `chain`, recorded time step by time step. With `reset` the state starts
    /// at 0; otherwise it continues from `net`'s state. Bit-identical to the evaluation.
    pub fn record(&self, net: &Network, chain: &[Condition], reset: bool) -> Result<Record> {
        self.check(std::slice::from_ref(net))?;
        let h = self.config.half_length;
        for (t, c) in chain.iter().enumerate() {
            if !(c.start.is_finite() && c.start.abs() < h && c.landmark.is_finite()) {
                return Err(Error::InvalidArgument(format!(
                    "conditions[{t}] has start {} and landmark {}; the start must lie strictly \
                     inside (-{h}, {h}) and both must be finite",
                    c.start, c.landmark
                )));
            }
        }
        let n = net.size();
        let mut rec = Record {
            conditions: chain.to_vec(),
            x: vec![],
            landmark: vec![],
            reinforcement: vec![],
            outputs: vec![],
            trial: vec![],
            moving: vec![],
            reached: vec![],
            classification: vec![],
            final_state: vec![0.0; n],
        };
        // The landmark input summed over the ticks of the time step so far, and their count.
        let (mut landmark, mut ticks) = (0.0, 0usize);
        let outcome = in_precision!(self.config.precision, E => {
        let mut lanes = Lanes::<1, E>::new(&[net])?;
        let outcome = run_chains(
            &self.config,
            &mut lanes,
            [chain],
            reset,
            |inputs, outputs, lanes| {
                let tick = lanes.get(0);
                landmark += inputs[0][0] * lanes.count as f64;
                ticks += lanes.count;
                if !tick.closes {
                    return;
                }
                rec.x.push(tick.x);
                rec.landmark.push(landmark / ticks as f64);
                rec.reinforcement.push(inputs.get(1).map_or(0.0, |r| r[0]));
                rec.outputs.push(outputs.iter().map(|o| o[0].to_f64()).collect());
                rec.trial.push(tick.trial);
                rec.moving.push(tick.moving);
                (landmark, ticks) = (0.0, 0);
            },
        )
        .map_err(|d| d.error(|_| 0))?;
        rec.final_state = lane_state(&lanes);
        outcome
        });
        rec.reached = outcome.reached.iter().map(|r| r[0]).collect();
        rec.classification = outcome.classification.iter().map(|c| c[0]).collect();
        Ok(rec)
    }

    /// Checks that every network has the task's size constraints and sensors.
    fn check(&self, networks: &[Network]) -> Result<()> {
        let c = &self.config;
        let what = if c.reinforcement_input {
            "landmark, reinforcement"
        } else {
            "landmark"
        };
        check_inputs(networks, c.n_inputs(), what)?;
        let mut needed = c.left_motor.max(c.right_motor);
        if c.objective != Objective::Goal {
            needed = needed.max(c.classifier);
        }
        if let Some(p) = networks.iter().position(|net| net.size() <= needed) {
            return Err(Error::InvalidArgument(format!(
                "network {p} has N = {} neurons; this task reads neuron {needed}, so N must be \
                 at least {}",
                networks[p].size(),
                needed + 1
            )));
        }
        Ok(())
    }
}

impl Task for Nav1dTask {
    fn layout(&self) -> Layout {
        Layout {
            size: self.config.size,
            n_inputs: self.config.n_inputs(),
        }
    }

    /// The fitness of [`Nav1dTask::scores`].
    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        self.scores(networks, generation, seed, cancel)
    }

    /// [`Nav1dTask::assess`] with [`SUCCESS_CHAINS`] chains.
    fn succeeds(&self, net: &Network, seed: u64) -> Result<Option<bool>> {
        Ok(Some(self.assess(net, SUCCESS_CHAINS, seed)?.success))
    }

    /// Each network on `validation_chains` chains drawn as in
    /// [`fresh_chains`](Nav1dTask::fresh_chains) from [`Purpose::Validate`]: the rate of scored
    /// trials done right and their mean score.
    fn validate(
        &self,
        networks: &[Network],
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        let chains = self.chains_from(
            Purpose::Validate,
            self.config.validation_chains,
            self.chain_len(),
            seed,
        );
        let refs: Vec<&Network> = networks.iter().collect();
        let episodes = self.episodes_of(&refs, &chains, cancel)?;
        Ok(Some(
            episodes
                .iter()
                .map(|eps| Validation {
                    rate: self.rate(eps),
                    score: self.mean_score(eps),
                })
                .collect(),
        ))
    }
}

/// One network's fitness from its scores on the scored trials (of environment type
/// `trial_types[k]`, one of `types`): their mean, combined as `aggregate` says with the worst
/// type's mean (types without a scored trial are left out).
fn fitness(scores: &[f64], trial_types: &[usize], types: usize, aggregate: Aggregate) -> f64 {
    let overall = scores.iter().fold(0.0, |sum, s| sum + s) / scores.len() as f64;
    if aggregate == Aggregate::Mean {
        return overall;
    }
    let mut by_type = vec![(0.0, 0usize); types];
    for (&s, &of_type) in scores.iter().zip(trial_types) {
        by_type[of_type].0 += s;
        by_type[of_type].1 += 1;
    }
    let worst = by_type
        .iter()
        .filter(|(_, n)| *n > 0)
        .map(|(sum, n)| sum / *n as f64)
        .fold(f64::INFINITY, f64::min);
    aggregate.combine(overall, worst)
}

/// Implicit fitness sharing: each network's score on each trial (`scores[network][trial]`),
/// divided by every network's mean score on that trial; 0 where that mean is 0.
fn share(scores: &mut [Vec<f64>]) {
    let trials = scores.first().map_or(0, Vec::len);
    for k in 0..trials {
        let mean = scores.iter().fold(0.0, |sum, s| sum + s[k]) / scores.len() as f64;
        for s in scores.iter_mut() {
            s[k] = if mean > 0.0 { s[k] / mean } else { 0.0 };
        }
    }
}
