//! A trial in the world: the robot driven by the wall follower at a fixed time step, with its
//! sonars read before every step.
//!
//! [`Sim::step`] is the loop body for a task that feeds sonar readings to a network;
//! [`Sim::run`] runs many steps and can record poses and echoes into a caller's [`Trace`].
//! Neither allocates, except for the caller's trace growing.

use streams::Stream;

use crate::error::{check_range, Error};
use crate::pose::Pose;
use crate::robot::RobotSpec;
use crate::sonar::{Echo, Sonar, SonarSpec};
use crate::wall_follow::{WallFollower, WallFollowerSpec};
use crate::world::World;

/// The settings of a trial. `Default` is the landmark experiment's robot with one left sonar.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimSpec {
    /// The simulated time per step, in seconds, > 0. Default 0.1 (a 45 s trial is 450 steps).
    pub dt: f64,
    /// The robot. Default [`RobotSpec::default`].
    pub robot: RobotSpec,
    /// The wall follower. Default [`WallFollowerSpec::default`].
    pub follower: WallFollowerSpec,
    /// The sonars, read in this order. Default one [`SonarSpec::default`] (the left side).
    pub sonars: Vec<SonarSpec>,
    /// The least clearance of a random start, in metres, >= 0. Default 0.05.
    pub start_clearance: f64,
}

impl Default for SimSpec {
    fn default() -> Self {
        SimSpec {
            dt: 0.1,
            robot: RobotSpec::default(),
            follower: WallFollowerSpec::default(),
            sonars: vec![SonarSpec::default()],
            start_clearance: 0.05,
        }
    }
}

impl SimSpec {
    /// Checks every field; the error names the first bad one (sonars as `sonars[i].<field>`).
    pub fn validate(&self) -> Result<(), Error> {
        check_range("dt", self.dt, 0.0, false, f64::INFINITY, false)?;
        self.robot.validate()?;
        self.follower.validate(&self.robot)?;
        for (i, s) in self.sonars.iter().enumerate() {
            s.validate_as(&format!("sonars[{i}]"))?;
        }
        check_range(
            "start_clearance",
            self.start_clearance,
            0.0,
            true,
            f64::INFINITY,
            false,
        )?;
        Ok(())
    }
}

/// What [`Sim::run`] records: the pose at the start of every step and the echoes read there.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    /// One pose per step, before the step's motion.
    pub poses: Vec<Pose>,
    /// The echoes, step by step: `sonars.len()` per step, in the sonars' order.
    pub echoes: Vec<Echo>,
}

impl Trace {
    /// An empty trace with room for `steps` steps of `sonars` sonars.
    pub fn with_capacity(steps: usize, sonars: usize) -> Trace {
        Trace {
            poses: Vec::with_capacity(steps),
            echoes: Vec::with_capacity(steps * sonars),
        }
    }
}

/// One trial: a world, the robot's pose, its follower and sonars, and the simulated time.
///
/// # Example
/// ```
/// use streams::{Purpose, Stream};
/// use sim2d::{Echo, Sim, SimSpec, World, WorldSpec};
/// let world = World::new(&WorldSpec::landmark(2)?)?;
/// let mut stream = Stream::new(7, 0, Purpose::Trial, 0, 0);
/// let mut sim = Sim::random_start(&world, &SimSpec::default(), &mut stream)?;
/// let mut echo = [Echo::default()];
/// for _ in 0..450 {
///     sim.step(&mut stream, &mut echo)?;
///     let x = sim2d::input(echo[0].range, sim2d::DEFAULT_D0); // the network's input
///     assert!((0.0..=1.0).contains(&x));
/// }
/// assert!((sim.time() - 45.0).abs() < 1e-9);
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Sim<'w> {
    world: &'w World,
    robot: RobotSpec,
    follower: WallFollower,
    sonars: Vec<Sonar>,
    pose: Pose,
    dt: f64,
    steps: u64,
    contacts: u64,
}

