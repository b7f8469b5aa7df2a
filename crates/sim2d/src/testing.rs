//! Internals that the crate's own integration tests (`tests/unit`) check directly. Not public
//! API: hidden from the documentation, and free to change or go at any time. It exists so that
//! the unit tests build as an integration test, against the library that `cargo test` builds
//! anyway, instead of compiling the whole crate a second time as a unit-test harness.

/// The range checks behind every message of [`crate::Error::Invalid`].
pub mod error {
    pub use crate::error::{check_finite, check_range};
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
