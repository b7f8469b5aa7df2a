//! Many robots in one world, stepped together: the closed loop of a population, one robot per
//! row.
//!
//! A [`Fleet`] holds B rows. Each row is one episode of one network: a robot (the differential
//! drive of [`RobotSpec`] that never enters a wall), its `K` pursuers, its own noise stream and
//! its latest readings. Rows share nothing but the world and the settings ([`Arena`]), so a row
//! gives the same bits whatever other rows there are and however many threads step them.
//!
//! # One step of a row
//! 1. The robot moves for `dt` with its wheel speeds (m/s, clamped to `±robot.max_speed`);
//!    `contact` says whether a wall or box cut its motion short.
//! 2. Each pursuer moves for `dt` by pure pursuit towards the robot's centre as it was at the
//!    start of the step ([`PursuerSpec`]).
//! 3. `captured` says whether a pursuer's centre is now within `pursuers.capture_radius` of the
//!    robot's centre.
//! 4. The sonar ring ([`Ring`]: walls, boxes and pursuers echo) and the pursuer sensor
//!    ([`SectorSpec`]) are read at the new poses.
//!
//! # Random numbers
//! [`Fleet::reset`] starts row `r` from episode `episodes[r]` and a `seed`: its start (the
//! robot's pose, then its pursuers') comes from the stream `(seed, 0, Trial, episode, 0)` and its
//! sonar noise from `(seed, 0, Trial, episode, 1)`. Rows of the same episode number start alike
//! (every network meets the same episodes), and a row's draws do not depend on how many rows
//! there are.

use streams::{Purpose, Stream};

use crate::error::{check_range, Error};
use crate::pose::Pose;
use crate::pursuer::PursuerSpec;
use crate::ring::{Ring, RingSpec};
use crate::robot::RobotSpec;
use crate::scene::{Disc, Scene};
use crate::sectors::SectorSpec;
use crate::world::World;
use crate::world_spec::WorldSpec;

/// The settings of a fleet. `Default` is the landmark experiment's robot with a ring of eight
/// sonars, no pursuer and no pursuer sensor, stepped every 0.1 s.
///
/// # Example
/// ```
/// use sim2d::{FleetSpec, PursuerSpec};
/// let spec = FleetSpec {
///     pursuers: PursuerSpec { count: 2, ..PursuerSpec::default() },
///     ..FleetSpec::default()
/// };
/// assert!(spec.validate().is_ok());
/// let bad = FleetSpec { dt: 0.0, ..FleetSpec::default() };
/// assert_eq!(bad.validate().unwrap_err().to_string(), "dt is 0; it must be a finite number > 0");
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FleetSpec {
    /// The simulated time per step, in seconds, > 0. Default 0.1.
    pub dt: f64,
    /// The robot. Default [`RobotSpec::default`].
    pub robot: RobotSpec,
    /// The sonar ring on the robot's rim. Default [`RingSpec::default`].
    pub sonar: RingSpec,
    /// The pursuers. Default [`PursuerSpec::default`] (none).
    pub pursuers: PursuerSpec,
    /// The pursuer sensor. Default [`SectorSpec::default`] (off).
    pub sectors: SectorSpec,
    /// The least clearance from walls and boxes of a random start, robot's and pursuers', in
    /// metres, >= 0. Default 0.05.
    pub start_clearance: f64,
}

impl Default for FleetSpec {
    fn default() -> Self {
        FleetSpec {
            dt: 0.1,
            robot: RobotSpec::default(),
            sonar: RingSpec::default(),
            pursuers: PursuerSpec::default(),
            sectors: SectorSpec::default(),
            start_clearance: 0.05,
        }
    }
}

impl FleetSpec {
    /// Checks every field; the error names the first bad one (as `robot.radius`,
    /// `sonar.cone_deg`, `pursuers.speed`, ...).
    pub fn validate(&self) -> Result<(), Error> {
        let inf = f64::INFINITY;
        check_range("dt", self.dt, 0.0, false, inf, false)?;
        self.robot.validate()?;
        self.sonar.validate()?;
        self.pursuers.validate()?;
        self.sectors.validate()?;
        check_range(
            "start_clearance",
            self.start_clearance,
            0.0,
            true,
            inf,
            false,
        )
    }
}

