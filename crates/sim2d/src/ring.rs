//! A ring of sonars around the robot's rim, read through a [`Scene`] so that pursuers echo too.
//!
//! Each sonar works as [`Sonar`](crate::Sonar) does: a cone of `cone_deg` sampled by `rays` rays
//! spread evenly from edge to edge (one ray: the axis only), cast from the transducer on the
//! robot's rim at `angles_deg[i]` from the heading; a ray that meets a surface at an angle of
//! incidence above `specular_max_incidence_deg` returns nothing; the reading is the nearest
//! return plus Gaussian noise of `noise_sd`, clamped to `[min_range, max_range]`, or `max_range`
//! when nothing echoed. Walls, boxes and every pursuer's disc echo. Casts are exact in `f64`
//! (see [`Scene`]), where a lone [`Sonar`](crate::Sonar) goes through parry2d in `f32`.
//!
//! Ray `i` of a sonar at `a` degrees points at `a_i = radians(a) - cone / 2 + i * cone / (rays -
//! 1)` from the heading `h`. Its direction is computed once in the robot's frame,
//! `(cos a_i, sin a_i)`, and turned by the heading at each reading: `(cos h cos a_i - sin h sin
//! a_i, sin h cos a_i + cos h sin a_i)`, which is `(cos(h + a_i), sin(h + a_i))` to rounding.
//! The transducer sits on the rim, at the robot's radius along the sonar's axis.

use streams::Stream;

use crate::error::{check_count, check_range, Error};
use crate::pose::Pose;
use crate::scene::{Disc, Scene};
use crate::sonar::SonarSpec;

/// The sonars of a ring and the physics they share. `Default` is eight sonars every 45 degrees,
/// each a 25-degree cone of three rays reaching 6.5 m, without noise.
///
/// # Example
/// ```
/// let ring = sim2d::RingSpec::default();
/// assert_eq!(ring.angles_deg, [0.0, 45.0, 90.0, 135.0, 180.0, -135.0, -90.0, -45.0]);
/// assert!(ring.validate().is_ok());
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RingSpec {
    /// Each sonar's axis relative to the heading, in degrees, counter-clockwise positive; the
    /// readings come in this order. Any finite values, any number of sonars (none is allowed).
    /// Default `[0, 45, 90, 135, 180, -135, -90, -45]`: the front, then round to the left.
    pub angles_deg: Vec<f64>,
    /// The full opening angle of each cone in degrees, in (0, 180). Default 25.
    pub cone_deg: f64,
    /// How many rays sample each cone, >= 1. Default 3.
    pub rays: u32,
    /// The shortest range reported, in metres, >= 0. Default 0.15.
    pub min_range: f64,
    /// The longest range, reported when nothing echoes, in metres, > `min_range`. Default 6.5.
    pub max_range: f64,
    /// The standard deviation of Gaussian noise added to a range that echoed, in metres, >= 0.
    /// Default 0 (no noise, and no random draws).
    pub noise_sd: f64,
    /// When set, a ray whose angle of incidence exceeds this many degrees, in [0, 90], is lost to
    /// a specular reflection. Default `None`.
    pub specular_max_incidence_deg: Option<f64>,
}

impl Default for RingSpec {
    fn default() -> Self {
        RingSpec {
            angles_deg: vec![0.0, 45.0, 90.0, 135.0, 180.0, -135.0, -90.0, -45.0],
            cone_deg: 25.0,
            rays: 3,
            min_range: 0.15,
            max_range: 6.5,
            noise_sd: 0.0,
            specular_max_incidence_deg: None,
        }
    }
}

impl RingSpec {
    /// Checks every field; the error names the first bad one (as `sonar.<field>`).
    pub fn validate(&self) -> Result<(), Error> {
        check_count("sonar.angles_deg's length", self.angles_deg.len() as u64, 0)?;
        for (i, a) in self.angles_deg.iter().enumerate() {
            check_range(
                &format!("sonar.angles_deg[{i}]"),
                *a,
                -360.0,
                true,
                360.0,
                true,
            )?;
        }
        self.sonar(0.0, 0.0).validate_as("sonar")
    }

    /// One sonar of the ring as a [`SonarSpec`].
    fn sonar(&self, angle_deg: f64, offset: f64) -> SonarSpec {
        SonarSpec {
            mount_angle_deg: angle_deg,
            mount_offset: offset,
            cone_deg: self.cone_deg,
            rays: self.rays,
            min_range: self.min_range,
            max_range: self.max_range,
            noise_sd: self.noise_sd,
            specular_max_incidence_deg: self.specular_max_incidence_deg,
            lobe_deg: None,
            dropout: 0.0,
        }
    }
}

