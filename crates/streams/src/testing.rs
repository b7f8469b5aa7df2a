//! Internals that the crate's own integration tests (`tests/unit`) check directly. Not public
//! API: hidden from the documentation, and free to change or go at any time. It exists so that
//! the unit tests build as an integration test, against the library that `cargo test` builds
//! anyway, instead of compiling the whole crate a second time as a unit-test harness.

use crate::Stream;

/// A stream with the raw xoshiro256++ state `s`, for checking against the reference vectors.
pub fn from_state(s: [u64; 4]) -> Stream {
    Stream::from_state(s)
}