/// What every row of a fleet shares: the world, its exact geometry and the validated settings.
/// [`Fleet::split_mut`] hands it out beside the rows, for callers that step rows in parallel.
#[derive(Clone, Debug)]
pub struct Arena {
    spec: FleetSpec,
    world: World,
    scene: Scene,
    ring: Ring,
}

/// One row: a robot, its pursuers, its noise stream and its latest readings.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    episode: u64,
    pose: Pose,
    noise: Stream,
    contact: bool,
    captured: bool,
    pursuers: Vec<Pose>,
    /// The pursuers' bodies for the sonar, kept in step with `pursuers`.
    discs: Vec<Disc>,
    ranges: Vec<f64>,
    sectors: Vec<f64>,
}

impl Row {
    /// The episode this row runs.
    pub fn episode(&self) -> u64 {
        self.episode
    }

    /// The robot's pose.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// Whether a wall or box cut the robot's last step short (false after a reset).
    pub fn contact(&self) -> bool {
        self.contact
    }

    /// Whether a pursuer's centre is within the capture radius of the robot's centre.
    pub fn captured(&self) -> bool {
        self.captured
    }

    /// The pursuers' poses, K of them.
    pub fn pursuers(&self) -> &[Pose] {
        &self.pursuers
    }

    /// The sonar ring's ranges in metres, one per sonar in the order of `sonar.angles_deg`.
    pub fn ranges(&self) -> &[f64] {
        &self.ranges
    }

    /// The pursuer sensor's gaps in metres, one per sector.
    pub fn sectors(&self) -> &[f64] {
        &self.sectors
    }
}

