//! Forward Euler and classical RK4 for one network or a block of networks stepped together.
//!
//! The kernel works on [`Lanes`]: `L` networks of the same shape, stored parameter by parameter
//! with the networks side by side (`theta[i][lane]`), so that one step is straight-line
//! arithmetic over rows of `L` values, one per network. A single network is `Lanes<1>` and a
//! population block is `Lanes<LANES>`. The kernel is written once over the crate's lane vectors,
//! and `simd.rs` chooses at run time, from the CPU the process runs on, whether a block keeps
//! each row in AVX-512 or AVX2 registers (NEON on 64-bit ARM), or runs lane by lane. Every path performs
//! the same operations in the same order, which is why single networks and populations agree bit
//! for bit.
//!
//! One Euler step of size `dt`, with `h = dt / tau`:
//! `v += h * (-v + W f(v - theta) + S I)`. Each row of inputs is held for `substeps` steps.
//!
//! The parts: the settings ([`Integrator`], [`Method`]), the packing of networks into lanes
//! ([`Lanes`]), and the step itself (`kernel.rs`).

use std::sync::atomic::AtomicBool;

use crate::error::{Error, Result};
use crate::limits;
use crate::network::Network;
use crate::vector::Elem;

pub(crate) mod kernel;
mod lanes;
mod settings;
mod step_limit;

pub(crate) use lanes::CANCEL_CHECK_STEPS;
pub use lanes::{copy_lane, diverged, Lanes, LANES};
pub use settings::{Integrator, Method, Precision};
pub use step_limit::check_step;
pub(crate) use step_limit::Shortest;

impl Network {
    /// Integrates the network through `steps` rows of `inputs` (row-major `steps x n_inputs`),
    /// each held for `integ.substeps` steps, and returns the state after every row
    /// (row-major `steps x size`). The network keeps the final state.
    ///
    /// # Example
    /// ```
    /// use ctrnn::{Integrator, Network};
    /// let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    /// let states = net.run(&[1.0, 1.0], 2, &Integrator::default()).unwrap();
    /// // v += 0.1 * (-v + 1): 0.1, then 0.19
    /// assert!((states[0] - 0.1).abs() < 1e-15 && (states[1] - 0.19).abs() < 1e-15);
    /// ```
    pub fn run(&mut self, inputs: &[f64], steps: usize, integ: &Integrator) -> Result<Vec<f64>> {
        self.run_cancellable(inputs, steps, integ, None)
    }

    /// [`Network::run`] that stops with [`Error::Interrupted`] once `cancel` is set.
    pub fn run_cancellable(
        &mut self,
        inputs: &[f64],
        steps: usize,
        integ: &Integrator,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        self.run_in(inputs, steps, integ, Precision::F64, cancel)
    }

    /// [`Network::run_cancellable`] computing in `precision`. In [`Precision::F32`] the
    /// parameters, the state and each input are rounded to `f32` once, the network steps in
    /// `f32` with the bits of a population run in `f32`, and the states returned, and kept, are
    /// the `f32` states widened (exactly) to `f64`.
    ///
    /// # Example
    /// ```
    /// use ctrnn::{Integrator, Network, Precision};
    /// let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None)?;
    /// let states = net.run_in(&[1.0, 1.0], 2, &Integrator::default(), Precision::F32, None)?;
    /// // v += 0.1 * (-v + 1) in f32: 0.1, then 0.19, widened to f64.
    /// assert_eq!(states, [0.1f32 as f64, (0.1f32 + 0.1f32 * (1.0 - 0.1f32)) as f64]);
    /// assert_eq!(net.state(), &states[1..]);
    /// # Ok::<(), ctrnn::Error>(())
    /// ```
    pub fn run_in(
        &mut self,
        inputs: &[f64],
        steps: usize,
        integ: &Integrator,
        precision: Precision,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        integ.validate()?;
        check_step(&[self.params()], integ)?;
        limits::check_work(1, steps, integ.substeps)?;
        check_inputs(
            inputs,
            limits::product(&[steps, self.n_inputs()], "inputs")?,
            "steps x n_inputs",
        )?;
        match precision {
            Precision::F64 => self.run_lanes::<f64>(inputs, steps, integ, cancel),
            Precision::F32 => self.run_lanes::<f32>(inputs, steps, integ, cancel),
        }
    }

    /// [`Network::run_in`] on one lane of element type `E`, its inputs checked.
    fn run_lanes<E: Elem>(
        &mut self,
        inputs: &[f64],
        steps: usize,
        integ: &Integrator,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        let (n, m) = (self.size(), self.n_inputs());
        let mut lanes = Lanes::<1, E>::new(&[self])?;
        let mut states = limits::zeros(limits::product(&[steps, n], "states")?, "recorded states")?;
        lanes.run_rows(
            steps,
            integ,
            cancel,
            |t, row| {
                for k in 0..m {
                    row[k][0] = E::from_f64(inputs[t * m + k]);
                }
            },
            |t, state| {
                for (into, v) in states[t * n..(t + 1) * n].iter_mut().zip(state) {
                    *into = v[0].to_f64();
                }
            },
        )?;
        lanes.check_finite(|_| "the network".into())?;
        for (into, i) in self.state_mut().iter_mut().zip(0..n) {
            *into = lanes.state(i)[0].to_f64();
        }
        Ok(states)
    }
}

/// Checks an input array's length and that every value is finite.
pub(crate) fn check_inputs(inputs: &[f64], want: usize, shape: &str) -> Result<()> {
    if inputs.len() != want {
        return Err(Error::InvalidArgument(format!(
            "inputs have {}; expected {shape} = {want}",
            crate::error::counted(inputs.len(), "value")
        )));
    }
    match inputs.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(k) => Err(Error::InvalidArgument(format!(
            "inputs contain {} at flat index {k}; every input must be finite",
            inputs[k]
        ))),
    }
}
