//! The robot: a disc with differential drive, and its collision-safe motion.
//!
//! # Motion
//! With wheel speeds `v_left`, `v_right` (m/s, each clamped to `±max_speed`) the robot moves at
//! `v = (v_left + v_right) / 2` along its heading and turns at `omega = (v_right - v_left) /
//! wheel_base` (counter-clockwise positive). Within one step both are constant, so a step ends
//! exactly where the circular arc of that motion ends, with the heading turned by `omega dt`. On
//! the way the centre moves along the arc's *chord*, which departs from the arc by at most its
//! sagitta, `|v| dt * |omega| dt / 8` (under 3 mm at 0.6 m/s and 2 rad/s with `dt = 0.1` s).
//!
//! # Collisions
//! The disc never overlaps a wall or a box: its clearance (the distance from its edge to the
//! nearest obstacle) stays at least [`CONTACT_MARGIN`]. Every obstacle is convex, so the distance
//! from a point moving along a straight line to it is a convex function of the distance travelled,
//! and lies above its tangent: with current clearance margin `e` (clearance minus
//! `CONTACT_MARGIN`) and `a = n . u` (`n` the distance's gradient, `u` the direction of motion),
//! the margin after moving `s` is at least `e + a s`. So a step advances along the chord by
//! `min over obstacles of (e - CONTACT_TOLERANCE) / -a` (obstacles with `a >= 0` do not limit it:
//! the robot is not approaching them, and never will along this line), measures again, and repeats
//! until the chord is done or the allowed advance is shorter than [`MIN_ADVANCE`] (a contact), at
//! most [`MAX_ADVANCE_ITERATIONS`] times. Within `2 CONTACT_TOLERANCE` of the margin an advance
//! uses up at most half of what is left, so motion along a surface goes on while motion into it
//! stops. Against a flat wall this stops at the margin in one advance; the robot slides freely
//! along a wall and leaves it freely.
//!
//! When the translation stops short, the heading still turns by the full `omega * dt`: turning in
//! place never moves a disc's footprint, so a robot against a wall can turn away from it. A pose
//! that already overlaps something can move only in directions that do not make the overlap worse.

use std::f64::consts::PI;

use crate::error::{check_finite, check_range, Error};
use crate::pose::{wrap_angle, Pose};
use crate::world::World;

/// The gap in metres that a moving robot keeps from walls and boxes: 1 mm.
pub const CONTACT_MARGIN: f64 = 1e-3;

/// How close beyond [`CONTACT_MARGIN`] an advance stops, in metres: 10 µm, well above parry2d's
/// `f32` rounding of distances in a room of a few metres (about 1e-6 m).
pub const CONTACT_TOLERANCE: f64 = 1e-5;

/// An advance shorter than this many metres (and short of the step's end) is a contact: 1 µm.
pub const MIN_ADVANCE: f64 = 1e-6;

/// The most advances that one step makes before stopping (and reporting a contact).
pub const MAX_ADVANCE_ITERATIONS: u32 = 32;

/// The robot's body and drive. `Default` is a Nomad-200-sized disc.
///
/// # Example
/// ```
/// use sim2d::{Pose, RobotSpec, World, WorldSpec};
/// let world = World::new(&WorldSpec::landmark(1)?)?;
/// let robot = RobotSpec::default();
/// let mut pose = Pose::new(1.0, 1.0, 0.0);
/// // Both wheels at 0.5 m/s for 1 s: 0.5 m straight ahead.
/// let collided = robot.step(&mut pose, 0.5, 0.5, 1.0, &world)?;
/// assert!(!collided && (pose.x - 1.5).abs() < 1e-12);
/// // Driving into the bottom wall stops the robot 1 mm (CONTACT_MARGIN) short of it.
/// let mut pose = Pose::new(1.0, 1.0, -std::f64::consts::FRAC_PI_2);
/// assert!(robot.step(&mut pose, 1.0, 1.0, 2.0, &world)?);
/// assert!((pose.y - (0.265 + 0.001)).abs() < 1e-4);
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RobotSpec {
    /// The disc's radius in metres, > 0. Default 0.265 (a Nomad 200 is about 0.53 m across).
    pub radius: f64,
    /// The distance between the two drive wheels in metres, > 0. Default 0.45.
    pub wheel_base: f64,
    /// The fastest a wheel can turn, in m/s, > 0; commands beyond it are clamped. Default 1.0.
    pub max_speed: f64,
}

