//! Integration settings: the method, the step size and the steps per input row.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// The integration method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Forward Euler, the paper's method (default).
    #[default]
    Euler,
    /// Classical fourth-order Runge-Kutta.
    Rk4,
}

impl std::str::FromStr for Method {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::names::parse_name("method", s).map_err(Error::InvalidArgument)
    }
}

impl Method {
    /// The lower-case name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Euler => "euler",
            Method::Rk4 => "rk4",
        }
    }
}

/// The floating-point type an integration computes in.
///
/// `f64` is the default and the reference: every published result, preset and stored
/// fingerprint is `f64`. `f32` is opt-in: the parameters (time constants, thresholds, weights),
/// the step size and each input row are rounded to `f32` once, and every state, firing rate and
/// step is computed in `f32` with its own exponential ([`crate::math::exp_f32`]). Like `f64`, it
/// performs one sequence of IEEE operations, so every kernel gives the same `f32` bits; they are
/// not `f64`'s bits, and trajectories drift apart from `f64`'s over time (faster in chaotic
/// networks).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// IEEE binary64 (default).
    #[default]
    F64,
    /// IEEE binary32, opt-in.
    F32,
}

impl std::str::FromStr for Precision {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::names::parse_name("precision", s).map_err(Error::InvalidArgument)
    }
}

impl Precision {
    /// The lower-case name used in files and on the command line: `"f64"` or `"f32"`.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }
}

/// Integration settings: each input row is held for `substeps` steps of `dt`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Integrator {
    /// Integration method. Default: Euler.
    pub method: Method,
    /// Step size in units of simulated time. Default: 0.1.
    pub dt: f64,
    /// Integration steps per input row. Default: 1.
    pub substeps: usize,
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator {
            method: Method::Euler,
            dt: 0.1,
            substeps: 1,
        }
    }
}

impl Integrator {
    /// Checks `dt` is finite and > 0 and `substeps >= 1`.
    pub fn validate(&self) -> Result<()> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "dt is {}; it must be finite and > 0",
                self.dt
            )));
        }
        if self.substeps == 0 {
            return Err(Error::InvalidArgument(
                "substeps is 0; it must be >= 1".into(),
            ));
        }
        Ok(())
    }

    /// The same method with a step `factor` times shorter and `factor` times as many steps per
    /// input row, so an input row lasts as long; an error when the step count overflows.
    ///
    /// ```
    /// let i = ctrnn::Integrator { dt: 0.1, substeps: 10, ..Default::default() };
    /// let f = i.finer(10)?;
    /// assert_eq!((f.dt, f.substeps), (0.1 / 10.0, 100));
    /// # Ok::<(), ctrnn::Error>(())
    /// ```
    pub fn finer(&self, factor: usize) -> Result<Integrator> {
        let substeps = self.substeps.checked_mul(factor).filter(|_| factor > 0);
        match substeps {
            Some(substeps) => Ok(Integrator {
                dt: self.dt / factor as f64,
                substeps,
                ..*self
            }),
            None => Err(Error::InvalidArgument(format!(
                "substeps {} x {factor} is not a step count",
                self.substeps
            ))),
        }
    }
}
