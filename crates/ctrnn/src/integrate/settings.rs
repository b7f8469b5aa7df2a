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
    /// The `dt / tau` from which a step of this method makes a neuron's own decay, `dv/dt =
    /// -v / tau`, grow without bound instead of shrink: 2 for Euler (`|1 - h| < 1` ends there),
    /// 2.7853 for classical RK4 (where its stability interval on the negative real axis ends).
    /// At and beyond it a network's integration is no longer its dynamics.
    pub fn unstable_from(self) -> f64 {
        match self {
            Method::Euler => 2.0,
            Method::Rk4 => RK4_STABILITY_END,
        }
    }

    /// The lower-case name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Euler => "euler",
            Method::Rk4 => "rk4",
        }
    }
}

/// Where classical RK4's stability interval on the negative real axis ends: the root of
/// `1 - z + z^2/2 - z^3/6 + z^4/24 = 1` in `z`, `dt / tau`, other than 0.
const RK4_STABILITY_END: f64 = 2.785_293_563_405_282;

/// A number for a message: four significant digits (rounded to nearest), in exponent form when
/// very large or small.
pub(crate) fn short(x: f64) -> String {
    rounded(x, f64::round)
}

/// A number for a message, exact (the shortest text that reads back as `x`), in exponent form
/// when very large or small: `1e-300`, not three hundred digits.
pub(crate) fn exact(x: f64) -> String {
    if x != 0.0 && (x.abs() >= 1e16 || x.abs() < 1e-5) {
        return format!("{x:e}");
    }
    format!("{x}")
}

/// [`short`] rounded down, for a bound that `x` must stay below: the bound it prints is one.
fn short_below(x: f64) -> String {
    rounded(x, f64::floor)
}

/// `x` to four significant digits by `round` (in exponent form, rounded to nearest, when very
/// large or small).
fn rounded(x: f64, round: fn(f64) -> f64) -> String {
    if x != 0.0 && (x.abs() >= 1e5 || x.abs() < 1e-3) || !x.is_finite() {
        return format!("{x:.3e}");
    }
    let digits = 3 - x.abs().log10().floor().max(-4.0) as i32;
    let scale = 10f64.powi(digits.max(0));
    format!("{}", round(x * scale) / scale)
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

    /// Fails when a step of `dt` is too long for a time constant `tau` (of `what`, named in the
    /// message): when `dt / tau` reaches [`Method::unstable_from`], where the neuron's own decay
    /// would grow without bound and the integration would return numbers that are not the
    /// network's dynamics (a period-2 flicker, then overflow).
    ///
    /// ```
    /// use ctrnn::{Integrator, Method};
    /// let euler = Integrator { dt: 0.1, ..Default::default() };
    /// euler.check_step(0.06, "tau[0]")?;
    /// let e = euler.check_step(0.04, "tau[0]").unwrap_err().to_string();
    /// assert!(e.contains("dt / tau is 2.5 for tau[0] = 0.04 (dt 0.1)"), "{e}");
    /// Integrator { method: Method::Rk4, ..euler }.check_step(0.04, "tau[0]")?;
    /// # Ok::<(), ctrnn::Error>(())
    /// ```
    pub fn check_step(&self, tau: f64, what: &str) -> Result<()> {
        let limit = self.method.unstable_from();
        let h = self.dt / tau;
        if h < limit {
            return Ok(());
        }
        let other = match self.method {
            Method::Euler => format!(
                ", or method rk4 (to dt / tau < {})",
                short(RK4_STABILITY_END)
            ),
            Method::Rk4 => String::new(),
        };
        Err(Error::InvalidArgument(format!(
            "dt / tau is {} for {what} = {} (dt {}); from {} on, {} steps make a neuron's own decay \
             grow without bound: use dt < {}{other}",
            short(h),
            exact(tau),
            exact(self.dt),
            short(limit),
            match self.method {
                Method::Euler => "Euler",
                Method::Rk4 => "RK4",
            },
            short_below(limit * tau),
        )))
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
