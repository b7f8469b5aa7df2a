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
//!    a box) within `wall_distance + 0.35` m while it faces the wall within 15 degrees. Facing the
//!    wall squarely, the follow phase's corner turn then puts the wall on the right. The landmark
//!    can therefore never capture it, wherever it starts.
//! 2. **Follow.** A proportional controller holds the wall on the right at `wall_distance`:
//!    `omega = -K_DISTANCE clamp(d - wall_distance, ±0.3) - K_ANGLE alpha`. As a wall comes up
//!    ahead (a corner), the front fan blends in a left turn and slows down: with
//!    `s = clamp((front - (wall_distance - 0.1)) / 0.45, 0, 1)` the speed is `s speed` and the turn
//!    rate `s omega + (1 - s) max_turn_rate`. If neither right ray sees anything within
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
/// Turn rate per metre of distance error in the follow phase, rad/s per m.
const K_DISTANCE: f64 = 3.0;
/// Turn rate per radian of wall angle in the follow phase, rad/s per rad.
const K_ANGLE: f64 = 2.2;
/// Turn rate per radian of heading error in the seek phase, rad/s per rad.
const K_SEEK: f64 = 3.0;
/// How closely the seek phase must face the chosen wall before following starts, rad (15 deg).
const SEEK_ALIGNED: f64 = 15.0 * PI / 180.0;
/// The largest distance error the follow controller acts on, m.
const MAX_DISTANCE_ERROR: f64 = 0.3;
/// The front distance, beyond `wall_distance`, where the corner turn starts, m.
const FRONT_TURN: f64 = 0.35;
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
    /// The cruising speed in m/s, > 0. Default 0.6 (the paper's simulated robot ran at 3 times the
    /// real robot's 0.2 m/s).
    pub speed: f64,
    /// The distance held between the wall and the robot's centre, in metres, > the robot's radius
    /// + 0.1. Default 0.55 (a gap of 0.285 m for the default robot).
    pub wall_distance: f64,
    /// The fastest turn, in rad/s, > 0. Default 2.0.
    pub max_turn_rate: f64,
    /// The range of the follower's own rays, in metres, > `wall_distance`. Default 2.0.
    pub sensor_range: f64,
}

impl Default for WallFollowerSpec {
    fn default() -> Self {
        WallFollowerSpec {
            speed: 0.6,
            wall_distance: 0.55,
            max_turn_rate: 2.0,
            sensor_range: 2.0,
        }
    }
}

