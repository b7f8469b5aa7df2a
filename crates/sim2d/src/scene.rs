//! Exact ray casts in `f64` against a world's walls and boxes and against moving discs.
//!
//! [`World::cast_ray`](crate::World::cast_ray) goes through parry2d, which computes in `f32`
//! (distances off by about `1e-6` m). A [`Fleet`](crate::Fleet)'s sonar ring casts through a
//! [`Scene`] instead: the same room and boxes, plus discs (the pursuers) given per cast, with
//! closed-form intersections in `f64`. A ray cast written in NumPy then agrees with it to
//! rounding (`tests/test_robots.py` checks a whole trial to `1e-9`).
//!
//! - The room `[0, width] x [0, height]` is seen from inside: a ray leaves it where it first
//!   crosses `x = 0`, `x = width`, `y = 0` or `y = height`. An origin outside the room is inside
//!   a wall and hits it at distance 0.
//! - A box is a rectangle turned about its centre; a ray meets it by the slab method in the box's
//!   own frame. An origin inside a box hits it at distance 0.
//! - A disc of radius `r` at `c` is met where `|o + t u - c| = r`, the smaller root. An origin
//!   inside a disc hits it at distance 0.
//!
//! Every normal is the surface's outward unit normal at the hit point (for a wall, pointing back
//! into the room).

use crate::world_spec::WorldSpec;

/// A disc that rays can hit: a pursuer's body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disc {
    /// The centre `[x, y]` in metres.
    pub center: [f64; 2],
    /// The radius in metres.
    pub radius: f64,
}

/// Where a ray met a [`Scene`] first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneHit {
    /// The distance from the ray's origin, in metres (0 for an origin inside something).
    pub distance: f64,
    /// The outward unit normal of the surface hit (`[0, 0]` for an origin inside a disc's
    /// centre).
    pub normal: [f64; 2],
}

/// A box in its own frame: centre, turn and half sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rect {
    center: [f64; 2],
    cos: f64,
    sin: f64,
    half: [f64; 2],
}

/// A world's room and boxes for exact `f64` ray casts.
///
/// # Example
/// ```
/// use sim2d::{Disc, Scene, WorldSpec};
/// let scene = Scene::new(&WorldSpec::landmark(1)?);
/// // From (1, 2.5) looking +x: the landmark's left face at x = 2.4.
/// let hit = scene.cast([1.0, 2.5], [1.0, 0.0], 10.0, &[]).unwrap();
/// assert!((hit.distance - 1.4).abs() < 1e-12);
/// assert_eq!(hit.normal, [-1.0, 0.0]);
/// // A disc of radius 0.5 at (2, 2.5) is nearer: its edge at x = 1.5.
/// let disc = Disc { center: [2.0, 2.5], radius: 0.5 };
/// let hit = scene.cast([1.0, 2.5], [1.0, 0.0], 10.0, &[disc]).unwrap();
/// assert!((hit.distance - 0.5).abs() < 1e-12);
/// // Looking -x, the left wall at x = 0; nothing within 0.5 m.
/// assert!((scene.cast([1.0, 2.5], [-1.0, 0.0], 10.0, &[]).unwrap().distance - 1.0).abs() < 1e-12);
/// assert!(scene.cast([1.0, 2.5], [-1.0, 0.0], 0.5, &[]).is_none());
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    room: [f64; 2],
    boxes: Vec<Rect>,
}

impl Scene {
    /// The room and boxes of `spec` (which is not validated again).
    pub fn new(spec: &WorldSpec) -> Scene {
        let boxes = spec
            .boxes
            .iter()
            .map(|b| {
                let (sin, cos) = b.angle_deg.to_radians().sin_cos();
                Rect {
                    center: b.center,
                    cos,
                    sin,
                    half: [0.5 * b.size[0], 0.5 * b.size[1]],
                }
            })
            .collect();
        Scene {
            room: spec.room,
            boxes,
        }
    }

    /// The nearest hit within `reach` (inclusive) of the ray from `origin` along the unit vector
    /// `dir`, over the walls, the boxes and `discs`; `None` when nothing is that close.
    ///
    /// `dir` must be a unit vector; a non-finite `origin` or `dir` hits nothing. Allocates
    /// nothing.
    pub fn cast(
        &self,
        origin: [f64; 2],
        dir: [f64; 2],
        reach: f64,
        discs: &[Disc],
    ) -> Option<SceneHit> {
        if !(origin.iter().chain(&dir).all(|v| v.is_finite()) && reach >= 0.0) {
            return None;
        }
        let mut best: Option<SceneHit> = None;
        let mut limit = reach;
        let mut offer = |hit: Option<SceneHit>| {
            if let Some(h) = hit {
                if h.distance <= limit && best.is_none_or(|b| h.distance < b.distance) {
                    limit = h.distance;
                    best = Some(h);
                }
            }
        };
        offer(self.walls(origin, dir));
        for r in &self.boxes {
            offer(rect_hit(r, origin, dir));
        }
        for d in discs {
            offer(disc_hit(d, origin, dir));
        }
        best
    }