impl Arena {
    /// The settings.
    pub fn spec(&self) -> &FleetSpec {
        &self.spec
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The sonar ring.
    pub fn ring(&self) -> &Ring {
        &self.ring
    }

    /// A row for `episode` of `seed` at a random start (see the [module docs](self)).
    fn start(&self, episode: u64, seed: u64) -> Result<Row, Error> {
        let s = &self.spec;
        let mut stream = Stream::new(seed, 0, Purpose::Trial, episode, 0);
        let pose = self
            .world
            .random_pose(s.robot.radius, s.start_clearance, &mut stream)?;
        let k = s.pursuers.count as usize;
        let mut pursuers = vec![Pose::default(); k];
        s.pursuers.place(
            &self.world,
            &pose,
            s.start_clearance,
            &mut stream,
            &mut pursuers,
        )?;
        let mut row = Row {
            episode,
            pose,
            noise: Stream::new(seed, 0, Purpose::Trial, episode, 1),
            contact: false,
            captured: false,
            pursuers,
            discs: Vec::with_capacity(k),
            ranges: vec![0.0; self.ring.len()],
            sectors: vec![0.0; s.sectors.count as usize],
        };
        self.sense(&mut row);
        Ok(row)
    }

    /// Steps one row for `dt` with wheel speeds `v_left`, `v_right` in m/s (see the
    /// [module docs](self)). Errors, before changing anything, if a speed is not finite.
    /// Allocates nothing.
    pub fn step_row(&self, row: &mut Row, v_left: f64, v_right: f64) -> Result<(), Error> {
        for (name, v) in [("v_left", v_left), ("v_right", v_right)] {
            check_range(name, v, f64::NEG_INFINITY, false, f64::INFINITY, false)?;
        }
        let s = &self.spec;
        let target = row.pose.position();
        row.contact = s
            .robot
            .step(&mut row.pose, v_left, v_right, s.dt, &self.world)?;
        for p in row.pursuers.iter_mut() {
            s.pursuers.step(p, target, s.dt, &self.world)?;
        }
        self.sense(row);
        Ok(())
    }

    /// Capture and every reading at the row's current poses.
    fn sense(&self, row: &mut Row) {
        let s = &self.spec;
        let r = s.pursuers.radius;
        row.discs.clear();
        row.discs.extend(row.pursuers.iter().map(|p| Disc {
            center: [p.x, p.y],
            radius: r,
        }));
        let (x, y) = (row.pose.x, row.pose.y);
        row.captured = row
            .pursuers
            .iter()
            .any(|p| (p.x - x).hypot(p.y - y) <= s.pursuers.capture_radius);
        self.ring.read(
            &self.scene,
            &row.pose,
            &row.discs,
            &mut row.noise,
            &mut row.ranges,
        );
        s.sectors.read(
            &row.pose,
            s.robot.radius,
            &row.pursuers,
            r,
            &mut row.sectors,
        );
    }
}

/// B robots in one world, one per row, stepped together (see the [module docs](self)).
///
/// # Example
/// Eight rows, two episodes of seed 7, driving straight on for 2 s:
/// ```
/// use sim2d::{Fleet, FleetSpec, WorldSpec};
/// let mut fleet = Fleet::new(&WorldSpec::landmark(1)?, &FleetSpec::default())?;
/// fleet.reset(&[0, 1, 0, 1, 0, 1, 0, 1], 7)?;
/// let wheels = vec![0.3; 2 * fleet.len()];
/// for _ in 0..20 {
///     fleet.step(&wheels, None)?;
/// }
/// // Rows of the same episode went through the same world alike.
/// assert_eq!(fleet.rows()[0], fleet.rows()[2]);
/// assert_eq!(fleet.rows()[0].ranges().len(), 8);
/// // A wheel speed that is not a number is refused, and nothing moves.
/// let mut bad = wheels.clone();
/// bad[3] = f64::NAN;
/// assert_eq!(fleet.step(&bad, None).unwrap_err().to_string(),
///            "wheels[1, 1] is NaN; it must be a finite number");
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Fleet {
    arena: Arena,
    rows: Vec<Row>,
}

impl Fleet {
    /// Validates `world` and `spec`; the fleet has no row until [`Fleet::reset`].
    pub fn new(world: &WorldSpec, spec: &FleetSpec) -> Result<Fleet, Error> {
        spec.validate()?;
        let world = World::new(world)?;
        // Pursuers start in the same region, each as a disc of its own radius.
        let widest = match spec.pursuers.count {
            0 => spec.robot.radius,
            _ => spec.robot.radius.max(spec.pursuers.radius),
        };
        world.check_start(widest, spec.start_clearance)?;
        Ok(Fleet {
            arena: Arena {
                scene: Scene::new(world.spec()),
                ring: Ring::new(&spec.sonar, spec.robot.radius)?,
                world,
                spec: spec.clone(),
            },
            rows: Vec::new(),
        })
    }

    /// The shared settings and world.
    pub fn arena(&self) -> &Arena {
        &self.arena
    }

    /// The settings.
    pub fn spec(&self) -> &FleetSpec {
        &self.arena.spec
    }

    /// The rows.
    pub fn rows(&self) -> &[Row] {
        &self.rows
    }

    /// The number of rows, B.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the fleet has no row.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Starts one row per entry of `episodes`, from random starts drawn from `seed` (see the
    /// [module docs](self)), and reads their sensors. On an error the rows are as they were.
    pub fn reset(&mut self, episodes: &[u64], seed: u64) -> Result<(), Error> {
        let rows = episodes
            .iter()
            .map(|&e| self.arena.start(e, seed))
            .collect::<Result<Vec<Row>, Error>>()?;
        self.rows = rows;
        Ok(())
    }

