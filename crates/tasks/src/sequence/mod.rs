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
//! [`Purpose::Evaluate`](ctrnn::Purpose::Evaluate), see [`SequenceTask::assessment_timings`]), in at least 90 %
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

mod config;
pub(crate) mod scoring;
mod task;
mod trial;

pub use crate::Aggregate;
pub use config::{Clamp, PerfBase, SequenceConfig};
pub use scoring::{performance, warmup, SUCCESS_FRACTION, SUCCESS_TRIALS};
pub use task::{Assessment, Scores, SequenceTask, TargetReport, TrialRecord};
