//! sim2d's unit tests, one module per source file of the library that held them, named after it.
//!
//! They are one integration test, not `#[cfg(test)]` modules in the library: a unit-test
//! harness compiles the whole library a second time. The few internals they check are reached
//! through `sim2d::testing`, which is not public API.

mod error;
mod fleet;
mod pose;
mod pursuer;
mod ring;
mod robot;
mod scene;
mod sectors;
mod sim;
mod sonar;
mod wall_follow;
mod world;
mod world_spec;
