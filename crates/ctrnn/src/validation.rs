//! Validated champions: the best candidates of each generation, by training fitness, re-scored on
//! a validation set of fresh conditions that stays fixed for the whole run.
//!
//! Training fitness is measured on a few trial conditions per generation (common random
//! numbers), so the fittest individual of a generation can be one that was lucky on those
//! conditions. A run therefore re-scores its top `validation_candidates` individuals by training
//! fitness on the task's validation set, drawn once per run from
//! `Stream::new(seed, 0, Purpose::Validate, 0, t)`: a stream that neither training
//! ([`Purpose::Trial`](crate::Purpose::Trial)) nor assessment
//! ([`Purpose::Evaluate`](crate::Purpose::Evaluate)) draws from. The champion is the candidate
//! with the best [`Validation`] seen in any generation. Selection and breeding never see these
//! scores, so evolution itself is unchanged.
//!
//! With [`GaConfig::champion_step_check`](crate::GaConfig::champion_step_check), a candidate that
//! would replace the champion is validated again with an integration [`STEP_CHECK_FINER`] times
//! finer ([`Task::validate_finer`](crate::Task::validate_finer)), and counts with the
//! [`worse`](Validation::worse) of its two validations: a network whose behaviour lives in the
//! integrator's error at the run's step is not chosen. Only would-be champions are checked, so
//! the check costs a few validations per replacement of the champion, not one per candidate.
//!
//! # Example
//! ```
//! use ctrnn::validation::{candidates, Validation};
//! // The top 2 by training fitness; ties go to the lower index.
//! assert_eq!(candidates(&[0.2, 0.9, 0.5, 0.9], 2), vec![1, 3]);
//! let a = Validation { rate: 1.0, score: 0.8 };
//! let b = Validation { rate: 0.95, score: 0.99 };
//! assert!(a.beats(&b) && !b.beats(&a) && !a.beats(&a));
//! ```

use serde::{Deserialize, Serialize};

/// How one network did on the validation set.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Validation {
    /// The fraction of validation conditions done right under the task's success rule (for a
    /// task with several targets, the lowest target's fraction), in [0, 1].
    pub rate: f64,
    /// The mean of the task's trial score over the validation set, finite (the built-in tasks'
    /// lie in [0, 1]): the margin that separates networks with the same rate.
    pub score: f64,
}

impl Validation {
    /// Whether `self` is strictly better than `other`: a higher rate, or the same rate and a
    /// higher score.
    pub fn beats(&self, other: &Validation) -> bool {
        self.rate > other.rate || (self.rate == other.rate && self.score > other.score)
    }

    /// The lower rate and the lower score of the two: how a network did under both of two
    /// integrations of the same validation set.
    pub fn worse(&self, other: &Validation) -> Validation {
        Validation {
            rate: self.rate.min(other.rate),
            score: self.score.min(other.score),
        }
    }
}

/// How many times shorter the step check's integration step is than the run's, each time step
/// kept as long: `dt / STEP_CHECK_FINER`, `substeps * STEP_CHECK_FINER`
/// ([`Integrator::finer`](crate::Integrator::finer)).
pub const STEP_CHECK_FINER: usize = 10;

/// The indices of the `k` highest fitness values (all of them when `k >= fitness.len()`), best
/// first; among equal fitness the lower index comes first. NaN never occurs here: fitness has
/// been checked before.
pub fn candidates(fitness: &[f64], k: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..fitness.len()).collect();
    order.sort_by(|&a, &b| fitness[b].total_cmp(&fitness[a]).then(a.cmp(&b)));
    order.truncate(k);
    order
}