impl<'w> Sim<'w> {
    /// A trial starting at `start`; validates `spec`. A start that overlaps a wall or box is an
    /// error.
    pub fn new(world: &'w World, spec: &SimSpec, start: Pose) -> Result<Sim<'w>, Error> {
        spec.validate()?;
        for (name, v) in [("start.x", start.x), ("start.y", start.y)] {
            check_range(name, v, f64::NEG_INFINITY, false, f64::INFINITY, false)?;
        }
        check_range(
            "start.heading",
            start.heading,
            f64::NEG_INFINITY,
            false,
            f64::INFINITY,
            false,
        )?;
        let [w, h] = world.room();
        if !(start.x > 0.0 && start.x < w && start.y > 0.0 && start.y < h) {
            return Err(Error::invalid(
                "start",
                format!("({}, {})", start.x, start.y),
                &format!("a position inside the room, (0, {w}) x (0, {h})"),
            ));
        }
        let c = world.clearance(start.position(), spec.robot.radius);
        if c < 0.0 {
            return Err(Error::invalid(
                "start",
                format!("({}, {}) with clearance {c:.4} m", start.x, start.y),
                "a position where the robot overlaps no wall or box",
            ));
        }
        Ok(Sim {
            world,
            robot: spec.robot.clone(),
            follower: WallFollower::new(&spec.follower, &spec.robot)?,
            sonars: spec.sonars.iter().map(Sonar::new_unchecked).collect(),
            pose: start,
            dt: spec.dt,
            steps: 0,
            contacts: 0,
        })
    }

    /// A trial from a random start drawn from `stream` by
    /// [`World::random_pose`] with `spec.start_clearance`.
    pub fn random_start(
        world: &'w World,
        spec: &SimSpec,
        stream: &mut Stream,
    ) -> Result<Sim<'w>, Error> {
        spec.validate()?;
        let start = world.random_pose(spec.robot.radius, spec.start_clearance, stream)?;
        Sim::new(world, spec, start)
    }

    /// Reads every sonar at the current pose into `echoes` (one per sonar, in order), then moves
    /// the robot by the follower's command for one `dt`.
    ///
    /// Errors if `echoes.len()` differs from the number of sonars. Allocates nothing.
    pub fn step(&mut self, stream: &mut Stream, echoes: &mut [Echo]) -> Result<(), Error> {
        if echoes.len() != self.sonars.len() {
            return Err(Error::invalid(
                "echoes.len()",
                echoes.len(),
                &format!("the number of sonars, {}", self.sonars.len()),
            ));
        }
        for (sonar, out) in self.sonars.iter().zip(echoes.iter_mut()) {
            *out = sonar.read(self.world, &self.pose, stream);
        }
        let (vl, vr) = self.follower.command(self.world, &self.pose);
        if self
            .robot
            .step(&mut self.pose, vl, vr, self.dt, self.world)?
        {
            self.contacts += 1;
        }
        self.steps += 1;
        Ok(())
    }

    /// Runs `steps` steps, appending each step's pose and echoes to `trace` if given.
    pub fn run(
        &mut self,
        steps: u64,
        stream: &mut Stream,
        mut trace: Option<&mut Trace>,
    ) -> Result<(), Error> {
        // Up to 8 sonars on the stack; more go through the trace or a one-off buffer.
        let n = self.sonars.len();
        let mut small = [Echo::default(); 8];
        let mut large = Vec::new();
        let buf: &mut [Echo] = if n <= small.len() {
            &mut small[..n]
        } else {
            large.resize(n, Echo::default());
            &mut large
        };
        for _ in 0..steps {
            let pose = self.pose;
            self.step(stream, buf)?;
            if let Some(t) = trace.as_deref_mut() {
                t.poses.push(pose);
                t.echoes.extend_from_slice(buf);
            }
        }
        Ok(())
    }

    /// The robot's current pose.
    pub fn pose(&self) -> Pose {
        self.pose
    }

    /// The simulated time so far, in seconds (steps times `dt`).
    pub fn time(&self) -> f64 {
        self.steps as f64 * self.dt
    }

    /// How many steps have run.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// How many steps were cut short by a contact with a wall or box.
    pub fn contacts(&self) -> u64 {
        self.contacts
    }

    /// The wall follower (its phase tells whether it has reached a wall).
    pub fn follower(&self) -> &WallFollower {
        &self.follower
    }

    /// The world.
    pub fn world(&self) -> &'w World {
        self.world
    }

    /// The number of sonars.
    pub fn sonar_count(&self) -> usize {
        self.sonars.len()
    }
}
