//! The world's geometry: the room's four walls and its boxes as parry2d shapes, with ray casts
//! and disc clearance queries.
//!
//! Shapes are built once by [`World::new`]; queries allocate nothing. parry2d 0.25 computes in
//! `f32`, so distances carry an error of about `1e-6` m in a room of a few metres; the public API
//! is in `f64`.

use std::f64::consts::PI;

use parry2d::math::{Isometry, Point, Real, Vector};
use parry2d::query::{PointQuery, Ray, RayCast};
use parry2d::shape::Cuboid;
use streams::Stream;

use crate::error::{check_range, Error};
use crate::pose::Pose;
use crate::world_spec::WorldSpec;

/// How many random positions [`World::random_pose`] tries before giving up.
pub const START_ATTEMPTS: u32 = 10_000;

/// The side of the grid of points on which [`World::check_start`] measures how much of the start
/// region is free: `START_GRID x START_GRID` cell centres.
pub const START_GRID: usize = 64;

/// The least share of the start region's grid points at which a robot must fit for
/// [`World::check_start`]: at 1%, all [`START_ATTEMPTS`] draws of one start miss with a
/// probability of about `0.99^10000`, 2e-44, so a start never fails by chance.
pub const MIN_START_FREE: f64 = 0.01;

/// The thickness of each wall slab outside the room, in metres (any positive value works).
const WALL_THICKNESS: f64 = 1.0;

/// Checks a robot's `radius` (> 0) and the `min_clearance` (>= 0) it must keep, as the start
/// functions take them.
fn check_robot(radius: f64, min_clearance: f64) -> Result<(), Error> {
    check_range("radius", radius, 0.0, false, f64::INFINITY, false)?;
    check_range(
        "min_clearance",
        min_clearance,
        0.0,
        true,
        f64::INFINITY,
        false,
    )
}

/// What a ray hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surface {
    /// One of the room's four walls.
    Wall,
    /// The box with this index in [`WorldSpec::boxes`].
    Box(usize),
}

/// The nearest intersection of a ray with the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The distance from the ray's origin to the hit point, in metres.
    pub distance: f64,
    /// The hit point `[x, y]`.
    pub point: [f64; 2],
    /// The surface's outward unit normal at the hit point (pointing back into the room).
    pub normal: [f64; 2],
    /// What was hit.
    pub surface: Surface,
}

/// One convex obstacle: a cuboid placed by an isometry.
#[derive(Clone, Debug)]
struct Obstacle {
    pose: Isometry<Real>,
    shape: Cuboid,
    surface: Surface,
}

/// A room with walls and boxes, ready for ray casts and clearance queries.
///
/// # Example
/// ```
/// use sim2d::{Surface, World, WorldSpec};
/// let world = World::new(&WorldSpec::landmark(1)?)?;
/// // From (1, 2.5) looking +x: the landmark's left face is at x = 2.4.
/// let hit = world.cast_ray([1.0, 2.5], [1.0, 0.0], 10.0).unwrap();
/// assert!((hit.distance - 1.4).abs() < 1e-5);
/// assert_eq!(hit.surface, Surface::Box(0));
/// // Looking -x, the left wall at x = 0.
/// let hit = world.cast_ray([1.0, 2.5], [-1.0, 0.0], 10.0).unwrap();
/// assert_eq!((hit.surface, hit.normal), (Surface::Wall, [1.0, 0.0]));
/// // A robot of radius 0.265 at (1, 1) is 0.735 m from the nearest wall.
/// assert!((world.clearance([1.0, 1.0], 0.265) - 0.735).abs() < 1e-5);
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct World {
    spec: WorldSpec,
    /// The four walls first, then the boxes in order.
    obstacles: Vec<Obstacle>,
}

fn isometry(center: [f64; 2], angle: f64) -> Isometry<Real> {
    Isometry::new(
        Vector::new(center[0] as Real, center[1] as Real),
        angle as Real,
    )
}

fn cuboid(size: [f64; 2]) -> Cuboid {
    Cuboid::new(Vector::new(0.5 * size[0] as Real, 0.5 * size[1] as Real))
}

