//! The sequence-learning task: scoring a population, recording and assessing one network.

use std::sync::atomic::AtomicBool;

use ctrnn::{
    Elem, Error, Lanes, Layout, Network, Purpose, Result, Stream, Task, Validation, LANES,
};
use serde::{Deserialize, Serialize};

use crate::common::{check_inputs, in_precision, lane_state};
use crate::lanes::{by_block_named, by_pair, pairs, Kinds};
use crate::Aggregate;

use super::config::*;
use super::scoring::*;
use super::trial::*;

/// The trial number of the `Purpose::Trial` stream that draws a chained generation's trial order:
/// one no trial's timings use.
const ORDER_STREAM: u64 = u64::MAX;

/// The sequence-learning task: a validated [`SequenceConfig`].
#[derive(Clone, Debug, PartialEq)]
pub struct SequenceTask {
    pub(super) config: SequenceConfig,
    /// The targets as bits.
    bits: Vec<Vec<u8>>,
}

/// Everything one trial of one network did, time step by time step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrialRecord {
    /// The target sequence, such as `"01"`.
    pub target: String,
    /// Trigger input (input 0) during each time step.
    pub trigger: Vec<f64>,
    /// Reinforcement input (input 1) during each time step.
    pub reinforcement: Vec<f64>,
    /// Output (neuron 0's firing rate) after each time step.
    pub output: Vec<f64>,
    /// Every neuron's firing rate after each time step (`outputs[t][i]`).
    pub outputs: Vec<Vec<f64>>,
    /// The expected bit of each trigger.
    pub targets: Vec<u8>,
    /// The reinforcement R earned by each trigger.
    pub r: Vec<f64>,
    /// The mean output over each trigger's window.
    pub mean_output: Vec<f64>,
    /// Whether each trigger's mean output was on the expected bit's side of 0.5.
    pub trigger_correct: Vec<bool>,
    /// The state at the end of the trial, to continue from with `reset = false`.
    pub final_state: Vec<f64>,
}

/// A generation's scores from [`SequenceTask::scores`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// Trials per network.
    pub trials: usize,
    /// Triggers per trial.
    pub triggers: usize,
    /// R of every network, trial and trigger, row-major `P x trials x triggers`.
    pub r: Vec<f64>,
    /// `mean_k R_k` of every network and trial, row-major `P x trials`.
    pub mean_r: Vec<f64>,
    /// The performance base that was used for each target.
    pub base: Vec<f64>,
    /// Fitness of every network: the mean of its trials' performance.
    pub fitness: Vec<f64>,
}

/// How well one network learnt one target in [`SequenceTask::assess`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TargetReport {
    /// The target sequence.
    pub target: String,
    /// Mean performance P over the trials.
    pub mean_performance: f64,
    /// Fraction of trials in which every trigger after the warm-up was correct.
    pub success_fraction: f64,
    /// Whether `success_fraction >= SUCCESS_FRACTION`.
    pub succeeded: bool,
}

/// The verdict of [`SequenceTask::assess`] on one network.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Assessment {
    /// One report per target, in the config's order.
    pub targets: Vec<TargetReport>,
    /// Whether every target was learnt.
    pub success: bool,
}

impl SequenceTask {
    /// The task for `config`, which is validated.
    pub fn new(config: SequenceConfig) -> Result<Self> {
        config.validate()?;
        let bits = config.targets.iter().map(|t| to_bits(t)).collect();
        Ok(SequenceTask { config, bits })
    }

    /// The task from a JSON object of config fields, as in [`SequenceConfig::from_params`].
    pub fn from_params(params: &serde_json::Value) -> Result<Self> {
        SequenceTask::new(SequenceConfig::from_params(params)?)
    }

    /// The config.
    pub fn config(&self) -> &SequenceConfig {
        &self.config
    }

    /// The (delay, gap) of every trigger of trial `trial` in generation `generation`, as every
    /// individual meets them under common random numbers.
    pub fn timings(&self, seed: u64, generation: u64, trial: usize) -> Vec<(usize, usize)> {
        self.timings_of(seed, generation, 0, trial)
    }

    /// The (delay, gap) of every trigger of trial `trial` for individual `individual`: with
    /// `independent_conditions` these are its timings; individual 0's are everyone's otherwise.
    pub fn timings_of(
        &self,
        seed: u64,
        generation: u64,
        individual: usize,
        trial: usize,
    ) -> Vec<(usize, usize)> {
        let stream = Stream::new(
            seed,
            generation,
            Purpose::Trial,
            individual as u64,
            trial as u64,
        );
        draw_timings(&self.config, stream, self.config.triggers)
    }