    /// Where the ray leaves the room (0 from outside it).
    fn walls(&self, o: [f64; 2], u: [f64; 2]) -> Option<SceneHit> {
        let [w, h] = self.room;
        if !(o[0] >= 0.0 && o[0] <= w && o[1] >= 0.0 && o[1] <= h) {
            // Inside a wall: the normal of the wall it is deepest in points back into the room.
            let normal = if o[0] < 0.0 {
                [1.0, 0.0]
            } else if o[0] > w {
                [-1.0, 0.0]
            } else if o[1] < 0.0 {
                [0.0, 1.0]
            } else {
                [0.0, -1.0]
            };
            return Some(SceneHit {
                distance: 0.0,
                normal,
            });
        }
        let mut best: Option<SceneHit> = None;
        for axis in 0..2 {
            let (t, normal) = if u[axis] > 0.0 {
                let far = [w, h][axis];
                ((far - o[axis]) / u[axis], -1.0)
            } else if u[axis] < 0.0 {
                (-o[axis] / u[axis], 1.0)
            } else {
                continue;
            };
            if best.is_none_or(|b| t < b.distance) {
                let mut n = [0.0, 0.0];
                n[axis] = normal;
                best = Some(SceneHit {
                    distance: t,
                    normal: n,
                });
            }
        }
        best
    }
}

/// The slab method in the box's frame.
fn rect_hit(r: &Rect, o: [f64; 2], u: [f64; 2]) -> Option<SceneHit> {
    // Into the box's frame: rotate by -angle.
    let (dx, dy) = (o[0] - r.center[0], o[1] - r.center[1]);
    let p = [r.cos * dx + r.sin * dy, -r.sin * dx + r.cos * dy];
    let d = [r.cos * u[0] + r.sin * u[1], -r.sin * u[0] + r.cos * u[1]];
    let mut enter = f64::NEG_INFINITY;
    let mut enter_axis = 0;
    let mut leave = f64::INFINITY;
    for axis in 0..2 {
        let h = r.half[axis];
        if d[axis] == 0.0 {
            if p[axis].abs() > h {
                return None; // parallel to this slab and outside it
            }
            continue;
        }
        let t1 = (-h - p[axis]) / d[axis];
        let t2 = (h - p[axis]) / d[axis];
        let (near, far) = if t1 <= t2 { (t1, t2) } else { (t2, t1) };
        if near > enter {
            enter = near;
            enter_axis = axis;
        }
        leave = leave.min(far);
    }
    if enter > leave || leave < 0.0 {
        return None;
    }
    // The face entered: its normal points against the ray along that axis (in the box's frame).
    let mut local = [0.0, 0.0];
    local[enter_axis] = if d[enter_axis] > 0.0 { -1.0 } else { 1.0 };
    let normal = [
        r.cos * local[0] - r.sin * local[1],
        r.sin * local[0] + r.cos * local[1],
    ];
    Some(SceneHit {
        distance: enter.max(0.0),
        normal,
    })
}

/// The smaller root of `|o + t u - c| = r`.
fn disc_hit(c: &Disc, o: [f64; 2], u: [f64; 2]) -> Option<SceneHit> {
    let q = [o[0] - c.center[0], o[1] - c.center[1]];
    let b = q[0] * u[0] + q[1] * u[1];
    let cc = q[0] * q[0] + q[1] * q[1] - c.radius * c.radius;
    if cc <= 0.0 {
        // Inside (or on) the disc.
        let len = q[0].hypot(q[1]);
        let normal = if len > 0.0 {
            [q[0] / len, q[1] / len]
        } else {
            [0.0, 0.0]
        };
        return Some(SceneHit {
            distance: 0.0,
            normal,
        });
    }
    let disc = b * b - cc;
    if disc < 0.0 || b > 0.0 {
        return None; // misses, or the disc is behind the origin
    }
    let t = -b - disc.sqrt();
    let at = [q[0] + t * u[0], q[1] + t * u[1]];
    Some(SceneHit {
        distance: t,
        normal: [at[0] / c.radius, at[1] / c.radius],
    })
}
