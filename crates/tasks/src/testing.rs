//! Internals that the crate's own integration tests (`tests/unit`) check directly. Not public
//! API: hidden from the documentation, and free to change or go at any time. It exists so that
//! the unit tests build as an integration test, against the library that `cargo test` builds
//! anyway, instead of compiling the whole crate a second time as a unit-test harness.

pub use crate::common::Diverged;
pub use crate::lanes::{by_block, by_pair, pairs};

/// The sequence task's scoring.
pub mod sequence {
    pub use crate::sequence::scoring::{correct, mean, score};
}

/// The landmark task's trial sets.
pub mod landmark {
    use ctrnn::Result;

    use crate::landmark::{LandmarkTask, Sensing};

    /// The validation set of `task` when training varies; `None` when training is off.
    pub fn varied_validation_trials(
        task: &LandmarkTask,
        seed: u64,
    ) -> Option<Result<Vec<Sensing>>> {
        task.varied_validation_trials(seed)
    }
}
