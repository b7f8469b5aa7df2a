//! Sequence learning (paper §5): a network learns, from delayed reinforcement, which of a set B of
//! periodic bit sequences its environment wants.
//!
//! # The network
//! Two sensors: input 0 is the trigger, input 1 the reinforcement. The output is neuron 0's firing
//! rate `f(v_0 - theta_0)`.
//!
//! # One trial
//! The state is reset to 0. Then, for each trigger `k = 0, 1, ..., triggers - 1`:
//!
//! 1. trigger window: `trigger_steps` time steps with input 0 = 1. The output is recorded after
//!    each time step and compared with the target bit `p = target[k % len(target)]`;
//! 2. delay: `d_k` time steps with no input;
//! 3. reinforcement: `reinforcement_steps` time steps with input 1 = `R_k`, where
//!    `R_k = 1 - mean over the trigger window of |p - output|`;
//! 4. gap: `g_k` time steps with no input (the last trigger's gap is run too, so that trials can be
//!    chained, see [`SequenceTask::run_trial`]).
//!
//! A time step holds the inputs for `integrator.substeps` integration steps of `integrator.dt`
//! (by default 10 Euler steps of 0.1, one unit of simulated time).
//!
//! # Timings and randomness
//! Trial `t` draws `d_0, g_0, d_1, g_1, ...` in that order, each uniform over its inclusive range,
//! from `Stream::new(seed, generation, Purpose::Trial, 0, t)` (see [`SequenceTask::timings`]).
//! Trials are ordered target-major: `trials_per_target` trials of `targets[0]`, then of
//! `targets[1]`, and so on. Every individual of a generation meets the same timings (common random
//! numbers) unless `independent_conditions` is set; then individual `i` uses
//! `Stream::new(seed, generation, Purpose::Trial, i, t)` instead.
//!
//! # Scoring
//! A trial scores `P = max(0, (mean_k R_k - base) / (1 - base))` ([`performance`]), and fitness is
//! the mean of `P` over the trials. With `perf_base = "generation-mean"` the base is the mean of
//! `mean_k R_k` over the whole generation (every individual and every trial), so one network's
//! fitness depends on the whole batch it is scored with: score a generation in one call. If that
//! mean is 1 (every network perfect) every fitness is 0. With `perf_base = "target-mean"` each
//! target has its own base, the generation's mean over that target's trials, so a target that the
//! whole population fails still separates the networks that fail it least.
//!
//! With `aggregate = "min"` fitness is instead the worst target's score (each target's mean over
//! its trials, clamped as `clamp` says), and with `"mean-min"` the mean of the two; the default
//! `"mean"` is the paper's.
//!
//! Note that clamping per trial rewards a constant output: on B = {0*, 1*} with base 0.5, a
//! network whose output is always 0 scores 1 on the 0* trials and 0 on the 1* trials, so its
//! fitness is 0.5. Only an output stuck at 0.5 (or a random one) scores about 0. With
//! `clamp = "evaluation"` the clamp is applied once, to the mean over the trials of
//! `(mean_k R_k - base) / (1 - base)`, and every constant output scores 0.
//!
//! # Success rule
//! A network has learnt a target when, over fresh random timings (drawn with
//! [`Purpose::Evaluate`], see [`SequenceTask::assessment_timings`]), in at least 90 %
//! ([`SUCCESS_FRACTION`]) of its trials every trigger from index `warmup = 2 * len(target)` on is
//! correct. A trigger is correct when the mean output over its window is on the target bit's side
//! of 0.5 (above 0.5 for a 1, below for a 0). It has learnt B when it has learnt every target
//! ([`SequenceTask::assess`]).
//!
//! # Example
//! ```
//! use ctrnn::{Network, Task};
//! use tasks::{SequenceConfig, SequenceTask};
//! let task = SequenceTask::new(SequenceConfig { triggers: 3, ..SequenceConfig::default() })?;
//! // All parameters 0: the state stays at 0 and the output at f(0) = 0.5, which earns nothing.
//! let net = Network::new(vec![1.0; 5], vec![0.0; 5], vec![0.0; 25], vec![0.0; 10], None)?;
//! assert_eq!(task.evaluate(&[net.clone()], 0, 42, None)?, vec![0.0]);
//! let timing = task.timings(42, 0, 0);
//! let record = task.run_trial(&net, 0, &timing, true)?;
//! assert_eq!(record.r, vec![0.5; 3]);
//! # Ok::<(), ctrnn::Error>(())
//! ```

use std::fmt;
use std::sync::atomic::AtomicBool;

use ctrnn::{
    Error, Integrator, Lanes, Layout, Method, Network, Population, Purpose, Result, Stream, Task,
    Validation, LANES,
};
use rayon::prelude::*;

use crate::common::{check_inputs, config_from_params, interrupted, Diverged};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// What the two sensors are, for error messages.
const SENSORS: &str = "trigger, reinforcement";

/// The fraction of trials a network must get right, after the warm-up, to have learnt a target.
pub const SUCCESS_FRACTION: f64 = 0.9;

/// Trials per target when a run checks whether its champion has succeeded yet (`dnnevo sweep`'s
/// "first success" generation). `dnnevo evaluate` uses as many as asked.
pub const SUCCESS_TRIALS: usize = 20;

/// The base of the performance score.
///
/// In JSON and TOML it is a number in [0, 1), or the string `"generation-mean"` or
/// `"target-mean"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PerfBase {
    /// A fixed base in [0, 1): 0.5 for one bit, 2/3 for three bits in the paper.
    Value(f64),
    /// The mean reinforcement of the whole generation being scored (the paper's two-bit runs).
    GenerationMean,
    /// Per target: the mean reinforcement of the generation's trials of that target, so a
    /// target the whole population fails still rewards whoever fails it least.
    TargetMean,
}

impl Default for PerfBase {
    fn default() -> Self {
        PerfBase::Value(0.5)
    }
}

/// The string form of [`PerfBase::GenerationMean`].
const GENERATION_MEAN: &str = "generation-mean";
/// The string form of [`PerfBase::TargetMean`].
const TARGET_MEAN: &str = "target-mean";
/// What a perf_base may be, for error messages.
const PERF_BASE_FORMS: &str = "a number in [0, 1) or \"generation-mean\" or \"target-mean\"";

