//! The tasks crate's unit tests, one module per source file of the library that held them, named
//! after it.
//!
//! They are one integration test, not `#[cfg(test)]` modules in the library: a unit-test
//! harness compiles the whole library a second time. The few internals they check are reached
//! through `tasks::testing`, which is not public API.

mod landmark;
mod lanes;
mod nav1d;
mod registry;
mod run_config;
mod sequence;
