//! A hand-coded wall follower: it drives to the room's nearest outer wall, then follows the room's
//! perimeter counter-clockwise with the wall on its right, lap after lap (paper §3).
//!
//! The follower has its own noise-free range sensors, separate from the network's sonar:
//!
//! - a *front fan*: three rays along the heading, from the centre and from points 0.9 radius to
//!   its left and right; `front` is the nearest of their distances;
//! - a *right pair*: two rays pointing 90 degrees right, from points [`SIDE_SPACING`] ahead of and
//!   behind the centre; their distances `d_f`, `d_r` give the wall's angle
//!   `alpha = atan((d_f - d_r) / (2 SIDE_SPACING))` (positive when the robot heads away from the
//!   wall) and its distance `d = (d_f + d_r) / 2 * cos(alpha)`.
//!
//! It runs in two phases:
//!
//! 1. **Seek.** At the first command it picks an outer wall: the nearest one whose corridor is
//!    clear (three rays from the centre and from points `radius + 0.05` m to either side, towards
//!    the wall, all reach the wall before any box); if none is clear, the nearest. It turns to face
//!    that wall, driving forward only within 60 degrees of facing it and slowing to a stop as
//!    anything comes up ahead (as in the follow phase below), until the front fan sees a wall (not
//!    a box) within `wall_distance + corner_distance` m while it faces the wall within 15 degrees. Facing the
//!    wall squarely, the follow phase's corner turn then puts the wall on the right. The landmark
//!    can therefore never capture it, wherever it starts.
//! 2. **Follow.** A proportional controller holds the wall on the right at `wall_distance`:
//!    `omega = -distance_gain clamp(d - wall_distance, ±0.3) - angle_gain alpha`. As a wall comes
//!    up ahead (a corner), the front fan blends in a left turn and slows down: with
//!    `s = clamp((front - (wall_distance - 0.1)) / (corner_distance + 0.1), 0, 1)` the speed is
//!    `s speed` and the turn rate `s omega + (1 - s) max_turn_rate`. If neither right ray sees anything within
//!    `sensor_range`, it curves right at half its turn rate to find the wall again.
//!
//! Wheel speeds are scaled down together when one would exceed the robot's `max_speed`, which
//! keeps the path's curvature.

use std::f64::consts::{FRAC_PI_2, PI};

use crate::error::{check_range, Error};
use crate::pose::{wrap_angle, Pose};
use crate::robot::RobotSpec;
use crate::world::{Surface, World};

/// Half the spacing of the right-side ray pair, in metres (rays 0.15 m ahead of and behind the
/// centre).
pub const SIDE_SPACING: f64 = 0.15;
/// Turn rate per radian of heading error in the seek phase, rad/s per rad.
const K_SEEK: f64 = 3.0;
/// How closely the seek phase must face the chosen wall before following starts, rad (15 deg).
const SEEK_ALIGNED: f64 = 15.0 * PI / 180.0;
/// The largest distance error the follow controller acts on, m.
const MAX_DISTANCE_ERROR: f64 = 0.3;
/// The front distance, short of `wall_distance`, where forward motion stops, m.
const FRONT_STOP: f64 = 0.1;

/// The wall follower's settings. `Default` drives at the paper's simulated speed.
///
/// # Example
/// ```
/// use sim2d::{Pose, RobotSpec, WallFollower, WallFollowerSpec, World, WorldSpec};
/// let world = World::new(&WorldSpec::landmark(1)?)?;
/// let robot = RobotSpec::default();
/// let mut follower = WallFollower::new(&WallFollowerSpec::default(), &robot)?;
/// let mut pose = Pose::new(1.5, 1.2, 2.0);
/// for _ in 0..300 {
///     let (vl, vr) = follower.command(&world, &pose);
///     robot.step(&mut pose, vl, vr, 0.1, &world)?;
/// }
/// assert!(follower.is_following());
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WallFollowerSpec {
    /// The cruising speed in m/s, in (0, `robot.max_speed`]. Default 0.6 (the paper's simulated
    /// robot ran at 3 times the real robot's 0.2 m/s).
    pub speed: f64,
    /// The distance held between the wall and the robot's centre, in metres, > the robot's radius
    /// + 0.1. Default 0.55 (a gap of 0.285 m for the default robot).
    pub wall_distance: f64,
    /// The fastest turn, in rad/s, > 0. Default 2.0.
    pub max_turn_rate: f64,
    /// The range of the follower's own rays, in metres, > `wall_distance`. Default 2.0.
    pub sensor_range: f64,
    /// The follow phase's turn rate per metre of distance error, in rad/s per m, in (0,
    /// [`MAX_GAIN`]]. Default 3.0.
    pub distance_gain: f64,
    /// The follow phase's turn rate per radian of the wall's angle, in rad/s per rad, in (0,
    /// [`MAX_GAIN`]]. Default 2.2, which damps the approach to the wall (a damping ratio of about
    /// 0.8 at the default speed); a much smaller gain makes the robot weave.
    pub angle_gain: f64,
    /// How far beyond `wall_distance` a wall ahead starts the corner turn (and ends the seek
    /// phase), in metres, > 0, with `wall_distance + corner_distance < sensor_range` (the front
    /// fan must see where the turn starts). Default 0.35.
    pub corner_distance: f64,
}