impl Serialize for PerfBase {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            PerfBase::Value(v) => s.serialize_f64(*v),
            PerfBase::GenerationMean => s.serialize_str(GENERATION_MEAN),
            PerfBase::TargetMean => s.serialize_str(TARGET_MEAN),
        }
    }
}

impl<'de> Deserialize<'de> for PerfBase {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = PerfBase;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(PERF_BASE_FORMS)
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> std::result::Result<PerfBase, E> {
                Ok(PerfBase::Value(v))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<PerfBase, E> {
                Ok(PerfBase::Value(v as f64))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> std::result::Result<PerfBase, E> {
                Ok(PerfBase::Value(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> std::result::Result<PerfBase, E> {
                match v {
                    GENERATION_MEAN => Ok(PerfBase::GenerationMean),
                    TARGET_MEAN => Ok(PerfBase::TargetMean),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// Where the performance score `(mean R - base) / (1 - base)` is clamped at 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Clamp {
    /// Per trial, then averaged: READING.md's formula. An output stuck at 0 scores 1 on every
    /// 0* trial and 0 on every 1* trial, so 0.5 on B = {0*, 1*}.
    #[default]
    Trial,
    /// Once, on the mean of the trials' unclamped scores, so that failing one target cancels
    /// succeeding at another: any constant output scores 0 on B = {0*, 1*}.
    Evaluation,
}

/// How the scores of the targets make one fitness.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Aggregate {
    /// The mean over all trials (every target has as many): the paper's.
    #[default]
    Mean,
    /// The worst target's score (each target's score is the mean over its trials, clamped as
    /// `clamp` says): a network is only as good as the target it learns least.
    Min,
    /// The mean of `mean` and `min`: rewards every target, and the weakest twice.
    MeanMin,
}

/// The sequence-learning experiment's settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SequenceConfig {
    /// The set B: each target a non-empty string of `'0'` and `'1'`, repeated forever (`"01"` is
    /// (01)*). Default `["0", "1"]`.
    pub targets: Vec<String>,
    /// Neurons per network N (at least 1). Default 5.
    pub size: usize,
    /// Trials per target in one evaluation (at least 1). Default 2.
    pub trials_per_target: usize,
    /// Triggers per trial (at least 1). Default 10.
    pub triggers: usize,
    /// Time steps of a trigger window (at least 1). Default 10.
    pub trigger_steps: usize,
    /// Time steps of reinforcement after each trigger (may be 0). Default 10.
    pub reinforcement_steps: usize,
    /// Delay between a trigger window and its reinforcement, inclusive range in time steps.
    /// Default (10, 40).
    pub delay: (usize, usize),
    /// Gap between a reinforcement and the next trigger, inclusive range in time steps.
    /// Default (10, 40).
    pub gap: (usize, usize),
    /// Base of the performance score: a number in [0, 1), `"generation-mean"` or
    /// `"target-mean"`. Default 0.5.
    pub perf_base: PerfBase,
    /// Where the performance score is clamped at 0. Default `"trial"`.
    pub clamp: Clamp,
    /// How the targets' scores make one fitness. Default `"mean"`.
    pub aggregate: Aggregate,
    /// How one time step is integrated; `dt * substeps` is the length of a time step in units of
    /// simulated time. Default 10 Euler steps of dt = 0.1.
    pub integrator: Integrator,
    /// Whether each individual draws its own timings (`Purpose::Trial` stream with its index)
    /// instead of sharing the generation's. Default false.
    pub independent_conditions: bool,
    /// Fresh trials per target in a run's validation set, on which the best candidates of each
    /// generation are judged by the success rule to choose the champion (at least 1). Default 32.
    pub validation_trials: usize,
}

impl Default for SequenceConfig {
    fn default() -> Self {
        SequenceConfig {
            targets: vec!["0".into(), "1".into()],
            size: 5,
            trials_per_target: 2,
            triggers: 10,
            trigger_steps: 10,
            reinforcement_steps: 10,
            delay: (10, 40),
            gap: (10, 40),
            perf_base: PerfBase::default(),
            clamp: Clamp::Trial,
            aggregate: Aggregate::Mean,
            integrator: Integrator {
                method: Method::Euler,
                dt: 0.1,
                substeps: 10,
            },
            independent_conditions: false,
            validation_trials: 32,
        }
    }
}

impl SequenceConfig {
    /// Checks every field; the error names the field and says what is allowed.
    ///
    /// # Example
    /// ```
    /// use tasks::{PerfBase, SequenceConfig};
    /// let bad = SequenceConfig { perf_base: PerfBase::Value(1.0), ..SequenceConfig::default() };
    /// assert!(bad.validate().unwrap_err().to_string().contains("perf_base"));
    /// ```
    pub fn validate(&self) -> Result<()> {
        let config = |msg: String| Err(Error::Config(msg));
        if self.targets.is_empty() {
            return config("targets is empty; give at least one target such as \"0\"".into());
        }
        for (i, t) in self.targets.iter().enumerate() {
            if t.is_empty() || !t.chars().all(|c| c == '0' || c == '1') {
                return config(format!(
                    "targets[{i}] is {t:?}; each target must be a non-empty string of '0' and '1'"
                ));
            }
            if let Some(j) = self.targets[..i].iter().position(|u| u == t) {
                return config(format!(
                    "targets[{i}] is {t:?}, the same as targets[{j}]; targets must be distinct"
                ));
            }
        }
        for (name, value) in [
            ("size", self.size),
            ("trials_per_target", self.trials_per_target),
            ("triggers", self.triggers),
            ("trigger_steps", self.trigger_steps),
            ("validation_trials", self.validation_trials),
        ] {
            crate::common::check_count(name, value)?;
        }
        for (name, (lo, hi)) in [("delay", self.delay), ("gap", self.gap)] {
            if lo > hi {
                return config(format!(
                    "{name} is ({lo}, {hi}); the lower bound must not exceed the upper bound"
                ));
            }
        }
        if let PerfBase::Value(b) = self.perf_base {
            if !(0.0..1.0).contains(&b) {
                return config(format!("perf_base is {b}; it must be {PERF_BASE_FORMS}"));
            }
        }
        self.integrator.validate().map_err(|e| match e {
            Error::InvalidArgument(msg) => Error::Config(format!("integrator: {msg}")),
            other => other,
        })?;
        let per_trigger = self.trigger_steps as u128
            + self.delay.1 as u128
            + self.reinforcement_steps as u128
            + self.gap.1 as u128;
        crate::common::check_trial_steps(
            "triggers x (trigger_steps + delay + reinforcement_steps + gap), at their largest",
            self.triggers as u128 * per_trigger,
            self.integrator.substeps,
        )
    }

    /// Reads a config from a JSON object of its fields (`null` means all defaults) and validates
    /// it. Unknown fields are errors that name the field.
    pub fn from_params(params: &serde_json::Value) -> Result<Self> {
        let config: SequenceConfig = config_from_params("sequence", params)?;
        config.validate()?;
        Ok(config)
    }

    /// Trials per evaluation: `targets.len() * trials_per_target`.
    pub fn n_trials(&self) -> usize {
        self.targets.len() * self.trials_per_target
    }
}

/// The sequence-learning task: a validated [`SequenceConfig`].
#[derive(Clone, Debug, PartialEq)]
pub struct SequenceTask {
    config: SequenceConfig,
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

/// A trial's performance `max(0, (mean(rs) - base) / (1 - base))`; 0 when `base >= 1`.
///
/// # Example
/// ```
/// assert_eq!(tasks::performance(&[1.0, 0.5], 0.5), 0.5);
/// assert_eq!(tasks::performance(&[0.25], 0.5), 0.0);
/// ```
pub fn performance(rs: &[f64], base: f64) -> f64 {
    score(mean(rs), base)
}

/// `max(0, (mean_r - base) / (1 - base))`, 0 when `base >= 1`.
fn score(mean_r: f64, base: f64) -> f64 {
    unclamped_score(mean_r, base).max(0.0)
}

/// `(mean_r - base) / (1 - base)`, 0 when `base >= 1`.
fn unclamped_score(mean_r: f64, base: f64) -> f64 {
    if base >= 1.0 {
        0.0
    } else {
        (mean_r - base) / (1.0 - base)
    }
}

/// The arithmetic mean, summed in order.
fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// The warm-up of the success rule: triggers before index `2 * len(target)` are not judged.
pub fn warmup(target: &str) -> usize {
    2 * target.len()
}

/// Whether a trigger whose window had mean output `mean_output` was right about bit `bit`.
fn correct(bit: u8, mean_output: f64) -> bool {
    if bit == 1 {
        mean_output > 0.5
    } else {
        mean_output < 0.5
    }
}

/// One judged trial: its performance, and whether every trigger after the warm-up was correct.
type Judged = (f64, bool);

/// Which part of a trigger's cycle a lane is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    Trigger,
    Delay,
    Reinforce,
    Gap,
    Done,
}

/// One lane's position in its trial: trigger `k`, `phase`, with `left` time steps to go.
#[derive(Clone, Copy, Debug)]
struct Cursor {
    k: usize,
    phase: Phase,
    left: usize,
}

impl Cursor {
    fn start(timing: &[(usize, usize)], trigger_steps: usize) -> Cursor {
        let phase = if timing.is_empty() {
            Phase::Done
        } else {
            Phase::Trigger
        };
        Cursor {
            k: 0,
            phase,
            left: trigger_steps,
        }
    }

    /// Moves on past finished (and empty) phases. Unless `full`, the trial ends with the last
    /// trigger window, after which nothing can change a score.
    fn settle(&mut self, timing: &[(usize, usize)], config: &SequenceConfig, full: bool) {
        while self.left == 0 && self.phase != Phase::Done {
            (self.phase, self.left) = match self.phase {
                Phase::Trigger if !full && self.k + 1 == timing.len() => (Phase::Done, 0),
                Phase::Trigger => (Phase::Delay, timing[self.k].0),
                Phase::Delay => (Phase::Reinforce, config.reinforcement_steps),
                Phase::Reinforce => (Phase::Gap, timing[self.k].1),
                Phase::Gap => {
                    self.k += 1;
                    if self.k == timing.len() {
                        (Phase::Done, 0)
                    } else {
                        (Phase::Trigger, config.trigger_steps)
                    }
                }
                Phase::Done => unreachable!(),
            };
        }
    }
}

/// Per-trigger results of one trial on every lane.
struct Outcome<const L: usize> {
    /// R of trigger k on lane l: `r[k][l]`.
    r: Vec<[f64; L]>,
    /// Mean output over the window of trigger k on lane l.
    mean_output: Vec<[f64; L]>,
}

/// Runs one trial of target `bits` on every lane of `lanes` in lockstep, lane `l` with its own
/// `timings[l]` (all of the same length). `observe(inputs, lanes)` sees each time step's inputs and
/// the state after it. With `full` the trial runs to the end of the last gap; otherwise it stops
/// after the last trigger window, which gives the same R values. This is the only trial loop: the
/// population evaluation (`L = LANES`) and the single-network record (`L = 1`) both run it, so
/// they agree bit for bit.
fn run_lanes<const L: usize>(
    config: &SequenceConfig,
    lanes: &mut Lanes<L>,
    bits: &[u8],
    timings: [&[(usize, usize)]; L],
    reset: bool,
    full: bool,
    mut observe: impl FnMut(&[[f64; L]; 2], &Lanes<L>),
) -> std::result::Result<Outcome<L>, Diverged> {
    let n_triggers = timings[0].len();
    debug_assert!(timings.iter().all(|t| t.len() == n_triggers));
    if reset {
        lanes.reset();
    }
    let steps = config.trigger_steps as f64;
    let mut cursors = timings.map(|t| Cursor::start(t, config.trigger_steps));
    let mut err = [0.0; L];
    let mut on = [0.0; L];
    let mut r = vec![[0.0; L]; n_triggers];
    let mut mean_output = vec![[0.0; L]; n_triggers];
    let mut inputs = [[0.0; L]; 2];
    while cursors.iter().any(|c| c.phase != Phase::Done) {
        for (l, c) in cursors.iter().enumerate() {
            inputs[0][l] = if c.phase == Phase::Trigger { 1.0 } else { 0.0 };
            inputs[1][l] = if c.phase == Phase::Reinforce {
                r[c.k][l]
            } else {
                0.0
            };
        }
        lanes.step_row(&inputs, &config.integrator);
        let out = lanes.output(0);
        for (l, c) in cursors.iter_mut().enumerate() {
            if c.phase == Phase::Done {
                continue;
            }
            if c.phase == Phase::Trigger {
                let p = f64::from(bits[c.k % bits.len()]);
                err[l] += (p - out[l]).abs();
                on[l] += out[l];
            }
            c.left -= 1;
            if c.left == 0 {
                if c.phase == Phase::Trigger {
                    r[c.k][l] = 1.0 - err[l] / steps;
                    mean_output[c.k][l] = on[l] / steps;
                    err[l] = 0.0;
                    on[l] = 0.0;
                }
                c.settle(timings[l], config, full);
            }
        }
        observe(&inputs, lanes);
    }
    Diverged::find(lanes)?;
    Ok(Outcome { r, mean_output })
}

/// Draws `n` (delay, gap) pairs from `stream`, delay first.
fn draw_timings(config: &SequenceConfig, mut stream: Stream, n: usize) -> Vec<(usize, usize)> {
    let mut draw = |(lo, hi): (usize, usize)| stream.range_inclusive_int(lo as u64, hi as u64);
    (0..n)
        .map(|_| {
            let d = draw(config.delay) as usize;
            let g = draw(config.gap) as usize;
            (d, g)
        })
        .collect()
}

/// Bits of a target string that has been validated.
fn to_bits(target: &str) -> Vec<u8> {
    target.bytes().map(|b| b - b'0').collect()
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

    /// Scores a generation: every network runs every trial, blocks of [`LANES`] networks in
    /// parallel. `networks` may have any N but must all have the same N and M = 2.
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
        let mut population = Population::new(networks)?;
        let per_block = population
            .blocks_mut()
            .par_iter_mut()
            .enumerate()
            .map(|(b, block)| {
                let first = b * LANES;
                // Lane-major: [lane][trial][trigger].
                let mut out = vec![0.0; block.len() * n_trials * k];
                for t in 0..n_trials {
                    if interrupted(cancel) {
                        return Err(Error::Interrupted);
                    }
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
                    let outcome = run_lanes(config, block, bits, timings, true, false, |_, _| {})
                        .map_err(|d| d.error(first))?;
                    for l in 0..block.len() {
                        let at = (l * n_trials + t) * k;
                        for (dst, r) in out[at..at + k].iter_mut().zip(&outcome.r) {
                            *dst = r[l];
                        }
                    }
                }
                Ok(out)
            })
            .collect::<Result<Vec<Vec<f64>>>>()?;
        let r = per_block.concat();
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
        match config.aggregate {
            Aggregate::Min => worst,
            Aggregate::MeanMin | Aggregate::Mean => 0.5 * (overall + worst),
        }
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
        let mut lanes = Lanes::<1>::new(&[net])?;
        let n = net.size();
        let mut trigger = vec![];
        let mut reinforcement = vec![];
        let mut output = vec![];
        let mut outputs = vec![];
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
                let rates: Vec<f64> = (0..n).map(|i| lanes.output(i)[0]).collect();
                output.push(rates[0]);
                outputs.push(rates);
            },
        )
        .map_err(|d| d.error(0))?;
        let targets: Vec<u8> = (0..timing.len()).map(|k| bits[k % bits.len()]).collect();
        let r: Vec<f64> = outcome.r.iter().map(|x| x[0]).collect();
        let mean_output: Vec<f64> = outcome.mean_output.iter().map(|x| x[0]).collect();
        let trigger_correct = targets
            .iter()
            .zip(&mean_output)
            .map(|(&b, &m)| correct(b, m))
            .collect();
        let mut final_state = vec![0.0; n];
        lanes.lane_state(0, &mut final_state);
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
            let pairs: Vec<(usize, usize)> = (0..nets.len())
                .flat_map(|n| (0..per_target).map(move |j| (n, j)))
                .collect();
            let groups = pairs
                .par_chunks(LANES)
                .map(|group| {
                    if interrupted(cancel) {
                        return Err(Error::Interrupted);
                    }
                    // Padding lanes repeat the group's first pair.
                    let pick = |l: usize| group[if l < group.len() { l } else { 0 }];
                    let refs: [&Network; LANES] = std::array::from_fn(|l| nets[pick(l).0]);
                    let lane_timings = std::array::from_fn(|l| timings[pick(l).1].as_slice());
                    let mut lanes = Lanes::<LANES>::new(&refs)?;
                    let outcome = run_lanes(
                        config,
                        &mut lanes,
                        bits,
                        lane_timings,
                        true,
                        false,
                        |_, _| {},
                    )
                    .map_err(|d| d.error(group[0].0))?;
                    Ok((0..group.len())
                        .map(|l| {
                            let r: Vec<f64> = outcome.r.iter().map(|x| x[l]).collect();
                            let ok = (from..config.triggers)
                                .all(|k| correct(bits[k % bits.len()], outcome.mean_output[k][l]));
                            (performance(&r, base), ok)
                        })
                        .collect::<Vec<_>>())
                })
                .collect::<Result<Vec<_>>>()?;
            let judged = groups.concat();
            for (n, trials) in judged.chunks(per_target).enumerate() {
                out[n].push(trials.to_vec());
            }
        }
        Ok(out)
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

#[cfg(test)]
mod tests {
    use super::*;
    use ctrnn::genome::{self, Ranges};

    /// A one-neuron network with zero weights and threshold `theta`: its output stays at
    /// `f(-theta)` whatever the inputs.
    fn constant(theta: f64) -> Network {
        Network::new(vec![1.0], vec![theta], vec![0.0], vec![0.0, 0.0], None).unwrap()
    }

    /// Random 5-neuron, 2-sensor networks over the paper's ranges.
    fn random_networks(count: usize, seed: u64) -> Vec<Network> {
        let layout = Layout {
            size: 5,
            n_inputs: 2,
        };
        (0..count)
            .map(|i| {
                let mut s = Stream::new(seed, 0, Purpose::Init, i as u64, 0);
                genome::decode(layout, &genome::random(layout, &Ranges::default(), &mut s)).unwrap()
            })
            .collect()
    }

    fn task(config: SequenceConfig) -> SequenceTask {
        SequenceTask::new(config).unwrap()
    }

    fn small() -> SequenceConfig {
        SequenceConfig {
            targets: vec!["0".into(), "1".into(), "01".into()],
            triggers: 5,
            ..SequenceConfig::default()
        }
    }

    #[test]
    fn timings_are_in_range_and_keyed_by_seed_generation_trial() {
        let t = task(SequenceConfig {
            delay: (3, 7),
            gap: (20, 22),
            triggers: 50,
            ..SequenceConfig::default()
        });
        let a = t.timings(1, 2, 3);
        assert_eq!(a.len(), 50);
        assert!(a
            .iter()
            .all(|&(d, g)| (3..=7).contains(&d) && (20..=22).contains(&g)));
        // Both ends of each range are reached.
        for v in [3, 7] {
            assert!(a.iter().any(|x| x.0 == v), "delay {v} never drawn");
        }
        for v in [20, 22] {
            assert!(a.iter().any(|x| x.1 == v), "gap {v} never drawn");
        }
        assert_eq!(a, t.timings(1, 2, 3));
        for other in [t.timings(2, 2, 3), t.timings(1, 3, 3), t.timings(1, 2, 4)] {
            assert_ne!(a, other);
        }
        // Common random numbers: individual 0's timings are everyone's.
        assert_eq!(a, t.timings_of(1, 2, 0, 3));
        assert_ne!(a, t.timings_of(1, 2, 1, 3));
        // The order of draws is delay_0, gap_0, delay_1, ... from the trial's stream.
        let mut s = Stream::new(1, 2, Purpose::Trial, 0, 3);
        for &(d, g) in &a[..5] {
            assert_eq!(d as u64, s.range_inclusive_int(3, 7));
            assert_eq!(g as u64, s.range_inclusive_int(20, 22));
        }
        // A fixed range gives fixed timings; assessment timings are a different stream.
        let fixed = task(SequenceConfig {
            delay: (12, 12),
            gap: (0, 0),
            ..SequenceConfig::default()
        });
        assert!(fixed.timings(5, 0, 0).iter().all(|&x| x == (12, 0)));
        assert_ne!(t.assessment_timings(1, 3), t.timings(1, 0, 3));
        assert_eq!(t.assessment_timings(1, 3), t.assessment_timings(1, 3));
    }

    #[test]
    fn constant_output_earns_r_one_or_zero() {
        let t = task(SequenceConfig::default());
        let timing = t.timings(0, 0, 0);
        // f(v + 100) rounds to exactly 1.
        let high = constant(-100.0);
        let one = t.run_pattern(&high, "1", &timing, true).unwrap();
        assert_eq!(one.r, vec![1.0; 10]);
        assert!(one.trigger_correct.iter().all(|&c| c));
        let zero = t.run_pattern(&high, "0", &timing, true).unwrap();
        assert_eq!(zero.r, vec![0.0; 10]);
        assert!(zero.trigger_correct.iter().all(|&c| !c));
        let alt = t.run_pattern(&high, "01", &timing, true).unwrap();
        assert_eq!(alt.targets, vec![0, 1, 0, 1, 0, 1, 0, 1, 0, 1]);
        assert_eq!(
            alt.r,
            vec![0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0]
        );
    }

    /// A neuron that follows the trigger: sensor weight 20 from the trigger, 3 from the
    /// reinforcement, threshold 5, tau 0.5.
    fn follower() -> Network {
        Network::new(vec![0.5], vec![5.0], vec![0.0], vec![20.0, 3.0], None).unwrap()
    }

    #[test]
    fn r_is_measured_over_the_trigger_window() {
        let t = task(SequenceConfig::default());
        let net = follower();
        let timing = t.timings(7, 1, 0);
        let rec = t.run_pattern(&net, "01", &timing, true).unwrap();
        // First window (target bit 0) by hand: from v = 0, Euler with h = 0.2 gives
        // v = 20 (1 - 0.8^j) after j steps; the output is recorded after each of the 10 time
        // steps of 10 Euler steps each.
        let sig = |x: f64| 1.0 / (1.0 + (-x).exp());
        let mut sum = 0.0;
        for n in 1..=10 {
            sum += sig(20.0 * (1.0 - 0.8f64.powi(10 * n)) - 5.0);
        }
        let want = 1.0 - sum / 10.0;
        assert!((rec.r[0] - want).abs() < 1e-12, "{} vs {want}", rec.r[0]);
        // A window shifted by one step would include f(-5) = 0.0067 and be well above.
        assert!(rec.r[0] < 0.01);
        // The second trigger wants a 1, which the follower gives.
        assert!(rec.r[1] > 0.99);

        // The whole trial replayed through ctrnn's own integrator from an input series built
        // here from the timings, feeding back the recorded R values.
        let mut inputs = vec![];
        let mut windows = vec![];
        for (k, &(d, g)) in timing.iter().enumerate() {
            windows.push(inputs.len() / 2);
            for (rows, value) in [(10, [1.0, 0.0]), (d, [0.0; 2]), (10, [0.0, rec.r[k]])] {
                for _ in 0..rows {
                    inputs.extend_from_slice(&value);
                }
            }
            for _ in 0..g {
                inputs.extend_from_slice(&[0.0; 2]);
            }
        }
        let steps = inputs.len() / 2;
        assert_eq!(rec.output.len(), steps);
        let trig: Vec<f64> = inputs.iter().step_by(2).copied().collect();
        let reinf: Vec<f64> = inputs.iter().skip(1).step_by(2).copied().collect();
        assert_eq!(rec.trigger, trig);
        assert_eq!(rec.reinforcement, reinf);
        let mut replay = net.clone();
        let states = replay.run(&inputs, steps, &t.config.integrator).unwrap();
        let out: Vec<f64> = states
            .iter()
            .map(|v| ctrnn::math::sigmoid(v - 5.0))
            .collect();
        assert_eq!(rec.output, out);
        for (k, &w) in windows.iter().enumerate() {
            let p = (k % 2) as f64;
            let err: f64 = out[w..w + 10].iter().map(|o| (p - o).abs()).sum();
            assert_eq!(rec.r[k], 1.0 - err / 10.0, "trigger {k}");
        }
        assert_eq!(rec.final_state, replay.state());
        assert_eq!(rec.outputs.len(), steps);
        assert_eq!(rec.outputs[3], vec![rec.output[3]]);
    }

    #[test]
    fn performance_of_hand_made_values() {
        assert_eq!(performance(&[1.0, 1.0], 0.5), 1.0);
        assert_eq!(performance(&[0.5, 0.5], 0.5), 0.0);
        assert_eq!(performance(&[0.75], 0.5), 0.5);
        assert_eq!(performance(&[0.2, 0.3], 0.5), 0.0);
        assert_eq!(performance(&[0.2, 0.4], 0.0), 0.30000000000000004);
        let p = performance(&[1.0, 0.5], 2.0 / 3.0);
        assert!((p - 0.25).abs() < 1e-15, "{p}");
        assert_eq!(performance(&[1.0], 1.0), 0.0);
    }

    #[test]
    fn constant_outputs_score_half_or_nothing() {
        let t = task(SequenceConfig::default());
        let nets = [constant(100.0), constant(-100.0), constant(0.0)];
        let f = t.evaluate(&nets, 0, 3, None).unwrap();
        // Always 0: perfect on the two 0* trials, nothing on the two 1* trials. Always 1: the
        // reverse. Always 0.5: R = 0.5 everywhere, nothing above the base.
        assert_eq!(f, vec![0.5, 0.5, 0.0]);
        // Clamped once per evaluation, no constant output earns anything.
        let t = task(SequenceConfig {
            clamp: Clamp::Evaluation,
            ..SequenceConfig::default()
        });
        assert_eq!(t.evaluate(&nets, 0, 3, None).unwrap(), vec![0.0, 0.0, 0.0]);
    }

    #[test]
    fn batched_evaluation_equals_run_trial() {
        let t = task(small());
        let nets = random_networks(19, 11);
        let (seed, generation) = (5, 3);
        let scores = t.scores(&nets, generation, seed, None).unwrap();
        let (n_trials, k) = (6, 5);
        assert_eq!((scores.trials, scores.triggers), (n_trials, k));
        assert_eq!(scores.r.len(), 19 * n_trials * k);
        for (p, net) in nets.iter().enumerate() {
            let mut fitness = 0.0;
            for trial in 0..n_trials {
                let timing = t.timings(seed, generation, trial);
                let rec = t.run_trial(net, trial / 2, &timing, true).unwrap();
                let at = (p * n_trials + trial) * k;
                assert_eq!(rec.r, scores.r[at..at + k], "network {p}, trial {trial}");
                fitness += performance(&rec.r, 0.5);
            }
            assert_eq!(scores.fitness[p], fitness / n_trials as f64, "network {p}");
        }
        // Not trivially equal: the random networks score differently.
        assert!(scores.fitness.iter().any(|&f| f != scores.fitness[0]));
        assert!(scores.r.iter().any(|&r| r > 0.01 && r < 0.99));
    }

    #[test]
    fn evaluation_does_not_depend_on_threads() {
        let t = task(small());
        let nets = random_networks(37, 2);
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| t.scores(&nets, 4, 9, None).unwrap())
        };
        let one = run(1);
        let two = run(2);
        let bits = |s: &Scores| s.r.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&one), bits(&two));
        assert_eq!(one, two);
        // A network's score does not depend on its neighbours either.
        let alone = t.scores(&nets[20..21], 4, 9, None).unwrap();
        assert_eq!(alone.fitness[0], one.fitness[20]);
    }

    #[test]
    fn independent_conditions_use_each_individuals_timings() {
        let t = task(SequenceConfig {
            independent_conditions: true,
            ..small()
        });
        let nets = random_networks(11, 4);
        let scores = t.scores(&nets, 1, 8, None).unwrap();
        for (p, net) in nets.iter().enumerate() {
            for trial in 0..6 {
                let timing = t.timings_of(8, 1, p, trial);
                let rec = t.run_trial(net, trial / 2, &timing, true).unwrap();
                let at = (p * 6 + trial) * 5;
                assert_eq!(rec.r, scores.r[at..at + 5], "network {p}, trial {trial}");
            }
        }
        let common = task(small()).scores(&nets, 1, 8, None).unwrap();
        assert_eq!(
            common.r[..30],
            scores.r[..30],
            "individual 0 has the common timings"
        );
        assert_ne!(common.r, scores.r);
    }

    #[test]
    fn generation_mean_base() {
        let t = task(SequenceConfig {
            targets: vec!["0".into()],
            triggers: 3,
            perf_base: PerfBase::GenerationMean,
            ..SequenceConfig::default()
        });
        // Outputs 0, 0.25 and 1: mean R 1, 0.75 and 0 on 0*.
        let quarter = constant(3f64.ln());
        let nets = [constant(100.0), quarter.clone(), constant(-100.0)];
        let s = t.scores(&nets, 0, 1, None).unwrap();
        assert!((s.mean_r[2] - 0.75).abs() < 1e-12);
        assert!((s.base[0] - 1.75 / 3.0).abs() < 1e-12, "{:?}", s.base);
        assert_eq!(s.base, vec![mean(&s.mean_r)]);
        let want = [1.0, 0.4, 0.0];
        for (f, w) in s.fitness.iter().zip(want) {
            assert!((f - w).abs() < 1e-12, "{:?}", s.fitness);
        }
        // The same network scores differently in another batch.
        let s = t.scores(&nets[1..], 0, 1, None).unwrap();
        assert!((s.fitness[0] - 0.6).abs() < 1e-12, "{:?}", s.fitness);
        // A generation of perfect networks has nothing to beat: fitness 0, not NaN.
        let s = t.scores(&[constant(100.0)], 0, 1, None).unwrap();
        assert_eq!(s.fitness, vec![0.0]);
    }

    #[test]
    fn target_mean_base_is_each_targets_generation_mean() {
        let config = SequenceConfig {
            triggers: 3,
            perf_base: PerfBase::TargetMean,
            ..SequenceConfig::default()
        };
        // Outputs 0, 0.25 and 1: mean R 1, 0.75 and 0 on 0*, and 0, 0.25 and 1 on 1*.
        let nets = [constant(100.0), constant(3f64.ln()), constant(-100.0)];
        let s = task(config.clone()).scores(&nets, 0, 1, None).unwrap();
        let (b0, b1) = (1.75 / 3.0, 1.25 / 3.0);
        assert!((s.base[0] - b0).abs() < 1e-12 && (s.base[1] - b1).abs() < 1e-12);
        let p = |r: f64, b: f64| (r - b) / (1.0 - b);
        let close = |got: &[f64], want: &[f64]| {
            assert!(
                got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-12),
                "{got:?} != {want:?}"
            )
        };
        // Per trial, clamped: always-0 earns 1 on its two 0* trials, 0 on its 1* trials.
        close(&s.fitness, &[0.5, p(0.75, b0) / 2.0, p(1.0, b1) / 2.0]);
        // Clamped once: the failed target costs what it falls below its own base.
        let once = task(SequenceConfig {
            clamp: Clamp::Evaluation,
            ..config.clone()
        })
        .scores(&nets, 0, 1, None)
        .unwrap();
        let mean2 = |a: f64, b: f64| (2.0 * a + 2.0 * b) / 4.0;
        close(
            &once.fitness,
            &[
                mean2(1.0, p(0.0, b1)),
                mean2(p(0.75, b0), p(0.25, b1)),
                mean2(p(0.0, b0), 1.0),
            ]
            .map(|x| x.max(0.0)),
        );
    }

    #[test]
    fn min_and_mean_min_aggregates_judge_the_weakest_target() {
        let nets = [
            constant(100.0),
            constant(3f64.ln()),
            Network::new(vec![1.0], vec![0.5], vec![2.0], vec![3.0, -4.0], None).unwrap(),
        ];
        let config = SequenceConfig {
            triggers: 4,
            ..SequenceConfig::default()
        };
        let mean = task(config.clone()).scores(&nets, 0, 1, None).unwrap();
        for clamp in [Clamp::Trial, Clamp::Evaluation] {
            let with = |aggregate| {
                task(SequenceConfig {
                    aggregate,
                    clamp,
                    ..config.clone()
                })
                .scores(&nets, 0, 1, None)
                .unwrap()
            };
            let (min, both) = (with(Aggregate::Min), with(Aggregate::MeanMin));
            let overall = with(Aggregate::Mean);
            for i in 0..nets.len() {
                // Each target's score from the trials' mean R, by hand.
                let trials = &mean.mean_r[i * 4..(i + 1) * 4];
                let target = |j: usize| {
                    let (a, b) = (trials[2 * j], trials[2 * j + 1]);
                    match clamp {
                        Clamp::Trial => (score(a, 0.5) + score(b, 0.5)) / 2.0,
                        Clamp::Evaluation => score((a + b) / 2.0, 0.5),
                    }
                };
                let worst = target(0).min(target(1));
                assert_eq!(min.fitness[i], worst, "network {i}, {clamp:?}");
                assert_eq!(both.fitness[i], 0.5 * (overall.fitness[i] + worst));
            }
        }
        // Always 0 is perfect on 0* and worthless on 1*: the minimum gives it nothing.
        assert_eq!(
            task(SequenceConfig {
                aggregate: Aggregate::Min,
                ..config.clone()
            })
            .scores(&nets[..1], 0, 1, None)
            .unwrap()
            .fitness,
            vec![0.0]
        );
    }

    #[test]
    fn continuing_without_reset_chains_trials() {
        let t = task(SequenceConfig::default());
        let net = &random_networks(1, 5)[0];
        let timing = t.timings(1, 0, 0);
        let whole = t.run_pattern(net, "0", &timing, true).unwrap();
        let first = t.run_pattern(net, "0", &timing[..4], true).unwrap();
        let mut cont = net.clone();
        cont.set_state(Some(&first.final_state)).unwrap();
        let second = t.run_pattern(&cont, "0", &timing[4..], false).unwrap();
        assert_eq!([first.r, second.r].concat(), whole.r);
        assert_eq!([first.output, second.output].concat(), whole.output);
        // With a reset the continuation starts over.
        let fresh = t.run_pattern(&cont, "0", &timing[4..], true).unwrap();
        assert_ne!(
            fresh.output,
            whole.output[whole.output.len() - fresh.output.len()..]
        );
    }

    #[test]
    fn assess_judges_the_warm_up_and_matches_run_trial() {
        let t = task(SequenceConfig::default());
        let low = constant(100.0);
        let a = t.assess(&low, 5, 1).unwrap();
        assert_eq!(a.targets[0].success_fraction, 1.0);
        assert_eq!(a.targets[0].mean_performance, 1.0);
        assert!(a.targets[0].succeeded);
        assert_eq!(a.targets[1].success_fraction, 0.0);
        assert!(!a.success);

        // A random network, 11 trials per target (a group of 8 and a partial group).
        let net = &random_networks(3, 6)[2];
        let a = t.assess(net, 11, 4).unwrap();
        for (i, report) in a.targets.iter().enumerate() {
            let mut perf = vec![];
            let mut ok = 0;
            for j in 0..11 {
                let timing = t.assessment_timings(4, i * 11 + j);
                let rec = t.run_trial(net, i, &timing, true).unwrap();
                perf.push(performance(&rec.r, 0.5));
                ok += usize::from(rec.trigger_correct[2..].iter().all(|&c| c));
            }
            assert_eq!(report.mean_performance, mean(&perf));
            assert_eq!(report.success_fraction, ok as f64 / 11.0);
        }
        // Too few triggers to judge anything after the warm-up.
        let short = task(SequenceConfig {
            targets: vec!["011".into()],
            triggers: 6,
            ..SequenceConfig::default()
        });
        let e = short.assess(&low, 3, 0).unwrap_err().to_string();
        assert!(e.contains("warm-up of 6"), "{e}");
    }

    #[test]
    fn trigger_correct_is_the_side_of_one_half() {
        assert!(correct(1, 0.51) && !correct(1, 0.5) && !correct(1, 0.2));
        assert!(correct(0, 0.49) && !correct(0, 0.5) && !correct(0, 0.8));
        assert_eq!(warmup("011"), 6);
    }

    #[test]
    fn cancel_interrupts() {
        let t = task(SequenceConfig::default());
        let flag = AtomicBool::new(true);
        let r = t.evaluate(&random_networks(9, 0), 0, 0, Some(&flag));
        assert!(matches!(r, Err(Error::Interrupted)), "{r:?}");
    }

    #[test]
    fn wrong_networks_and_targets_are_errors() {
        let t = task(SequenceConfig::default());
        let one_input = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
        let e = t.evaluate(&[constant(0.0), one_input.clone()], 0, 0, None);
        assert!(e.unwrap_err().to_string().contains("network 1 has M = 1"));
        let timing = t.timings(0, 0, 0);
        assert!(t.run_trial(&one_input, 0, &timing, true).is_err());
        let e = t.run_trial(&constant(0.0), 2, &timing, true).unwrap_err();
        assert!(e.to_string().contains("2 targets"), "{e}");
        assert!(t.run_pattern(&constant(0.0), "0a", &timing, true).is_err());
        let fast = Network::new(vec![0.01], vec![0.0], vec![-5.0], vec![1.0, 1.0], None).unwrap();
        let e = t.evaluate(&[constant(0.0), fast], 0, 0, None).unwrap_err();
        assert!(e.to_string().contains("diverged") && e.to_string().contains("network 1"));
        assert_eq!(t.evaluate(&[], 0, 0, None).unwrap(), Vec::<f64>::new());
    }

    #[test]
    fn config_validation_names_the_field() {
        let check = |c: SequenceConfig, field: &str| {
            let e = c.validate().unwrap_err();
            assert!(matches!(e, Error::Config(_)), "{e:?}");
            assert!(e.to_string().contains(field), "{e} lacks {field}");
        };
        let d = SequenceConfig::default;
        check(
            SequenceConfig {
                targets: vec![],
                ..d()
            },
            "targets is empty",
        );
        check(
            SequenceConfig {
                targets: vec!["0".into(), "".into()],
                ..d()
            },
            "targets[1]",
        );
        check(
            SequenceConfig {
                targets: vec!["0".into(), "0".into()],
                ..d()
            },
            "distinct",
        );
        check(SequenceConfig { size: 0, ..d() }, "size");
        check(SequenceConfig { triggers: 0, ..d() }, "triggers");
        check(
            SequenceConfig {
                trigger_steps: 0,
                ..d()
            },
            "trigger_steps",
        );
        check(
            SequenceConfig {
                trials_per_target: 0,
                ..d()
            },
            "trials_per_target",
        );
        check(
            SequenceConfig {
                delay: (5, 4),
                ..d()
            },
            "delay",
        );
        check(SequenceConfig { gap: (5, 4), ..d() }, "gap");
        for b in [-0.1, 1.0, f64::NAN] {
            check(
                SequenceConfig {
                    perf_base: PerfBase::Value(b),
                    ..d()
                },
                "perf_base",
            );
        }
        let mut c = d();
        c.integrator.dt = 0.0;
        check(c, "integrator: dt");
        d().validate().unwrap();
        SequenceConfig {
            reinforcement_steps: 0,
            delay: (0, 0),
            gap: (0, 0),
            ..d()
        }
        .validate()
        .unwrap();
    }

    #[test]
    fn config_reads_and_writes_json() {
        let c = SequenceConfig::from_params(&serde_json::json!({
            "targets": ["011", "101", "110"],
            "size": 10,
            "perf_base": "generation-mean",
            "delay": [5, 6],
            "integrator": {"method": "rk4", "dt": 0.05, "substeps": 20},
        }))
        .unwrap();
        assert_eq!(c.perf_base, PerfBase::GenerationMean);
        assert_eq!(c.delay, (5, 6));
        assert_eq!(c.integrator.method, Method::Rk4);
        assert_eq!(c.gap, (10, 40));
        let text = serde_json::to_string(&c).unwrap();
        assert!(text.contains("\"perf_base\":\"generation-mean\""), "{text}");
        let back: SequenceConfig = serde_json::from_str(&text).unwrap();
        assert_eq!(back, c);
        let c = SequenceConfig::from_params(&serde_json::json!({"perf_base": 0})).unwrap();
        assert_eq!(c.perf_base, PerfBase::Value(0.0));
        let c = SequenceConfig::from_params(
            &serde_json::json!({"perf_base": "target-mean", "aggregate": "mean-min"}),
        )
        .unwrap();
        assert_eq!(
            (c.perf_base, c.aggregate),
            (PerfBase::TargetMean, Aggregate::MeanMin)
        );
        let text = serde_json::to_string(&c).unwrap();
        assert!(
            text.contains("\"perf_base\":\"target-mean\"") && text.contains("\"mean-min\""),
            "{text}"
        );
        let err = |v: serde_json::Value| SequenceConfig::from_params(&v).unwrap_err().to_string();
        let e = err(serde_json::json!({"perf_base": "mean"}));
        assert!(
            e.contains("generation-mean") && e.contains("\"mean\""),
            "{e}"
        );
        assert!(e.contains("target-mean"), "{e}");
        let e = err(serde_json::json!({"aggregate": "median"}));
        assert!(e.contains("unknown variant `median`"), "{e}");
        let e = err(serde_json::json!({"perf_base": 2.5}));
        assert!(e.contains("perf_base is 2.5"), "{e}");
        let e = err(serde_json::json!({"trigers": 3}));
        assert!(e.contains("unknown field `trigers`"), "{e}");
        let e = err(serde_json::json!({"independent_conditions": 1}));
        assert!(e.contains("sequence"), "{e}");
        assert_eq!(
            SequenceConfig::from_params(&serde_json::Value::Null).unwrap(),
            SequenceConfig::default()
        );
    }

    #[test]
    fn layout_is_size_and_two_sensors() {
        let t = task(SequenceConfig {
            size: 10,
            ..SequenceConfig::default()
        });
        assert_eq!(
            t.layout(),
            Layout {
                size: 10,
                n_inputs: 2
            }
        );
    }

    /// The paper's size: 1000 random 5-neuron networks, 4 trials of 10 triggers.
    /// Run with `cargo test -p tasks --release -- --ignored --nocapture paper_size`.
    #[test]
    #[ignore]
    fn paper_size_generation_timing() {
        let t = task(SequenceConfig::default());
        let nets = random_networks(1000, 1);
        t.evaluate(&nets, 0, 0, None).unwrap();
        let reps = 20;
        let start = std::time::Instant::now();
        for g in 0..reps {
            t.evaluate(&nets, g, 0, None).unwrap();
        }
        let per = start.elapsed().as_secs_f64() / reps as f64;
        println!(
            "1000 networks x 4 trials: {:.1} ms per generation on {} threads",
            per * 1e3,
            rayon::current_num_threads()
        );
    }
}
