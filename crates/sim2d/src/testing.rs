//! Internals that the crate's own integration tests (`tests/unit`) check directly. Not public
//! API: hidden from the documentation, and free to change or go at any time. It exists so that
//! the unit tests build as an integration test, against the library that `cargo test` builds
//! anyway, instead of compiling the whole crate a second time as a unit-test harness.

/// The range checks behind every message of [`crate::Error::Invalid`].
pub mod error {
    use crate::Error;

    /// Checks that `value` is finite and inside the interval `(lo, hi)` with the given
    /// closedness; an [`Error::Invalid`] for `field` otherwise.
    pub fn check_range(
        field: &str,
        value: f64,
        lo: f64,
        lo_closed: bool,
        hi: f64,
        hi_closed: bool,
    ) -> Result<(), Error> {
        crate::error::check_range(field, value, lo, lo_closed, hi, hi_closed)
    }

    /// Checks that `value` is a finite number; an [`Error::Invalid`] for `field` otherwise.
    pub fn check_finite(field: &str, value: f64) -> Result<(), Error> {
        crate::error::check_finite(field, value)
    }
}

/// The wall follower's internals.
pub mod wall_follow {
    use crate::{Pose, WallFollower, World};

    /// The heading in radians that `follower`'s seek phase picks at `pose`: towards the nearest
    /// outer wall with a clear corridor, else the nearest wall.
    pub fn choose_wall(follower: &WallFollower, world: &World, pose: &Pose) -> f64 {
        follower.choose_wall(world, pose)
    }
}
