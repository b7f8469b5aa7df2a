//! A small 2-D robot world for the landmark-recognition experiment (paper §3): a room's walls and
//! boxes (parry2d shapes), a Nomad-200-like disc robot with differential drive that never passes
//! through anything, a Polaroid-like sonar and a hand-coded wall follower. It knows no network.
//!
//! | concept | where |
//! |---|---|
//! | world files, the two landmark worlds, jitter | [`WorldSpec`] (`world_spec.rs`, `worlds/*.toml`) |
//! | shapes, ray casts, clearance, random starts | [`World`] (`world.rs`) |
//! | the robot's pose | [`Pose`] (`pose.rs`) |
//! | differential drive and collisions | [`RobotSpec`] (`robot.rs`) |
//! | sonar cone, noise, specular misses, network input | [`Sonar`], [`input`] (`sonar.rs`) |
//! | finding and following the perimeter | [`WallFollower`] (`wall_follow.rs`) |
//! | a trial at a fixed time step | [`Sim`] (`sim.rs`) |
//! | many robots stepped together, one per row, for a closed loop | [`Fleet`] (`fleet.rs`) |
//! | pursuers and their pure-pursuit policy | [`PursuerSpec`] (`pursuer.rs`) |
//! | a ring of sonars that pursuers echo on | [`Ring`] (`ring.rs`) |
//! | the pursuer sensor | [`SectorSpec`] (`sectors.rs`) |
//! | exact `f64` ray casts against walls, boxes and discs | [`Scene`] (`scene.rs`) |
//!
//! Randomness (start poses, sonar noise, jitter) comes only from a caller's
//! [`streams::Stream`], so a trial is reproducible to the bit.
//!
//! # Example
//! A 45 s trial in the world of landmark 1, feeding the left sonar's input to a model:
//! ```
//! use streams::{Purpose, Stream};
//! use sim2d::{Echo, Sim, SimSpec, World, WorldSpec};
//!
//! let world = World::new(&WorldSpec::landmark(1)?)?;
//! let mut stream = Stream::new(42, 0, Purpose::Trial, 0, 0);
//! let mut sim = Sim::random_start(&world, &SimSpec::default(), &mut stream)?;
//! let mut echo = [Echo::default()];
//! let mut inputs = Vec::with_capacity(450);
//! while sim.time() < 45.0 - 1e-9 {
//!     sim.step(&mut stream, &mut echo)?;
//!     inputs.push(sim2d::input(echo[0].range, sim2d::DEFAULT_D0));
//! }
//! assert_eq!(inputs.len(), 450);
//! assert!(sim.follower().is_following());
//! # Ok::<(), sim2d::Error>(())
//! ```
#![warn(missing_docs)]

mod error;
pub mod fleet;
mod pose;
pub mod pursuer;
pub mod ring;
pub mod robot;
pub mod scene;
pub mod sectors;
pub mod sim;
pub mod sonar;
// Internals for the crate's own integration tests (tests/unit); not public API.
#[doc(hidden)]
pub mod testing;
pub mod wall_follow;
pub mod world;
pub mod world_spec;

pub use error::Error;
pub use fleet::{Arena, Fleet, FleetSpec, Row};
pub use pose::{wrap_angle, Pose};
pub use pursuer::PursuerSpec;
pub use ring::{Ring, RingSpec};
pub use robot::RobotSpec;
pub use scene::{Disc, Scene, SceneHit};
pub use sectors::SectorSpec;
pub use sim::{Sim, SimSpec, Trace};
pub use sonar::{input, Echo, Sonar, SonarSpec, DEFAULT_D0};
/// The random streams the simulator draws from ([`Stream`](streams::Stream)), so that a user of
/// this crate needs no other dependency to make one.
pub use streams;
pub use wall_follow::{Phase, WallFollower, WallFollowerSpec, MAX_GAIN};
pub use world::{Hit, Surface, World};
pub use world_spec::{BoxSpec, StartRegion, WorldSpec, MAX_ROOM};
