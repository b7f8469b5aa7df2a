//! The crate's one error type.
//!
//! Every fallible function of `sim2d` returns [`Error`]. A message names the field that was wrong,
//! its value and what is allowed, for example `sonar.cone_deg is -3; it must be in (0, 180)`.

use std::fmt::Display;

/// Everything that can go wrong in `sim2d`: bad parameters, bad world files, impossible starts.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter or argument is outside its allowed range.
    #[error("{field} is {value}; it must be {allowed}")]
    Invalid {
        /// The field's path, such as `boxes[1].size[0]` or `sonar.cone_deg`.
        field: String,
        /// The offending value, as written by `Display`.
        value: String,
        /// What is allowed, such as `in (0, 180)`.
        allowed: String,
    },
    /// A world file is not valid TOML or does not have the world's fields.
    #[error("world file: {0}")]
    Toml(String),
    /// Rejection sampling found no start position in the start region that keeps the robot clear
    /// of every wall and box.
    #[error(
        "no start pose: {attempts} random positions in the start region all put a robot of radius \
         {radius} m closer than {clearance} m to a wall or box; enlarge start or move the boxes"
    )]
    NoStartPose {
        /// How many positions were tried.
        attempts: u32,
        /// The robot's radius in metres.
        radius: f64,
        /// The clearance that was required, in metres.
        clearance: f64,
    },
    /// Too little of the start region keeps a robot clear of every wall and box for starts to
    /// be drawn reliably ([`World::check_start`](crate::World::check_start)).
    #[error(
        "the start region is free for a robot of radius {radius} m, {clearance} m from every wall \
         and box, at {:.2}% of its points; at least {:.0}% must be: enlarge start or move the boxes",
        100.0 * share,
        100.0 * needed
    )]
    StartBlocked {
        /// The free share of the start region, in [0, 1).
        share: f64,
        /// The share needed.
        needed: f64,
        /// The robot's radius in metres.
        radius: f64,
        /// The clearance that was required, in metres.
        clearance: f64,
    },
}

impl Error {
    /// An [`Error::Invalid`] for `field` with `value`, which must be `allowed`.
    pub(crate) fn invalid(field: impl Into<String>, value: impl Display, allowed: &str) -> Self {
        Error::Invalid {
            field: field.into(),
            value: value.to_string(),
            allowed: allowed.to_string(),
        }
    }
}

/// Checks that `value` is finite and inside the interval `(lo, hi)` with the given closedness;
/// returns an [`Error::Invalid`] for `field` otherwise.
pub fn check_range(
    field: &str,
    value: f64,
    lo: f64,
    lo_closed: bool,
    hi: f64,
    hi_closed: bool,
) -> Result<(), Error> {
    let above = if lo_closed { value >= lo } else { value > lo };
    let below = if hi_closed { value <= hi } else { value < hi };
    if value.is_finite() && above && below {
        return Ok(());
    }
    let allowed = match (lo == f64::NEG_INFINITY, hi == f64::INFINITY) {
        (true, true) => "a finite number".to_string(),
        (false, true) => format!(
            "a finite number {} {lo}",
            if lo_closed { ">=" } else { ">" }
        ),
        (true, false) => format!(
            "a finite number {} {hi}",
            if hi_closed { "<=" } else { "<" }
        ),
        (false, false) => format!(
            "in {}{lo}, {hi}{}",
            if lo_closed { '[' } else { '(' },
            if hi_closed { ']' } else { ')' }
        ),
    };
    Err(Error::invalid(field, number(value), &allowed))
}

/// `x` for a message: as Rust writes it, or in exponent form when that would take more than a
/// line (`1e300`, not three hundred digits).
fn number(x: f64) -> String {
    let plain = x.to_string();
    if plain.len() > 20 {
        format!("{x:e}")
    } else {
        plain
    }
}

/// The most of anything a robot has that its settings count (a sonar's rays, the sonars of a
/// ring, sectors, pursuers): far above any real robot, and small enough that a typing error (a
/// count of `10**9`) is an error naming the setting, not an allocation that takes the machine.
pub const MAX_PARTS: u64 = 4096;

/// Checks that a count of parts is in `least..=MAX_PARTS`.
pub fn check_count(field: &str, value: u64, least: u64) -> Result<(), Error> {
    if (least..=MAX_PARTS).contains(&value) {
        Ok(())
    } else {
        Err(Error::invalid(
            field,
            value,
            &format!("in [{least}, {MAX_PARTS}]"),
        ))
    }
}

/// Checks that `value` is a finite number.
pub fn check_finite(field: &str, value: f64) -> Result<(), Error> {
    check_range(field, value, f64::NEG_INFINITY, false, f64::INFINITY, false)
}