impl World {
    /// Validates `spec` and builds its shapes: four wall slabs just outside the room (overlapping
    /// at the corners) and one cuboid per box.
    pub fn new(spec: &WorldSpec) -> Result<World, Error> {
        spec.validate()?;
        let [w, h] = spec.room;
        let t = WALL_THICKNESS;
        let walls = [
            ([0.5 * w, -0.5 * t], [w + 2.0 * t, t]),    // bottom
            ([w + 0.5 * t, 0.5 * h], [t, h + 2.0 * t]), // right
            ([0.5 * w, h + 0.5 * t], [w + 2.0 * t, t]), // top
            ([-0.5 * t, 0.5 * h], [t, h + 2.0 * t]),    // left
        ];
        let mut obstacles = Vec::with_capacity(4 + spec.boxes.len());
        for (center, size) in walls {
            obstacles.push(Obstacle {
                pose: isometry(center, 0.0),
                shape: cuboid(size),
                surface: Surface::Wall,
            });
        }
        for (i, b) in spec.boxes.iter().enumerate() {
            obstacles.push(Obstacle {
                pose: isometry(b.center, b.angle_deg.to_radians()),
                shape: cuboid(b.size),
                surface: Surface::Box(i),
            });
        }
        Ok(World {
            spec: spec.clone(),
            obstacles,
        })
    }

    /// The world's description.
    pub fn spec(&self) -> &WorldSpec {
        &self.spec
    }

    /// The room's `[width, height]` in metres.
    pub fn room(&self) -> [f64; 2] {
        self.spec.room
    }

    /// The nearest hit of the ray from `origin` along `dir` within `max_distance`, over all walls
    /// and boxes; `None` if nothing is that close.
    ///
    /// `dir` need not be a unit vector; a zero or non-finite `dir`, or an origin that is not
    /// finite in f32 (the geometry's precision), hits nothing. An origin inside a wall or box hits
    /// it at distance 0. Allocates nothing.
    pub fn cast_ray(&self, origin: [f64; 2], dir: [f64; 2], max_distance: f64) -> Option<Hit> {
        let norm = dir[0].hypot(dir[1]);
        let finite = origin.iter().all(|&v| (v as Real).is_finite());
        if !(finite && norm > 0.0 && norm.is_finite() && max_distance >= 0.0) {
            return None;
        }
        let ray = Ray::new(
            Point::new(origin[0] as Real, origin[1] as Real),
            Vector::new((dir[0] / norm) as Real, (dir[1] / norm) as Real),
        );
        let mut best_toi = max_distance.min(f32::MAX as f64) as Real;
        let mut best = None;
        for ob in &self.obstacles {
            if let Some(hit) = ob
                .shape
                .cast_ray_and_get_normal(&ob.pose, &ray, best_toi, true)
            {
                if hit.time_of_impact <= best_toi {
                    best_toi = hit.time_of_impact;
                    best = Some((hit, ob.surface));
                }
            }
        }
        best.map(|(hit, surface)| {
            let p = ray.point_at(hit.time_of_impact);
            Hit {
                distance: hit.time_of_impact as f64,
                point: [p.x as f64, p.y as f64],
                normal: [hit.normal.x as f64, hit.normal.y as f64],
                surface,
            }
        })
    }

    /// The signed clearance of a disc: the distance from the disc's edge to the nearest wall or
    /// box, negative by the depth of the deepest overlap when it overlaps one.
    ///
    /// Allocates nothing.
    pub fn clearance(&self, center: [f64; 2], radius: f64) -> f64 {
        let p = Point::new(center[0] as Real, center[1] as Real);
        let mut nearest = f64::INFINITY;
        for ob in &self.obstacles {
            let proj = ob.shape.project_point(&ob.pose, &p, false);
            let d = (proj.point - p).norm() as f64;
            let signed = if proj.is_inside { -d } else { d };
            nearest = nearest.min(signed);
        }
        nearest - radius
    }

    /// Calls `f(signed_distance, outward_normal)` for each wall and box: the signed distance from
    /// `point` to it (negative inside) and the unit vector along which that distance grows fastest
    /// (`[0, 0]` when the point is on the boundary). Allocates nothing.
    pub(crate) fn for_each_distance(&self, point: [f64; 2], mut f: impl FnMut(f64, [f64; 2])) {
        let p = Point::new(point[0] as Real, point[1] as Real);
        for ob in &self.obstacles {
            let proj = ob.shape.project_point(&ob.pose, &p, false);
            let diff = p - proj.point;
            let d = diff.norm() as f64;
            let (signed, sign) = if proj.is_inside { (-d, -1.0) } else { (d, 1.0) };
            let n = if d > 0.0 {
                [sign * diff.x as f64 / d, sign * diff.y as f64 / d]
            } else {
                [0.0, 0.0]
            };
            f(signed, n);
        }
    }

