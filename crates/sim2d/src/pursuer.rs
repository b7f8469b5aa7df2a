//! Pursuers: discs that chase the robot by pure pursuit, at a constant speed with a turning
//! limit, and capture it when their centre comes within a radius of the robot's.
//!
//! # Policy
//! At each step a pursuer turns towards the robot's centre as it was at the start of the step
//! (pursuers and robot move at the same time), as fast as its turning limit allows:
//! `omega = clamp(e / dt, -max_turn_rate, max_turn_rate)` with `e` the bearing of the robot
//! relative to the pursuer's heading, wrapped into `(-pi, pi]`, so a pursuer that can turn far
//! enough faces the robot at the end of the step. It always drives forward at `speed`.
//!
//! Pure pursuit stops dead at a box between a pursuer and the robot: the pursuer presses into
//! the box's face for as long as the robot stays behind it. With `detour` on, a pursuer whose
//! pure-pursuit step a wall or box would cut short takes another step instead, turning left as
//! fast as it can (`omega = max_turn_rate`) at `speed`: pressed against a face, it turns until it
//! runs along it, skims it with the obstacle on its right, and turns back to the robot past the
//! corner, as a bug algorithm does around a convex obstacle. The detour needs no memory: the
//! heading carries it from step to step.
//!
//! # Motion
//! A pursuer moves as the robot does ([`RobotSpec::step`]: along the chord of the step's arc,
//! stopping short of walls and boxes), with the `v` and `omega` of its policy; it never enters a
//! wall or a box, and slides along one it drives into. Pursuers pass through each other and
//! through the robot: touching the robot is a capture, not a collision.

use streams::Stream;

use crate::error::{check_count, check_range, Error};
use crate::pose::{wrap_angle, Pose};
use crate::robot::RobotSpec;
use crate::world::{World, START_ATTEMPTS};

/// The pursuers of every row and their policy. `Default` is no pursuer; one added with the
/// other defaults is a 0.2 m disc at 0.4 m/s, turning at most 1.5 rad/s.
///
/// # Example
/// ```
/// use sim2d::{Pose, PursuerSpec};
/// let spec = PursuerSpec { count: 1, ..PursuerSpec::default() };
/// // The robot is straight ahead: no turn, full speed.
/// assert_eq!(spec.command(&Pose::new(1.0, 1.0, 0.0), [3.0, 1.0], 0.1), (0.4, 0.0));
/// // Straight behind: as fast a turn as allowed.
/// assert_eq!(spec.command(&Pose::new(1.0, 1.0, 0.0), [0.0, 1.0], 0.1), (0.4, 1.5));
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PursuerSpec {
    /// How many pursuers each row has, K. Default 0.
    pub count: u32,
    /// A pursuer's radius in metres, > 0. Default 0.2.
    pub radius: f64,
    /// Its speed in m/s, >= 0. Default 0.4.
    pub speed: f64,
    /// The fastest it turns, in rad/s, >= 0. Default 1.5.
    pub max_turn_rate: f64,
    /// The robot is captured when a pursuer's centre is this close to its centre (or closer), in
    /// metres, >= 0; checked at the end of every step. Default 0.5 (about touching, for the
    /// default robot of radius 0.265 and a pursuer of 0.2).
    pub capture_radius: f64,
    /// How far from the robot's centre a pursuer's centre starts at least, in metres, >= 0.
    /// Default 2.
    pub min_start_distance: f64,
    /// Whether a pursuer blocked by a wall or box turns left around it instead of pressing into
    /// it (see the [module docs](self)). Default false: pure pursuit alone.
    pub detour: bool,
}

impl Default for PursuerSpec {
    fn default() -> Self {
        PursuerSpec {
            count: 0,
            radius: 0.2,
            speed: 0.4,
            max_turn_rate: 1.5,
            capture_radius: 0.5,
            min_start_distance: 2.0,
            detour: false,
        }
    }
}

impl PursuerSpec {
    /// Checks every field; the error names the first bad one (as `pursuers.<field>`).
    pub fn validate(&self) -> Result<(), Error> {
        let inf = f64::INFINITY;
        check_count("pursuers.count", u64::from(self.count), 0)?;
        check_range("pursuers.radius", self.radius, 0.0, false, inf, false)?;
        check_range("pursuers.speed", self.speed, 0.0, true, inf, false)?;
        check_range(
            "pursuers.max_turn_rate",
            self.max_turn_rate,
            0.0,
            true,
            inf,
            false,
        )?;
        check_range(
            "pursuers.capture_radius",
            self.capture_radius,
            0.0,
            true,
            inf,
            false,
        )?;
        check_range(
            "pursuers.min_start_distance",
            self.min_start_distance,
            0.0,
            true,
            inf,
            false,
        )?;
        Ok(())
    }