    /// The (delay, gap) of every trigger of trial `trial` of [`assess`](Self::assess), from
    /// `Stream::new(seed, 0, Purpose::Evaluate, 0, trial)`.
    pub fn assessment_timings(&self, seed: u64, trial: usize) -> Vec<(usize, usize)> {
        self.fresh_timings(Purpose::Evaluate, seed, trial)
    }

    /// The (delay, gap) of every trigger of fresh trial `trial`, from
    /// `Stream::new(seed, 0, purpose, 0, trial)`: the same for every generation.
    pub fn fresh_timings(&self, purpose: Purpose, seed: u64, trial: usize) -> Vec<(usize, usize)> {
        draw_timings(
            &self.config,
            Stream::new(seed, 0, purpose, 0, trial as u64),
            self.config.triggers,
        )
    }

    /// The order in which generation `generation`'s trials run, as trial numbers (target-major:
    /// trial `t` is of target `t / trials_per_target`). In order unless the trials are
    /// [`chain`](SequenceConfig::chain)ed; then a permutation shared by every individual, drawn
    /// from `Stream::new(seed, generation, Purpose::Trial, 0, ORDER_STREAM)`.
    pub fn trial_order(&self, seed: u64, generation: u64) -> Vec<usize> {
        let n = self.config.n_trials();
        let mut order: Vec<usize> = (0..n).collect();
        if self.config.chain {
            let mut stream = Stream::new(seed, generation, Purpose::Trial, 0, ORDER_STREAM);
            for i in (1..n).rev() {
                let j = stream.below(i as u64 + 1) as usize;
                order.swap(i, j);
            }
        }
        order
    }