/// A validated ring on a robot of a given radius, ready to read.
///
/// # Example
/// ```
/// use streams::{Purpose, Stream};
/// use sim2d::{Disc, Pose, Ring, RingSpec, Scene, WorldSpec};
/// let scene = Scene::new(&WorldSpec::landmark(1)?);
/// let ring = Ring::new(&RingSpec { angles_deg: vec![0.0, 90.0], ..RingSpec::default() }, 0.25)?;
/// let mut stream = Stream::new(0, 0, Purpose::Trial, 0, 0);
/// let mut ranges = [0.0; 2];
/// // At (1, 1) facing +x, a pursuer of radius 0.2 at (2, 1): 1 - 0.25 - 0.2 = 0.55 m ahead.
/// // To the left (+y) the top wall at y = 5: 5 - 1 - 0.25 = 3.75 m.
/// let pursuer = Disc { center: [2.0, 1.0], radius: 0.2 };
/// ring.read(&scene, &Pose::new(1.0, 1.0, 0.0), &[pursuer], &mut stream, &mut ranges);
/// assert!((ranges[0] - 0.55).abs() < 1e-12 && (ranges[1] - 3.75).abs() < 1e-12);
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Ring {
    spec: RingSpec,
    /// Each sonar's axis as a unit vector in the robot's frame (x ahead, y to the left).
    axes: Vec<[f64; 2]>,
    /// Each ray's direction in the robot's frame, `rays` per sonar, sonar by sonar.
    rays: Vec<[f64; 2]>,
    /// The transducers' distance from the robot's centre: its radius.
    offset: f64,
    /// The cosine of the steepest incidence that still echoes (-1: no specular misses).
    min_cos_incidence: f64,
}

impl Ring {
    /// Validates `spec` and places its sonars on the rim of a robot of `radius` metres (> 0).
    pub fn new(spec: &RingSpec, radius: f64) -> Result<Ring, Error> {
        spec.validate()?;
        crate::error::check_range("robot.radius", radius, 0.0, false, f64::INFINITY, false)?;
        let cone = spec.cone_deg.to_radians();
        let (first_ray, ray_step) = if spec.rays == 1 {
            (0.0, 0.0)
        } else {
            (-0.5 * cone, cone / (spec.rays - 1) as f64)
        };
        let min_cos_incidence = match spec.specular_max_incidence_deg {
            Some(a) => a.to_radians().cos(),
            None => -1.0,
        };
        let unit = |angle: f64| {
            let (s, c) = angle.sin_cos();
            [c, s]
        };
        let axes: Vec<f64> = spec.angles_deg.iter().map(|a| a.to_radians()).collect();
        Ok(Ring {
            spec: spec.clone(),
            rays: axes
                .iter()
                .flat_map(|a| {
                    (0..spec.rays).map(move |i| unit(a + first_ray + ray_step * i as f64))
                })
                .collect(),
            axes: axes.into_iter().map(unit).collect(),
            offset: radius,
            min_cos_incidence,
        })
    }

    /// The ring's spec.
    pub fn spec(&self) -> &RingSpec {
        &self.spec
    }

    /// How many sonars the ring has.
    pub fn len(&self) -> usize {
        self.axes.len()
    }

    /// Whether the ring has no sonar.
    pub fn is_empty(&self) -> bool {
        self.axes.is_empty()
    }

    /// Reads every sonar for a robot at `pose` among `discs` into `ranges` (one per sonar, in
    /// the order of `angles_deg`; extra entries are left alone, missing ones not read).
    ///
    /// Draws one normal variate from `stream` per sonar that echoed, in order, only when
    /// `noise_sd > 0`. Allocates nothing.
    pub fn read(
        &self,
        scene: &Scene,
        pose: &Pose,
        discs: &[Disc],
        stream: &mut Stream,
        ranges: &mut [f64],
    ) {
        let s = &self.spec;
        let (sin, cos) = pose.heading.sin_cos();
        let turn = |v: &[f64; 2]| [cos * v[0] - sin * v[1], sin * v[0] + cos * v[1]];
        let rays = self.rays.chunks_exact(s.rays as usize);
        for ((axis, rays), out) in self.axes.iter().zip(rays).zip(ranges.iter_mut()) {
            let [mx, my] = turn(axis);
            let origin = [pose.x + self.offset * mx, pose.y + self.offset * my];
            let mut nearest: Option<f64> = None;
            for ray in rays {
                let dir = turn(ray);
                let reach = nearest.unwrap_or(s.max_range);
                let Some(hit) = scene.cast(origin, dir, reach, discs) else {
                    continue;
                };
                // cos(incidence) = -dir . normal; a ray from inside a surface (distance 0) echoes.
                let cos_inc = -(dir[0] * hit.normal[0] + dir[1] * hit.normal[1]);
                if hit.distance > 0.0 && cos_inc < self.min_cos_incidence {
                    continue;
                }
                if nearest.is_none_or(|d| hit.distance < d) {
                    nearest = Some(hit.distance);
                }
            }
            *out = match nearest {
                None => s.max_range,
                Some(d) => {
                    let noisy = if s.noise_sd > 0.0 {
                        d + s.noise_sd * stream.normal()
                    } else {
                        d
                    };
                    noisy.clamp(s.min_range, s.max_range)
                }
            };
        }
    }
}
