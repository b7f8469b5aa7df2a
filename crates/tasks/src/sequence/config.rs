//! The sequence task's settings: targets, timings, the score's base, clamp and aggregate.

use std::fmt;

use ctrnn::{Error, Integrator, Precision, Result};
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::common::{config_from_params, TIME_STEP};
use crate::Aggregate;

/// What the two sensors are, for error messages.
pub(super) const SENSORS: &str = "trigger, reinforcement";

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
    /// Per trial, then averaged: the formula of `docs/paper.md`, "Sequence learning". An output stuck at 0 scores 1 on every
    /// 0* trial and 0 on every 1* trial, so 0.5 on B = {0*, 1*}.
    #[default]
    Trial,
    /// Once, on the mean of the trials' unclamped scores, so that failing one target cancels
    /// succeeding at another: any constant output scores 0 on B = {0*, 1*}.
    Evaluation,
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
    /// How the targets' scores make one fitness (each target's score is the mean over its
    /// trials, clamped as `clamp` says). Default `"mean"`.
    pub aggregate: Aggregate,
    /// How one time step is integrated; `dt * substeps` is the length of a time step in units of
    /// simulated time. Default 10 Euler steps of dt = 0.1.
    pub integrator: Integrator,
    /// The floating-point type the networks compute in: `"f64"` (default, the reference) or
    /// `"f32"`, opt-in single precision (see [`ctrnn::Precision`]). The world, the inputs and the
    /// scores stay `f64`; each input is rounded to `f32` as the network reads it.
    pub precision: Precision,
    /// Whether each individual draws its own timings (`Purpose::Trial` stream with its index)
    /// instead of sharing the generation's. Default false.
    pub independent_conditions: bool,
    /// Whether an evaluation's trials run as one chain, without resetting the state between
    /// them, in an order drawn for each generation ([`SequenceTask::trial_order`]): every trial
    /// after the first starts where the one before it ended, after its last reinforcement and
    /// gap, so a network must notice from the reinforcement that the target changed and switch,
    /// as the paper's Fig. 5 shows its 2-bit network doing. Each trial is scored as without it.
    /// Validation and assessment still start every trial from rest. Default false.
    ///
    /// [`SequenceTask::trial_order`]: super::SequenceTask::trial_order
    pub chain: bool,
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
            integrator: TIME_STEP,
            precision: Precision::F64,
            independent_conditions: false,
            chain: false,
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