impl Default for WallFollowerSpec {
    fn default() -> Self {
        WallFollowerSpec {
            speed: 0.6,
            wall_distance: 0.55,
            max_turn_rate: 2.0,
            sensor_range: 2.0,
            distance_gain: 3.0,
            angle_gain: 2.2,
            corner_distance: 0.35,
        }
    }
}

impl WallFollowerSpec {
    /// Checks every field against `robot`; the error names the first bad one (as
    /// `follower.<field>`).
    pub fn validate(&self, robot: &RobotSpec) -> Result<(), Error> {
        let inf = f64::INFINITY;
        // The robot's wheels cannot go faster: a faster cruising speed would be clamped.
        check_range(
            "follower.speed",
            self.speed,
            0.0,
            false,
            robot.max_speed,
            true,
        )?;
        let min_d = robot.radius + FRONT_STOP;
        if !(self.wall_distance.is_finite() && self.wall_distance > min_d) {
            return Err(Error::invalid(
                "follower.wall_distance",
                self.wall_distance,
                &format!("a finite number > robot.radius + {FRONT_STOP} = {min_d}"),
            ));
        }
        check_range(
            "follower.max_turn_rate",
            self.max_turn_rate,
            0.0,
            false,
            inf,
            false,
        )?;
        for (name, gain) in [
            ("follower.distance_gain", self.distance_gain),
            ("follower.angle_gain", self.angle_gain),
        ] {
            check_range(name, gain, 0.0, false, MAX_GAIN, true)?;
        }
        check_range(
            "follower.corner_distance",
            self.corner_distance,
            0.0,
            false,
            inf,
            false,
        )?;
        if !(self.sensor_range.is_finite() && self.sensor_range > self.wall_distance) {
            return Err(Error::invalid(
                "follower.sensor_range",
                self.sensor_range,
                &format!(
                    "a finite number > follower.wall_distance ({})",
                    self.wall_distance
                ),
            ));
        }
        let corner = self.wall_distance + self.corner_distance;
        if corner >= self.sensor_range {
            return Err(Error::invalid(
                "follower.corner_distance",
                self.corner_distance,
                &format!(
                    "less than follower.sensor_range - follower.wall_distance = {} (the front \
                     rays must see where the corner turn starts)",
                    self.sensor_range - self.wall_distance
                ),
            ));
        }
        Ok(())
    }
}

/// The largest gain of the follow law, in rad/s per m or per rad: at 100 a 2 cm error (or a wall
/// angle of 1.1 degrees) already asks for the default fastest turn, 2 rad/s, so a larger gain is
/// a switch rather than a gain.
pub const MAX_GAIN: f64 = 100.0;

/// Which phase the follower is in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// Heading for an outer wall; `target` is the chosen heading in radians (`None` before the
    /// first command).
    Seek {
        /// The heading towards the chosen wall.
        target: Option<f64>,
    },
    /// Following the perimeter with the wall on the right.
    Follow,
}

/// The wall follower's controller and phase. See the [module docs](self) for the algorithm.
#[derive(Clone, Debug, PartialEq)]
pub struct WallFollower {
    spec: WallFollowerSpec,
    robot: RobotSpec,
    phase: Phase,
}

impl WallFollower {
    /// A follower in the seek phase for `robot`; validates both specs.
    pub fn new(spec: &WallFollowerSpec, robot: &RobotSpec) -> Result<WallFollower, Error> {
        robot.validate()?;
        spec.validate(robot)?;
        Ok(WallFollower {
            spec: spec.clone(),
            robot: robot.clone(),
            phase: Phase::Seek { target: None },
        })
    }

