//! Dynamical analysis of a network with its sensors held at a constant input: its equilibria and
//! their stability, its attracting limit cycles, and how both change as one input is swept
//! (folds and Hopf points).
//!
//! This is how evolved CTRNNs are explained in the field (Beer 1995, "On the dynamics of small
//! continuous-time recurrent neural networks"): a network that holds a bit holds it in which of
//! its attractors the state sits, and an input that flips the bit moves the state across a basin
//! boundary or removes an attractor at a fold.
//!
//! - [`equilibria`]: Newton's method from many starts, deduplicated, each with its eigenvalues,
//!   [`Stability`] and slowest time scale.
//! - [`limit_cycles`]: long RK4 integration, a Poincaré section, and Floquet multipliers.
//! - [`bifurcation`]: a sweep of one input with folds and Hopf points located by bisection, and
//!   the limit cycles followed as [`CycleBranch`]es with where each starts and ends.
//! - [`vector_field`] and [`jacobian`] for checks and plots.
//!
//! # Example
//! ```
//! use ctrnn::analysis::{equilibria, EquilibriumSearch};
//! use ctrnn::Network;
//! // A centre-crossing pair: theta_i = sum_j weights[i][j] / 2 puts an equilibrium at v = theta.
//! let net = Network::new(vec![1.0, 1.0], vec![2.5, 0.5], vec![3.0, 2.0, -1.0, 2.0], vec![], None)?;
//! let eq = equilibria(&net, &[], &EquilibriumSearch::default())?;
//! assert!(eq.iter().any(|e| (e.state[0] - 2.5).abs() < 1e-9 && (e.state[1] - 0.5).abs() < 1e-9));
//! # Ok::<(), ctrnn::Error>(())
//! ```

mod bifurcation;
pub(crate) mod branches;
mod cycles;
pub(crate) mod equilibria;
pub(crate) mod events;
mod field;
pub(crate) mod stability;

pub use bifurcation::{bifurcation, Bifurcation, Sweep};
pub use branches::{CycleBranch, CycleEnd, CycleEndKind, CYCLE_BISECTIONS};
pub use cycles::{limit_cycles, Cycle, CycleSearch, TRIVIAL_MULTIPLIER};
pub use equilibria::{
    equilibria, equilibria_cancellable, Equilibrium, EquilibriumSearch, RETRY_STARTS,
};
pub use events::{Event, EventKind, CRITICAL};
pub use field::{jacobian, vector_field};
pub use stability::{Stability, MARGINAL};