    /// The pure-pursuit command `(v, omega)` of a pursuer at `pursuer` chasing a robot whose
    /// centre is at `target`, for a step of `dt` seconds (see the [module docs](self)).
    pub fn command(&self, pursuer: &Pose, target: [f64; 2], dt: f64) -> (f64, f64) {
        let bearing = (target[1] - pursuer.y).atan2(target[0] - pursuer.x);
        let error = wrap_angle(bearing - pursuer.heading);
        let omega = (error / dt).clamp(-self.max_turn_rate, self.max_turn_rate);
        (self.speed, omega)
    }

    /// A pursuer's body as a robot: its radius, a wheel base of 1 m and no speed limit, so that
    /// its wheel speeds `v -+ omega / 2` give back its command.
    pub fn body(&self) -> RobotSpec {
        RobotSpec {
            radius: self.radius,
            wheel_base: 1.0,
            max_speed: f64::INFINITY,
        }
    }

    /// Moves a pursuer for `dt` seconds towards `target` by [`PursuerSpec::command`], stopping
    /// short of walls and boxes as [`RobotSpec::step`] does; with `detour` on, a step that a wall
    /// or box would cut short is replaced by a left turn at the turning limit (see the
    /// [module docs](self)). Returns whether a wall or box cut the motion short. Errors if `dt`
    /// is not finite and >= 0.
    ///
    /// # Example
    /// ```
    /// use sim2d::{Pose, PursuerSpec, World, WorldSpec};
    /// let world = World::new(&WorldSpec::landmark(1)?)?;
    /// let spec = PursuerSpec { count: 1, ..PursuerSpec::default() };
    /// let mut p = Pose::new(1.0, 1.0, 0.0);
    /// for _ in 0..10 {
    ///     spec.step(&mut p, [5.0, 1.0], 0.1, &world)?;
    /// }
    /// assert!((p.x - 1.4).abs() < 1e-12 && p.y == 1.0 && p.heading == 0.0);
    /// # Ok::<(), sim2d::Error>(())
    /// ```
    pub fn step(
        &self,
        pursuer: &mut Pose,
        target: [f64; 2],
        dt: f64,
        world: &World,
    ) -> Result<bool, Error> {
        check_range("dt", dt, 0.0, true, f64::INFINITY, false)?;
        let (v, omega) = self.command(pursuer, target, dt);
        let body = self.body();
        let (v_left, v_right) = body.wheels(v, omega);
        let start = *pursuer;
        let blocked = body.step(pursuer, v_left, v_right, dt, world)?;
        if !(blocked && self.detour) {
            return Ok(blocked);
        }
        *pursuer = start;
        let (v_left, v_right) = body.wheels(v, self.max_turn_rate);
        body.step(pursuer, v_left, v_right, dt, world)
    }

    /// Random start poses for the `out.len()` pursuers of a robot at `robot`: each uniform in the
    /// world's start region, at least `clearance` from walls and boxes
    /// ([`World::random_pose`]) and at least `min_start_distance` from the robot's centre, with
    /// a uniform heading; redrawn up to [`START_ATTEMPTS`] times.
    ///
    /// Errors when no such pose was found.
    pub fn place(
        &self,
        world: &World,
        robot: &Pose,
        clearance: f64,
        stream: &mut Stream,
        out: &mut [Pose],
    ) -> Result<(), Error> {
        for p in out.iter_mut() {
            let mut found = None;
            for _ in 0..START_ATTEMPTS {
                let pose = world.random_pose(self.radius, clearance, stream)?;
                if (pose.x - robot.x).hypot(pose.y - robot.y) >= self.min_start_distance {
                    found = Some(pose);
                    break;
                }
            }
            *p = found.ok_or_else(|| {
                Error::invalid(
                    "pursuers.min_start_distance",
                    self.min_start_distance,
                    &format!(
                        "small enough for the start region: {START_ATTEMPTS} random starts \
                         were all nearer to the robot at ({:.3}, {:.3})",
                        robot.x, robot.y
                    ),
                )
            })?;
        }
        Ok(())
    }
}
