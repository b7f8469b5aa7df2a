//! ctrnn's unit tests, one module per source file of the library, named after it.
//!
//! They are one integration test, not `#[cfg(test)]` modules in the library: a unit-test
//! harness compiles the whole library, its SIMD kernels included, a second time, the largest
//! unit of a clean `cargo test` build. The few internals they check are reached through
//! `ctrnn::testing`, which is not public API.

mod analysis;
mod batch;
mod error;
mod evolve;
mod ga;
mod genome;
mod integrate;
mod io;
mod math;
mod network;
mod population;
mod rows;
mod simd;
mod validation;