impl WallFollowerSpec {
    /// Checks every field against `robot`; the error names the first bad one (as
    /// `follower.<field>`).
    pub fn validate(&self, robot: &RobotSpec) -> Result<(), Error> {
        let inf = f64::INFINITY;
        check_range("follower.speed", self.speed, 0.0, false, inf, false)?;
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
        Ok(())
    }
}

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
                let at_wall = front <= self.spec.wall_distance + FRONT_TURN
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
            -K_DISTANCE * err - K_ANGLE * alpha
        };
        let free = self.free_ahead(front);
        let omega = free * omega_wall + (1.0 - free) * s.max_turn_rate;
        (
            s.speed * free,
            omega.clamp(-s.max_turn_rate, s.max_turn_rate),
        )
    }

    /// How free the way ahead is, from 0 (something within `wall_distance - FRONT_STOP`) to 1
    /// (nothing within `wall_distance + FRONT_TURN`), linear in between.
    fn free_ahead(&self, front: f64) -> f64 {
        let stop = self.spec.wall_distance - FRONT_STOP;
        let turn = self.spec.wall_distance + FRONT_TURN;
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
    fn choose_wall(&self, world: &World, pose: &Pose) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{Sim, SimSpec};
    use crate::world_spec::WorldSpec;
    use std::f64::consts::TAU;
    use streams::{Purpose, Stream};

    /// What one run did. A lap is one full counter-clockwise turn of the robot's position around
    /// the room's centre, counted from the moment the follower reached a wall.
    #[derive(Debug)]
    struct LapRun {
        /// Simulated seconds until the follow phase began.
        reached_wall: Option<f64>,
        /// Simulated seconds from reaching the wall to the end of the first and second laps.
        laps: [Option<f64>; 2],
        /// The least and largest distance from the robot's centre to the nearest outer wall while
        /// following, after the first 10 s of following.
        wall_gap: (f64, f64),
        /// Of the steps after the first 10 s of following, the fraction whose right-side ray (from
        /// the centre, 90 degrees right) met an outer wall within 1 m.
        wall_on_right: f64,
        /// Steps cut short by a contact.
        contacts: u64,
    }

    /// Runs until two laps are done or `limit_s` has passed.
    fn lap_run(world: &World, start: Option<Pose>, stream: &mut Stream, limit_s: f64) -> LapRun {
        let spec = SimSpec::default();
        let mut sim = match start {
            Some(p) => Sim::new(world, &spec, p).unwrap(),
            None => Sim::random_start(world, &spec, stream).unwrap(),
        };
        let [w, h] = world.room();
        let centre_angle = |p: Pose| (p.y - 0.5 * h).atan2(p.x - 0.5 * w);
        let mut echo = [Default::default()];
        let mut run = LapRun {
            reached_wall: None,
            laps: [None; 2],
            wall_gap: (f64::INFINITY, 0.0),
            wall_on_right: 0.0,
            contacts: 0,
        };
        let (mut angle, mut settled, mut right) = (0.0, 0u32, 0u32);
        let mut last = centre_angle(sim.pose());
        while sim.time() < limit_s && run.laps[1].is_none() {
            sim.step(stream, &mut echo).unwrap();
            let p = sim.pose();
            let a = centre_angle(p);
            if let Some(t0) = run.reached_wall {
                angle += wrap_angle(a - last);
                for k in 0..2 {
                    if angle >= TAU * (k + 1) as f64 && run.laps[k].is_none() {
                        run.laps[k] = Some(sim.time() - t0);
                    }
                }
                if sim.time() - t0 > 10.0 {
                    let gap = p.x.min(w - p.x).min(p.y).min(h - p.y);
                    run.wall_gap = (run.wall_gap.0.min(gap), run.wall_gap.1.max(gap));
                    settled += 1;
                    let hit = world.cast_ray(p.position(), p.direction_at(-FRAC_PI_2), 1.0);
                    right += u32::from(hit.is_some_and(|h| h.surface == Surface::Wall));
                }
            } else if sim.follower().is_following() {
                run.reached_wall = Some(sim.time());
            }
            last = a;
        }
        run.wall_on_right = f64::from(right) / f64::from(settled.max(1));
        run.contacts = sim.contacts();
        run
    }

    /// Two counter-clockwise laps, the first within 120 s of the start, steadily along the walls.
    fn check(run: &LapRun, what: &str) {
        let t0 = run
            .reached_wall
            .unwrap_or_else(|| panic!("{what}: no wall: {run:?}"));
        let lap = run.laps[0].unwrap_or_else(|| panic!("{what}: no lap: {run:?}"));
        assert!(t0 + lap <= 120.0, "{what}: {run:?}");
        let second = run.laps[1].unwrap_or_else(|| panic!("{what}: one lap only: {run:?}"));
        // The perimeter at 0.55 m from the walls is 2 (4.9 + 3.9) = 17.6 m: 29 s at 0.6 m/s, plus
        // the corners; every lap takes about as long.
        assert!((25.0..40.0).contains(&lap), "{what}: {run:?}");
        assert!((second - 2.0 * lap).abs() < 2.0, "{what}: {run:?}");
        // The centre stays near wall_distance = 0.55 from the nearest wall (corners are rounded).
        assert!(
            run.wall_gap.0 > 0.4 && run.wall_gap.1 < 0.7,
            "{what}: {run:?}"
        );
        assert!(run.wall_on_right > 0.9, "{what}: {run:?}");
        assert_eq!(run.contacts, 0, "{what}: {run:?}");
    }

    #[test]
    fn laps_the_room_counter_clockwise_from_random_starts() {
        for n in [1, 2] {
            let world = World::new(&WorldSpec::landmark(n).unwrap()).unwrap();
            for trial in 0..20 {
                let mut s = Stream::new(2024, 0, Purpose::Trial, u64::from(n), trial);
                check(
                    &lap_run(&world, None, &mut s, 120.0),
                    &format!("landmark {n}, trial {trial}"),
                );
            }
        }
    }

    #[test]
    fn laps_jittered_rooms() {
        for trial in 0..6 {
            let mut s = Stream::new(7, 0, Purpose::Trial, 0, trial);
            let spec = WorldSpec::landmark(1 + (trial % 2) as u32)
                .unwrap()
                .jittered(&mut s, 0.15, 0.1)
                .unwrap();
            let world = World::new(&spec).unwrap();
            let run = lap_run(&world, None, &mut s, 120.0);
            assert!(
                run.laps[1].is_some() && run.contacts == 0,
                "jitter {trial}: {run:?}"
            );
            assert!(run.wall_on_right > 0.9, "jitter {trial}: {run:?}");
        }
    }

    #[test]
    fn starts_against_the_landmark_still_reach_the_perimeter() {
        // Poses touching the landmark (clearance 0.02 m) on each side, and in landmark 2's gap,
        // each facing four ways.
        let r = 0.265 + 0.02;
        let cases: [(u32, [f64; 2]); 7] = [
            (1, [2.4 - r, 2.5]),
            (1, [3.0, 2.2 - r]),
            (1, [3.6 + r, 2.8 + r]),
            (2, [3.0, 2.5]), // in the 0.6 m gap between the crates
            (2, [3.0, 2.8 + r]),
            (2, [2.1 - r, 2.2]),
            (2, [3.9 + r, 2.5]),
        ];
        for (n, [x, y]) in cases {
            let world = World::new(&WorldSpec::landmark(n).unwrap()).unwrap();
            for k in 0..4 {
                let start = Pose::new(x, y, 0.3 + k as f64 * FRAC_PI_2);
                let mut s = Stream::new(0, 0, Purpose::Trial, 0, 0);
                let run = lap_run(&world, Some(start), &mut s, 120.0);
                check(&run, &format!("landmark {n}, start {start:?}"));
            }
        }
    }

    #[test]
    fn chooses_a_clear_corridor() {
        // Directly above landmark 1, the nearest wall is the top one; below it, the bottom one.
        // Just left of the landmark's centre line and 0.1 m below it, the nearest wall is the
        // bottom; but with the robot between the landmark and the left wall at (1.9, 2.5), both
        // left (1.9 m) and the clear corridor agree.
        let world = World::new(&WorldSpec::landmark(1).unwrap()).unwrap();
        let f = WallFollower::new(&WallFollowerSpec::default(), &RobotSpec::default()).unwrap();
        let t = f.choose_wall(&world, &Pose::new(3.0, 3.2, 0.0));
        assert_eq!(t, FRAC_PI_2);
        let t = f.choose_wall(&world, &Pose::new(1.9, 2.5, 0.0));
        assert_eq!(t, PI);
        // A world where a box blocks the way to the nearest (bottom) wall: it picks the next one.
        let mut spec = WorldSpec::landmark(1).unwrap();
        spec.boxes[0].center = [3.0, 0.5];
        let world = World::new(&spec).unwrap();
        let t = f.choose_wall(&world, &Pose::new(3.0, 1.2, 0.0));
        assert_eq!(
            t, 0.0,
            "right wall (3 m) before left (3 m): ties keep bottom, right, top, left"
        );
    }

    #[test]
    fn settings_are_validated() {
        let robot = RobotSpec::default();
        let bad = WallFollowerSpec {
            wall_distance: 0.3,
            ..WallFollowerSpec::default()
        };
        assert_eq!(
            bad.validate(&robot).unwrap_err().to_string(),
            "follower.wall_distance is 0.3; it must be a finite number > robot.radius + 0.1 = 0.365"
        );
        let bad = WallFollowerSpec {
            speed: -1.0,
            ..WallFollowerSpec::default()
        };
        assert!(WallFollower::new(&bad, &robot).is_err());
    }
}
