//! The robot's pose: where its centre is and which way it faces.

use std::f64::consts::{PI, TAU};

/// A robot's pose in the room's frame (metres and radians).
///
/// The room spans `[0, width] x [0, height]` with `+x` to the right and `+y` up; `heading` is
/// measured from `+x`, counter-clockwise positive, and is kept in `(-pi, pi]` by
/// [`RobotSpec::step`](crate::RobotSpec::step).
///
/// # Example
/// ```
/// use sim2d::Pose;
/// let p = Pose::new(1.0, 2.0, std::f64::consts::FRAC_PI_2); // facing +y
/// let [dx, dy] = p.direction();
/// assert!(dx.abs() < 1e-12 && (dy - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Pose {
    /// The centre's x in metres (default 0).
    pub x: f64,
    /// The centre's y in metres (default 0).
    pub y: f64,
    /// The heading in radians from `+x`, counter-clockwise positive (default 0).
    pub heading: f64,
}

impl Pose {
    /// A pose at `(x, y)` facing `heading` radians.
    pub fn new(x: f64, y: f64, heading: f64) -> Self {
        Pose { x, y, heading }
    }

    /// The centre as `[x, y]`.
    pub fn position(&self) -> [f64; 2] {
        [self.x, self.y]
    }

    /// The unit vector the robot faces.
    pub fn direction(&self) -> [f64; 2] {
        let (s, c) = self.heading.sin_cos();
        [c, s]
    }

    /// The unit vector at `angle` radians from the heading (counter-clockwise positive).
    pub fn direction_at(&self, angle: f64) -> [f64; 2] {
        let (s, c) = (self.heading + angle).sin_cos();
        [c, s]
    }
}

/// `angle` wrapped into `(-pi, pi]`.
///
/// # Example
/// ```
/// use sim2d::wrap_angle;
/// assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
/// ```
pub fn wrap_angle(angle: f64) -> f64 {
    if !angle.is_finite() {
        return angle;
    }
    let mut a = angle.rem_euclid(TAU); // [0, 2 pi)
    if a > PI {
        a -= TAU;
    }
    a
}