    /// Whether a disc overlaps a wall or a box (its clearance is negative).
    pub fn disc_overlaps(&self, center: [f64; 2], radius: f64) -> bool {
        self.clearance(center, radius) < 0.0
    }

    /// The share of the start region at which a robot of `radius` is at least `min_clearance`
    /// from every wall and box, measured at the centres of a [`START_GRID`] x [`START_GRID`] grid
    /// over the region (a region of zero width or height is a line or a point, sampled along it).
    pub fn start_free_share(&self, radius: f64, min_clearance: f64) -> f64 {
        let (lo, hi) = (self.spec.start.min, self.spec.start.max);
        let at =
            |k: usize, i: usize| lo[k] + (hi[k] - lo[k]) * (i as f64 + 0.5) / START_GRID as f64;
        let mut free = 0usize;
        for i in 0..START_GRID {
            for j in 0..START_GRID {
                if self.clearance([at(0, i), at(1, j)], radius) >= min_clearance {
                    free += 1;
                }
            }
        }
        free as f64 / (START_GRID * START_GRID) as f64
    }

    /// Checks that [`random_pose`](Self::random_pose) can start a robot of `radius` with
    /// `min_clearance` every time: at least [`MIN_START_FREE`] of the start region
    /// ([`start_free_share`](Self::start_free_share)) must be free. A region that is free only in
    /// slivers would otherwise fail at random, some episodes and generations later.
    ///
    /// ```
    /// use sim2d::{Error, World, WorldSpec};
    /// let open = World::new(&WorldSpec::landmark(1)?)?;
    /// open.check_start(0.265, 0.05)?;
    /// let crowded = World::new(&WorldSpec::from_toml_str(
    ///     "room = [2.0, 2.0]\nstart = { min = [0.3, 0.3], max = [1.7, 1.7] }\n\
    ///      [[boxes]]\ncenter = [1.0, 1.0]\nsize = [1.2, 1.2]\n",
    /// )?)?;
    /// assert!(matches!(crowded.check_start(0.265, 0.05), Err(Error::StartBlocked { .. })));
    /// # Ok::<(), Error>(())
    /// ```
    pub fn check_start(&self, radius: f64, min_clearance: f64) -> Result<(), Error> {
        check_robot(radius, min_clearance)?;
        let share = self.start_free_share(radius, min_clearance);
        if share < MIN_START_FREE {
            return Err(Error::StartBlocked {
                share,
                needed: MIN_START_FREE,
                radius,
                clearance: min_clearance,
            });
        }
        Ok(())
    }

    /// A random start pose for a robot of `radius`: a position uniform in the start region, redrawn
    /// until the robot's clearance is at least `min_clearance` (up to [`START_ATTEMPTS`] draws),
    /// then a heading uniform in `[-pi, pi)`.
    ///
    /// Draws two uniforms per tried position, then one for the heading. Returns
    /// [`Error::NoStartPose`] if every draw was too close to a wall or box.
    ///
    /// # Example
    /// ```
    /// use streams::{Purpose, Stream};
    /// let world = sim2d::World::new(&sim2d::WorldSpec::landmark(2)?)?;
    /// let mut s = Stream::new(0, 0, Purpose::Trial, 0, 0);
    /// let pose = world.random_pose(0.265, 0.05, &mut s)?;
    /// assert!(world.clearance(pose.position(), 0.265) >= 0.05);
    /// # Ok::<(), sim2d::Error>(())
    /// ```
    pub fn random_pose(
        &self,
        radius: f64,
        min_clearance: f64,
        stream: &mut Stream,
    ) -> Result<Pose, Error> {
        check_robot(radius, min_clearance)?;
        let (lo, hi) = (self.spec.start.min, self.spec.start.max);
        for _ in 0..START_ATTEMPTS {
            let x = stream.range(lo[0], hi[0]);
            let y = stream.range(lo[1], hi[1]);
            if self.clearance([x, y], radius) >= min_clearance {
                let heading = stream.range(-PI, PI);
                return Ok(Pose::new(x, y, heading));
            }
        }
        Err(Error::NoStartPose {
            attempts: START_ATTEMPTS,
            radius,
            clearance: min_clearance,
        })
    }
}