    /// Puts every row's robot at `poses` (B of them) and, when given, its pursuers at
    /// `pursuers` (B x K, row by row), then reads their sensors (drawing noise) and clears
    /// `contact`. Errors, before changing anything, on a wrong count, a value that is not finite,
    /// or a robot or pursuer that overlaps a wall or box.
    pub fn place(&mut self, poses: &[Pose], pursuers: Option<&[Pose]>) -> Result<(), Error> {
        let (b, k) = (self.rows.len(), self.arena.spec.pursuers.count as usize);
        if poses.len() != b {
            return Err(Error::invalid(
                "poses",
                format!("{} poses", poses.len()),
                &format!("one per row, {b}"),
            ));
        }
        if let Some(p) = pursuers {
            if p.len() != b * k {
                return Err(Error::invalid(
                    "pursuers",
                    format!("{} poses", p.len()),
                    &format!("K = {k} per row, {}", b * k),
                ));
            }
        }
        let s = &self.arena.spec;
        for (i, p) in poses.iter().enumerate() {
            self.check_pose(&format!("poses[{i}]"), p, s.robot.radius)?;
        }
        for (i, p) in pursuers.unwrap_or(&[]).iter().enumerate() {
            let at = format!("pursuers[{}, {}]", i / k, i % k);
            self.check_pose(&at, p, s.pursuers.radius)?;
        }
        for (r, row) in self.rows.iter_mut().enumerate() {
            row.pose = poses[r];
            if let Some(p) = pursuers {
                row.pursuers.copy_from_slice(&p[r * k..(r + 1) * k]);
            }
            row.contact = false;
            self.arena.sense(row);
        }
        Ok(())
    }

    /// Checks that `p` is finite and that a disc of `radius` there lies inside the room and
    /// overlaps no wall or box.
    fn check_pose(&self, at: &str, p: &Pose, radius: f64) -> Result<(), Error> {
        for (v, what) in [(p.x, "x"), (p.y, "y"), (p.heading, "heading")] {
            let field = format!("{at}.{what}");
            check_range(&field, v, f64::NEG_INFINITY, false, f64::INFINITY, false)?;
        }
        // Clearance measures the distance to the walls, which is as large outside the room.
        let [w, h] = self.arena.world.room();
        let inside = (radius..=w - radius).contains(&p.x) && (radius..=h - radius).contains(&p.y);
        let c = self.arena.world.clearance(p.position(), radius);
        if !inside || c < 0.0 {
            return Err(Error::invalid(
                at,
                format!("({}, {}) with clearance {c:.4} m", p.x, p.y),
                "a position inside the room where it overlaps no wall or box",
            ));
        }
        Ok(())
    }

    /// Checks a step's arguments: `wheels` holds `(v_left, v_right)` for every row (2 B values,
    /// row by row), finite in every row that `active` (B flags, or `None` for all) marks.
    pub fn check_step(&self, wheels: &[f64], active: Option<&[bool]>) -> Result<(), Error> {
        let b = self.rows.len();
        if wheels.len() != 2 * b {
            return Err(Error::invalid(
                "wheels",
                format!("{} values", wheels.len()),
                &format!("two per row, {}", 2 * b),
            ));
        }
        if let Some(a) = active {
            if a.len() != b {
                return Err(Error::invalid(
                    "active",
                    format!("{} flags", a.len()),
                    &format!("one per row, {b}"),
                ));
            }
        }
        for (i, v) in wheels.iter().enumerate() {
            if !v.is_finite() && active.is_none_or(|a| a[i / 2]) {
                return Err(Error::invalid(
                    format!("wheels[{}, {}]", i / 2, i % 2),
                    v,
                    "a finite number",
                ));
            }
        }
        Ok(())
    }

    /// Steps every row that `active` marks (every row for `None`) with its wheel speeds (see
    /// [`Fleet::check_step`] and the [module docs](self)); other rows are left as they were,
    /// their wheel speeds unread. Errors, before changing anything, on bad arguments.
    /// Allocates nothing.
    pub fn step(&mut self, wheels: &[f64], active: Option<&[bool]>) -> Result<(), Error> {
        self.check_step(wheels, active)?;
        let (arena, rows) = (&self.arena, &mut self.rows);
        for (r, row) in rows.iter_mut().enumerate() {
            if active.is_none_or(|a| a[r]) {
                arena.step_row(row, wheels[2 * r], wheels[2 * r + 1])?;
            }
        }
        Ok(())
    }

    /// The arena and the rows apart, for a caller that steps rows on many threads with
    /// [`Arena::step_row`] after [`Fleet::check_step`]. Each row depends only on itself and the
    /// arena, so any split of the rows over threads gives the same bits.
    pub fn split_mut(&mut self) -> (&Arena, &mut [Row]) {
        (&self.arena, &mut self.rows)
    }
}