    /// Scores a generation: every network runs every trial, in
    /// [`trial_order`](Self::trial_order), blocks of [`LANES`] networks in parallel. `networks`
    /// may have any N but must all have the same N and M = 2.
    ///
    /// Stops with [`Error::Interrupted`] between trials once `cancel` is set.
    pub fn scores(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Scores> {
        let config = &self.config;
        let (n_trials, k) = (config.n_trials(), config.triggers);
        check_inputs(networks, 2, SENSORS)?;
        if networks.is_empty() {
            return Ok(Scores {
                trials: n_trials,
                triggers: k,
                r: vec![],
                mean_r: vec![],
                base: vec![self.fixed_base(); config.targets.len()],
                fitness: vec![],
            });
        }
        let common: Vec<Vec<(usize, usize)>> = if config.independent_conditions {
            vec![]
        } else {
            (0..n_trials)
                .map(|t| self.timings(seed, generation, t))
                .collect()
        };
        let order = self.trial_order(seed, generation);
        // Copies of a network meet the same trials (unless each draws its own), so one of each
        // kind runs for all; a GA population is a third to a half copies.
        let kinds = if config.independent_conditions {
            None
        } else {
            Some(Kinds::of(networks)).filter(|k| !k.all_distinct() && same_shape(networks))
        };
        let (run, names): (Vec<&Network>, Vec<usize>) = match &kinds {
            Some(kinds) => kinds.firsts.iter().map(|&p| (&networks[p], p)).unzip(),
            None => networks.iter().enumerate().map(|(p, net)| (net, p)).unzip(),
        };
        // Lane-major within a block: [lane][trial][trigger].
        let r = in_precision!(config.precision, E => by_block_named::<E, _, _>(
            &run,
            &names,
            n_trials,
            cancel,
            |len| vec![0.0; len * n_trials * k],
            |out, first, block, c| {
                let t = order[c];
                // A chain starts from rest, and each link runs to its end (its last
                // reinforcement and gap) before the next begins; the last may stop early.
                let (reset, full) = if config.chain {
                    (c == 0, c + 1 < n_trials)
                } else {
                    (true, false)
                };
                let own: Vec<Vec<(usize, usize)>>;
                let timings: [&[(usize, usize)]; LANES] = if config.independent_conditions {
                    // Padding lanes repeat the block's first network, and its timings.
                    own = (0..LANES)
                        .map(|l| {
                            let lane = if l < block.len() { l } else { 0 };
                            self.timings_of(seed, generation, first + lane, t)
                        })
                        .collect();
                    std::array::from_fn(|l| own[l].as_slice())
                } else {
                    [common[t].as_slice(); LANES]
                };
                let bits = &self.bits[t / config.trials_per_target];
                let outcome = run_lanes(config, block, bits, timings, reset, full, |_, _| {})?;
                for l in 0..block.len() {
                    let at = (l * n_trials + t) * k;
                    for (dst, r) in out[at..at + k].iter_mut().zip(&outcome.r) {
                        *dst = r[l];
                    }
                }
                Ok(())
            },
            |out| out,
        ))?;
        let r = match &kinds {
            Some(kinds) => {
                let per = n_trials * k;
                kinds
                    .kind
                    .iter()
                    .flat_map(|&j| &r[j * per..(j + 1) * per])
                    .copied()
                    .collect()
            }
            None => r,
        };
        let mean_r: Vec<f64> = r.chunks(k).map(mean).collect();
        let base = self.bases(&mean_r);
        let fitness = mean_r
            .chunks(n_trials)
            .map(|trials| self.fitness(trials, &base))
            .collect();
        Ok(Scores {
            trials: n_trials,
            triggers: k,
            r,
            mean_r,
            base,
            fitness,
        })
    }

    /// The numeric base, or 0.5 in place of a generation's mean when there is no generation.
    fn fixed_base(&self) -> f64 {
        match self.config.perf_base {
            PerfBase::Value(b) => b,
            PerfBase::GenerationMean | PerfBase::TargetMean => 0.5,
        }
    }

    /// The base of each target for a generation whose `mean_r` is `P x trials` row-major.
    fn bases(&self, mean_r: &[f64]) -> Vec<f64> {
        let targets = self.config.targets.len();
        match self.config.perf_base {
            PerfBase::Value(b) => vec![b; targets],
            PerfBase::GenerationMean => vec![mean(mean_r); targets],
            PerfBase::TargetMean => {
                let (n_trials, per) = (self.config.n_trials(), self.config.trials_per_target);
                (0..targets)
                    .map(|j| {
                        let of_target: Vec<f64> = mean_r
                            .chunks(n_trials)
                            .flat_map(|trials| &trials[j * per..(j + 1) * per])
                            .copied()
                            .collect();
                        mean(&of_target)
                    })
                    .collect()
            }
        }
    }

    /// One network's fitness from its trials' `mean_k R_k` (target-major) and each target's
    /// base: see [`Clamp`] and [`Aggregate`].
    fn fitness(&self, trials: &[f64], base: &[f64]) -> f64 {
        let config = &self.config;
        let per = config.trials_per_target;
        let base_of = |t: usize| base[t / per];
        // Kept in exactly the form of the paper's runs, so their fitness keeps its bits.
        let overall = match config.clamp {
            Clamp::Trial => {
                trials
                    .iter()
                    .enumerate()
                    .map(|(t, &m)| score(m, base_of(t)))
                    .sum::<f64>()
                    / trials.len() as f64
            }
            Clamp::Evaluation if base.iter().all(|&b| b == base[0]) => score(mean(trials), base[0]),
            Clamp::Evaluation => {
                let unclamped: Vec<f64> = trials
                    .iter()
                    .enumerate()
                    .map(|(t, &m)| unclamped_score(m, base_of(t)))
                    .collect();
                mean(&unclamped).max(0.0)
            }
        };
        if config.aggregate == Aggregate::Mean {
            return overall;
        }
        let worst = trials
            .chunks(per)
            .zip(base)
            .map(|(of_target, &b)| match config.clamp {
                Clamp::Trial => of_target.iter().map(|&m| score(m, b)).sum::<f64>() / per as f64,
                Clamp::Evaluation => score(mean(of_target), b),
            })
            .fold(f64::INFINITY, f64::min);
        config.aggregate.combine(overall, worst)
    }

    /// One trial of target `targets[target]` for `net`, with `timing[k]` the (delay, gap) of
    /// trigger k (so `timing.len()` triggers), recorded time step by time step.
    ///
    /// With `reset` the state starts at 0; otherwise it continues from `net`'s state. To chain
    /// trials (the "switch" demonstration), set the next trial's network state to the record's
    /// `final_state`. R values are bit-identical to those of [`scores`](Self::scores).
    pub fn run_trial(
        &self,
        net: &Network,
        target: usize,
        timing: &[(usize, usize)],
        reset: bool,
    ) -> Result<TrialRecord> {
        let Some(pattern) = self.config.targets.get(target) else {
            return Err(Error::InvalidArgument(format!(
                "target is {target}; the task has {} targets, numbered from 0",
                self.config.targets.len()
            )));
        };
        self.run_pattern(net, pattern, timing, reset)
    }

    /// [`run_trial`](Self::run_trial) with any target sequence `pattern` (a non-empty string of
    /// `'0'` and `'1'`), whether or not it is in the config's targets.
    pub fn run_pattern(
        &self,
        net: &Network,
        pattern: &str,
        timing: &[(usize, usize)],
        reset: bool,
    ) -> Result<TrialRecord> {
        if pattern.is_empty() || !pattern.chars().all(|c| c == '0' || c == '1') {
            return Err(Error::InvalidArgument(format!(
                "target is {pattern:?}; it must be a non-empty string of '0' and '1'"
            )));
        }
        check_inputs(std::slice::from_ref(net), 2, SENSORS)?;
        let bits = to_bits(pattern);
        let n = net.size();
        let mut trigger = vec![];
        let mut reinforcement = vec![];
        let mut output = vec![];
        let mut outputs = vec![];
        let (outcome, final_state) = in_precision!(self.config.precision, E => {
            let mut lanes = Lanes::<1, E>::new(&[net])?;
            let outcome = run_lanes(
                &self.config,
                &mut lanes,
                &bits,
                [timing],
                reset,
                true,
                |inputs, lanes| {
                    trigger.push(inputs[0][0]);
                    reinforcement.push(inputs[1][0]);
                    let rates: Vec<f64> = (0..n).map(|i| lanes.output(i)[0].to_f64()).collect();
                    output.push(rates[0]);
                    outputs.push(rates);
                },
            )
            .map_err(|d| d.error(|_| 0))?;
            (outcome, lane_state(&lanes))
        });
        let targets: Vec<u8> = (0..timing.len()).map(|k| bits[k % bits.len()]).collect();
        let r: Vec<f64> = outcome.r.iter().map(|x| x[0]).collect();
        let mean_output: Vec<f64> = outcome.mean_output.iter().map(|x| x[0]).collect();
        let trigger_correct = targets
            .iter()
            .zip(&mean_output)
            .map(|(&b, &m)| correct(b, m))
            .collect();
        Ok(TrialRecord {
            target: pattern.to_string(),
            trigger,
            reinforcement,
            output,
            outputs,
            targets,
            r,
            mean_output,
            trigger_correct,
            final_state,
        })
    }

    /// Judges `net` by the success rule of the module docs over `trials_per_target` fresh trials
    /// per target, trial `t` (numbered target-major) with
    /// [`assessment_timings(seed, t)`](Self::assessment_timings). Trials run [`LANES`] at a time in
    /// parallel; each gives the same R values as [`run_trial`](Self::run_trial).
    ///
    /// Performance uses the numeric `perf_base`, or 0.5 when it is a generation's mean.
    /// Every target must have more triggers than its warm-up, or nothing would be judged.
    pub fn assess(&self, net: &Network, trials_per_target: usize, seed: u64) -> Result<Assessment> {
        self.assess_cancellable(net, trials_per_target, seed, None)
    }

    /// [`assess`](Self::assess) that stops with [`Error::Interrupted`] soon after `cancel` is set.
    pub fn assess_cancellable(
        &self,
        net: &Network,
        trials_per_target: usize,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Assessment> {
        let judged = self.judge(&[net], trials_per_target, seed, Purpose::Evaluate, cancel)?;
        let targets: Vec<TargetReport> = self
            .config
            .targets
            .iter()
            .zip(&judged[0])
            .map(|(pattern, trials)| {
                let perf: Vec<f64> = trials.iter().map(|t| t.0).collect();
                let success_fraction =
                    trials.iter().filter(|t| t.1).count() as f64 / trials.len() as f64;
                TargetReport {
                    target: pattern.clone(),
                    mean_performance: mean(&perf),
                    success_fraction,
                    succeeded: success_fraction >= SUCCESS_FRACTION,
                }
            })
            .collect();
        let success = targets.iter().all(|t| t.succeeded);
        Ok(Assessment { targets, success })
    }

    /// Runs every network of `nets` through `per_target` fresh trials of every target, trial `t`
    /// (numbered target-major) with [`fresh_timings(purpose, seed, t)`](Self::fresh_timings), and
    /// judges each by the success rule: `out[network][target][trial]` is the trial's performance
    /// and whether every trigger after the warm-up was correct. (network, trial) pairs run
    /// [`LANES`] at a time in parallel; a lane's results do not depend on its neighbours.
    fn judge(
        &self,
        nets: &[&Network],
        per_target: usize,
        seed: u64,
        purpose: Purpose,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<Vec<Vec<Judged>>>> {
        for net in nets {
            check_inputs(std::slice::from_ref(*net), 2, SENSORS)?;
        }
        if per_target == 0 {
            return Err(Error::InvalidArgument(
                "trials_per_target is 0; assessing needs at least 1 trial per target".into(),
            ));
        }
        let config = &self.config;
        if let Some(t) = config.targets.iter().find(|t| config.triggers <= warmup(t)) {
            return Err(Error::InvalidArgument(format!(
                "triggers is {}; judging target {t:?} needs more than its warm-up of {} triggers",
                config.triggers,
                warmup(t)
            )));
        }
        let base = self.fixed_base();
        let mut out = vec![Vec::with_capacity(config.targets.len()); nets.len()];
        for (i, pattern) in config.targets.iter().enumerate() {
            let bits = &self.bits[i];
            let from = warmup(pattern);
            let timings: Vec<Vec<(usize, usize)>> = (0..per_target)
                .map(|j| self.fresh_timings(purpose, seed, i * per_target + j))
                .collect();
            // Lanes run in lockstep until the longest trial of their group ends: pairs go to
            // groups by their trial's length (a stable sort), so that few lanes idle. A lane's
            // results do not depend on its neighbours; they are put back in pair order below.
            let mut pairs = pairs(nets.len(), per_target);
            pairs.sort_by_key(|&(_, j)| self.trial_steps(&timings[j]));
            let groups: Vec<&[(usize, usize)]> = pairs.chunks(LANES).collect();
            let sorted = in_precision!(config.precision, E => by_pair::<E, _>(nets, &groups, cancel, |lanes, lane_pairs, len| {
                let lane_timings = lane_pairs.map(|(_, j)| timings[j].as_slice());
                let outcome = run_lanes(config, lanes, bits, lane_timings, true, false, |_, _| {})?;
                Ok((0..len)
                    .map(|l| {
                        let r: Vec<f64> = outcome.r.iter().map(|x| x[l]).collect();
                        let ok = (from..config.triggers)
                            .all(|k| correct(bits[k % bits.len()], outcome.mean_output[k][l]));
                        (performance(&r, base), ok)
                    })
                    .collect())
            }))?;
            let mut judged = vec![(0.0, false); sorted.len()];
            for (&(n, j), result) in pairs.iter().zip(sorted) {
                judged[n * per_target + j] = result;
            }
            for (n, trials) in judged.chunks(per_target).enumerate() {
                out[n].push(trials.to_vec());
            }
        }
        Ok(out)
    }

    /// Time steps of a trial with `timing` that stops after its last trigger window, as
    /// validation and assessment trials do.
    fn trial_steps(&self, timing: &[(usize, usize)]) -> usize {
        let c = &self.config;
        let cycles: usize = timing
            .iter()
            .map(|&(d, g)| c.trigger_steps + d + c.reinforcement_steps + g)
            .sum();
        match timing.last() {
            Some(&(d, g)) => cycles - (d + c.reinforcement_steps + g),
            None => 0,
        }
    }
}

impl Task for SequenceTask {
    fn layout(&self) -> Layout {
        Layout {
            size: self.config.size,
            n_inputs: 2,
        }
    }

    /// The fitness of [`SequenceTask::scores`].
    fn evaluate(
        &self,
        networks: &[Network],
        generation: u64,
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        Ok(self.scores(networks, generation, seed, cancel)?.fitness)
    }

    /// [`SequenceTask::assess`] with [`SUCCESS_TRIALS`] trials per target.
    fn succeeds(&self, net: &Network, seed: u64) -> Result<Option<bool>> {
        Ok(Some(self.assess(net, SUCCESS_TRIALS, seed)?.success))
    }

    /// Each network judged as in [`SequenceTask::assess`] on `validation_trials` trials per
    /// target drawn with [`Purpose::Validate`]: the rate is the lowest target's fraction of
    /// correct trials, the score the mean performance over all trials.
    fn validate(
        &self,
        networks: &[Network],
        seed: u64,
        cancel: Option<&AtomicBool>,
    ) -> Result<Option<Vec<Validation>>> {
        let refs: Vec<&Network> = networks.iter().collect();
        let per_target = self.config.validation_trials;
        let judged = self.judge(&refs, per_target, seed, Purpose::Validate, cancel)?;
        Ok(Some(
            judged
                .iter()
                .map(|targets| {
                    let correct = targets.iter().map(|trials| {
                        trials.iter().filter(|t| t.1).count() as f64 / per_target as f64
                    });
                    let perf: Vec<f64> = targets.iter().flatten().map(|t| t.0).collect();
                    Validation {
                        rate: correct.fold(f64::INFINITY, f64::min),
                        score: mean(&perf),
                    }
                })
                .collect(),
        ))
    }
}

/// Whether every network has the first one's N and M (a population needs it; without, the
/// population's own error names the first network that differs).
fn same_shape(networks: &[Network]) -> bool {
    networks
        .iter()
        .all(|n| (n.size(), n.n_inputs()) == (networks[0].size(), networks[0].n_inputs()))
}
