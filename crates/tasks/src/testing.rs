//! Internals and helpers for the crate's own integration tests (`tests/unit`, `tests/golden.rs`,
//! `tests/validation.rs`). Not public
//! API: hidden from the documentation, and free to change or go at any time. It exists so that
//! the unit tests build as an integration test, against the library that `cargo test` builds
//! anyway, instead of compiling the whole crate a second time as a unit-test harness.

use ctrnn::genome::{self, Layout, Ranges};
use ctrnn::{Network, Purpose, Stream};

pub use crate::common::Diverged;
pub use crate::lanes::{by_block, by_pair, pairs, Kinds};

/// `count` random networks of `layout` over the paper's ranges: network `i` is genome `i` of the
/// genetic algorithm's initial population for `seed`, drawn from
/// `Stream::new(seed, 0, Purpose::Init, i, 0)`.
pub fn random_networks(layout: Layout, count: usize, seed: u64) -> Vec<Network> {
    (0..count)
        .map(|i| {
            let mut s = Stream::new(seed, 0, Purpose::Init, i as u64, 0);
            genome::decode(layout, &genome::random(layout, &Ranges::default(), &mut s))
                .expect("a random genome decodes")
        })
        .collect()
}

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