impl Default for RobotSpec {
    fn default() -> Self {
        RobotSpec {
            radius: 0.265,
            wheel_base: 0.45,
            max_speed: 1.0,
        }
    }
}

/// `sin(a) / a`, with its limit 1 at 0.
fn sinc(a: f64) -> f64 {
    if a.abs() < 1e-4 {
        1.0 - a * a / 6.0
    } else {
        a.sin() / a
    }
}

impl RobotSpec {
    /// Checks every field; the error names the first bad one (as `robot.<field>`).
    pub fn validate(&self) -> Result<(), Error> {
        let inf = f64::INFINITY;
        check_range("robot.radius", self.radius, 0.0, false, inf, false)?;
        check_range("robot.wheel_base", self.wheel_base, 0.0, false, inf, false)?;
        check_range("robot.max_speed", self.max_speed, 0.0, false, inf, false)?;
        Ok(())
    }

    /// The wheel speeds `(v_left, v_right)` that drive at `v` m/s while turning at `omega` rad/s.
    pub fn wheels(&self, v: f64, omega: f64) -> (f64, f64) {
        let d = 0.5 * omega * self.wheel_base;
        (v - d, v + d)
    }

    /// Moves `pose` for `dt` seconds with wheel speeds `v_left`, `v_right` in m/s (each clamped to
    /// `±max_speed`), stopping short of any wall or box (see the [module docs](self)). Returns
    /// whether the motion was cut short by a contact.
    ///
    /// The heading ends in `(-pi, pi]`. A pose that already overlaps something moves only in
    /// directions that do not deepen the overlap. Errors if a speed or `dt` is not finite, or
    /// `dt < 0`. Allocates nothing.
    pub fn step(
        &self,
        pose: &mut Pose,
        v_left: f64,
        v_right: f64,
        dt: f64,
        world: &World,
    ) -> Result<bool, Error> {
        check_finite("v_left", v_left)?;
        check_finite("v_right", v_right)?;
        check_range("dt", dt, 0.0, true, f64::INFINITY, false)?;
        let vl = v_left.clamp(-self.max_speed, self.max_speed);
        let vr = v_right.clamp(-self.max_speed, self.max_speed);
        let v = 0.5 * (vl + vr);
        let omega = (vr - vl) / self.wheel_base;
        let start_heading = pose.heading;
        // The chord of the step's arc: length v dt sinc(omega dt / 2), at the mean heading.
        let half = 0.5 * omega * dt;
        let chord = v * dt * sinc(half);
        let (s, c) = (start_heading + half).sin_cos();
        let (length, u) = if chord >= 0.0 {
            (chord, [c, s])
        } else {
            (-chord, [-c, -s])
        };
        let mut p = pose.position();
        let mut done = 0.0;
        let mut contact = false;
        let mut iterations = 0;
        while done < length {
            if iterations == MAX_ADVANCE_ITERATIONS {
                contact = true;
                break;
            }
            iterations += 1;
            let remaining = length - done;
            let mut advance = remaining;
            world.for_each_distance(p, |d, n| {
                let a = n[0] * u[0] + n[1] * u[1];
                // NaN counts as approaching.
                if a < 0.0 || a.is_nan() {
                    // How far the robot's edge is from the hard limit CONTACT_MARGIN.
                    let e = d - self.radius - CONTACT_MARGIN;
                    let allowed = if e > 2.0 * CONTACT_TOLERANCE {
                        (e - CONTACT_TOLERANCE) / -a
                    } else {
                        // In contact: use up at most half of what is left, so that grazing
                        // motion (a tiny) goes on while pushing into the obstacle stops.
                        0.5 * e.max(0.0) / -a
                    };
                    advance = if allowed.is_nan() {
                        0.0
                    } else {
                        advance.min(allowed)
                    };
                }
            });
            let progress = advance >= MIN_ADVANCE || advance >= remaining;
            if !progress {
                contact = true;
                break;
            }
            if done + advance >= length {
                // The whole chord: land exactly on the arc's end.
                p = [pose.x + chord * c, pose.y + chord * s];
                break;
            }
            done += advance;
            p = [pose.x + done * u[0], pose.y + done * u[1]];
        }
        [pose.x, pose.y] = p;
        pose.heading = wrap_angle(start_heading + omega * dt);
        if !pose.heading.is_finite() {
            pose.heading = wrap_angle(start_heading);
        }
        debug_assert!((-PI..=PI).contains(&pose.heading) || !start_heading.is_finite());
        Ok(contact)
    }
}
