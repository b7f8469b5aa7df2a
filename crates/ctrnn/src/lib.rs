//! Continuous-time recurrent neural networks ("dynamical neural networks") after Yamauchi & Beer:
//! the model, its integrators for one network or a whole population, and the network file format.
//!
//! This crate knows no task and no Python.
//!
//! # Example
//! ```
//! use ctrnn::{Integrator, Network, Population, Inputs};
//! let net = Network::new(vec![1.0, 2.0], vec![0.0, 0.0], vec![0.0, 1.0, 1.0, 0.0], vec![1.0, 1.0], None)?;
//! let mut pop = Population::new(&[net.clone(), net])?;
//! let states = pop.run(Inputs::Shared(&[1.0; 3]), 3, &Integrator::default(), true, None)?;
//! assert_eq!(states.len(), 2 * 3 * 2); // P x T x N
//! # Ok::<(), ctrnn::Error>(())
//! ```
#![warn(missing_docs)]

pub mod analysis;
pub mod batch;
pub mod error;
pub mod evolve;
pub mod ga;
pub mod genome;
pub mod integrate;
pub mod io;
pub mod limits;
pub mod math;
pub mod names;
pub mod network;
pub mod population;
mod rows;
pub mod simd;
mod spin;
// Internals for ctrnn's own integration tests (tests/unit); not public API.
#[doc(hidden)]
pub mod testing;
pub mod validation;
mod vector;

pub use batch::Batch;
pub use error::{Error, Result};
pub use evolve::{Evolution, Fill, Stats, Task};
pub use ga::{GaConfig, Selection};
pub use genome::{Layout, Ranges};
pub use integrate::{Integrator, Lanes, Method, Precision, LANES};
pub use network::{compose, compose_with, Network, Params};
pub use population::{Block, Inputs, Population};
/// The random streams, from the `streams` crate (kept here under their old path).
pub use streams as rng;
pub use streams::{Purpose, Stream};
pub use validation::Validation;
pub use vector::Elem;