    /// The follower's settings.
    pub fn spec(&self) -> &WallFollowerSpec {
        &self.spec
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Whether it has reached a wall and is following the perimeter.
    pub fn is_following(&self) -> bool {
        self.phase == Phase::Follow
    }

    /// Back to the seek phase, as new.
    pub fn reset(&mut self) {
        self.phase = Phase::Seek { target: None };
    }

    /// The wheel speeds `(v_left, v_right)` in m/s for a robot at `pose`; may change the phase.
    /// Allocates nothing.
    pub fn command(&mut self, world: &World, pose: &Pose) -> (f64, f64) {
        let (v, omega) = match self.phase {
            Phase::Seek { target } => {
                let target = match target {
                    Some(t) => t,
                    None => {
                        let t = self.choose_wall(world, pose);
                        self.phase = Phase::Seek { target: Some(t) };
                        t
                    }
                };
                let e = wrap_angle(target - pose.heading);
                let (front, surface) = self.front(world, pose);
                let at_wall = front <= self.spec.wall_distance + self.spec.corner_distance
                    && surface == Some(Surface::Wall)
                    && e.abs() < SEEK_ALIGNED;
                if at_wall {
                    self.phase = Phase::Follow;
                    self.follow(world, pose, front)
                } else {
                    let omega =
                        (K_SEEK * e).clamp(-self.spec.max_turn_rate, self.spec.max_turn_rate);
                    // Full speed when facing the wall, none when more than 60 degrees off, and
                    // slowing down to a stop as anything comes up ahead.
                    let facing = ((e.cos() - 0.5) / 0.5).clamp(0.0, 1.0);
                    (self.spec.speed * facing * self.free_ahead(front), omega)
                }
            }
            Phase::Follow => {
                let (front, _) = self.front(world, pose);
                self.follow(world, pose, front)
            }
        };
        let (vl, vr) = self.robot.wheels(v, omega);
        let fastest = vl.abs().max(vr.abs());
        if fastest > self.robot.max_speed {
            let k = self.robot.max_speed / fastest;
            (vl * k, vr * k)
        } else {
            (vl, vr)
        }
    }

    /// The follow phase's `(v, omega)` given the front distance.
    fn follow(&self, world: &World, pose: &Pose, front: f64) -> (f64, f64) {
        let s = &self.spec;
        let range = s.sensor_range;
        let right = pose.direction_at(-FRAC_PI_2);
        let [hx, hy] = pose.direction();
        let side = |ahead: f64| {
            let origin = [pose.x + ahead * hx, pose.y + ahead * hy];
            world
                .cast_ray(origin, right, range)
                .map_or(range, |h| h.distance)
        };
        let (d_f, d_r) = (side(SIDE_SPACING), side(-SIDE_SPACING));
        let omega_wall = if d_f >= range && d_r >= range {
            -0.5 * s.max_turn_rate
        } else {
            let alpha = ((d_f - d_r) / (2.0 * SIDE_SPACING)).atan();
            let d = 0.5 * (d_f + d_r) * alpha.cos();
            let err = (d - s.wall_distance).clamp(-MAX_DISTANCE_ERROR, MAX_DISTANCE_ERROR);
            -s.distance_gain * err - s.angle_gain * alpha
        };
        let free = self.free_ahead(front);
        let omega = free * omega_wall + (1.0 - free) * s.max_turn_rate;
        (
            s.speed * free,
            omega.clamp(-s.max_turn_rate, s.max_turn_rate),
        )
    }

    /// How free the way ahead is, from 0 (something within `wall_distance - FRONT_STOP`) to 1
    /// (nothing within `wall_distance + corner_distance`), linear in between.
    fn free_ahead(&self, front: f64) -> f64 {
        let stop = self.spec.wall_distance - FRONT_STOP;
        let turn = self.spec.wall_distance + self.spec.corner_distance;
        ((front - stop) / (turn - stop)).clamp(0.0, 1.0)
    }

    /// The front fan's nearest distance (`sensor_range` if nothing) and what it saw.
    fn front(&self, world: &World, pose: &Pose) -> (f64, Option<Surface>) {
        let dir = pose.direction();
        let [lx, ly] = pose.direction_at(FRAC_PI_2);
        let mut best = (self.spec.sensor_range, None);
        for k in [-0.9, 0.0, 0.9] {
            let off = k * self.robot.radius;
            let origin = [pose.x + off * lx, pose.y + off * ly];
            if let Some(h) = world.cast_ray(origin, dir, best.0) {
                best = (h.distance, Some(h.surface));
            }
        }
        best
    }

    /// The heading towards the nearest outer wall with a clear corridor (else the nearest wall).
    pub(crate) fn choose_wall(&self, world: &World, pose: &Pose) -> f64 {
        let [w, h] = world.room();
        // (distance, heading) for bottom, right, top, left.
        let mut walls = [
            (pose.y, -FRAC_PI_2),
            (w - pose.x, 0.0),
            (h - pose.y, FRAC_PI_2),
            (pose.x, PI),
        ];
        walls.sort_by(|a, b| a.0.total_cmp(&b.0)); // stable: ties keep the order above
        let reach = w.hypot(h) + 1.0;
        let lateral = self.robot.radius + 0.05;
        for &(_, heading) in &walls {
            let (s, c) = heading.sin_cos();
            let clear = [-lateral, 0.0, lateral].iter().all(|&off| {
                // The lateral direction is the heading turned 90 degrees left: (-s, c).
                let origin = [pose.x - off * s, pose.y + off * c];
                world
                    .cast_ray(origin, [c, s], reach)
                    .is_none_or(|hit| hit.surface == Surface::Wall)
            });
            if clear {
                return heading;
            }
        }
        walls[0].1
    }
}
