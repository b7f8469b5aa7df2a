//! A Polaroid-like sonar: a cone of rays, the nearest echo, optional range noise and specular
//! misses, and the network's input derived from the range.
//!
//! A sonar is mounted on the robot's rim at `mount_angle_deg` from the heading. Its cone of
//! `cone_deg` is sampled by `rays` rays spread evenly over it (one ray points along the axis).
//! Each ray is cast from the mount point; a ray that meets a surface at an angle of incidence
//! (between the reversed ray and the surface normal) above `specular_max_incidence_deg` is
//! reflected away and returns nothing. With a `lobe_deg`, the beam is a lobe rather than a
//! uniform cone, as a real transducer's sensitivity falls off away from its axis: a ray `theta`
//! off the axis reaches only `max_range exp(-(theta / lobe_deg)^2)`, so the beam is wide for near
//! surfaces and narrow for far ones. The echo is the nearest return, plus Gaussian noise of
//! `noise_sd`, clamped to `[min_range, max_range]`. With a `dropout`, that fraction of readings
//! is lost at random, as a real sonar misses echoes: the reading is `max_range`, as if nothing
//! echoed.

use streams::Stream;

use crate::error::{check_count, check_finite, check_range, Error};
use crate::pose::Pose;
use crate::world::World;

/// The default `d0` of [`input`]: 0.5 m.
pub const DEFAULT_D0: f64 = 0.5;

/// One sonar's mounting and physics. `Default` is the paper's left-side sonar.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SonarSpec {
    /// The sonar's axis relative to the heading, in degrees, counter-clockwise positive. Default 90
    /// (out of the robot's left side). Any finite value.
    pub mount_angle_deg: f64,
    /// The distance from the robot's centre to the transducer, in metres, >= 0. Default 0.265 (the
    /// default robot's radius: on its rim).
    pub mount_offset: f64,
    /// The full opening angle of the cone in degrees, in (0, 180). Default 25.
    pub cone_deg: f64,
    /// How many rays sample the cone, >= 1, spread evenly from edge to edge (one ray: the axis
    /// only). Default 7.
    pub rays: u32,
    /// The shortest range reported, in metres, >= 0. Default 0.15.
    pub min_range: f64,
    /// The longest range, reported when nothing echoes, in metres, > `min_range`. Default 6.5.
    pub max_range: f64,
    /// The standard deviation of Gaussian noise added to a range, in metres, >= 0. Default 0
    /// (no noise, and no random draws).
    pub noise_sd: f64,
    /// When set, a ray whose angle of incidence exceeds this many degrees, in [0, 90], is lost to
    /// a specular reflection. Default `None` (every ray that hits echoes).
    pub specular_max_incidence_deg: Option<f64>,
    /// When set, the beam's lobe width in degrees, > 0: a ray `theta` off the axis reaches only
    /// `max_range exp(-(theta / lobe_deg)^2)` (see the [module docs](self)). Default `None` (a
    /// uniform cone: every ray reaches `max_range`).
    pub lobe_deg: Option<f64>,
    /// The probability, in [0, 1), that a reading is lost (reads `max_range`, no point) whatever
    /// echoed. Default 0 (no losses, and no random draws).
    pub dropout: f64,
}

impl Default for SonarSpec {
    fn default() -> Self {
        SonarSpec {
            mount_angle_deg: 90.0,
            mount_offset: 0.265,
            cone_deg: 25.0,
            rays: 7,
            min_range: 0.15,
            max_range: 6.5,
            noise_sd: 0.0,
            specular_max_incidence_deg: None,
            lobe_deg: None,
            dropout: 0.0,
        }
    }
}

impl SonarSpec {
    /// Checks every field; the error names the first bad one (as `sonar.<field>`).
    pub fn validate(&self) -> Result<(), Error> {
        self.validate_as("sonar")
    }

    /// [`SonarSpec::validate`], naming fields `<name>.<field>`.
    pub(crate) fn validate_as(&self, name: &str) -> Result<(), Error> {
        let inf = f64::INFINITY;
        let f = |field: &str| format!("{name}.{field}");
        check_finite(&f("mount_angle_deg"), self.mount_angle_deg)?;
        check_range(&f("mount_offset"), self.mount_offset, 0.0, true, inf, false)?;
        check_range(&f("cone_deg"), self.cone_deg, 0.0, false, 180.0, false)?;
        check_count(&f("rays"), u64::from(self.rays), 1)?;
        check_range(&f("min_range"), self.min_range, 0.0, true, inf, false)?;
        if !(self.max_range.is_finite() && self.max_range > self.min_range) {
            return Err(Error::invalid(
                f("max_range"),
                self.max_range,
                &format!("a finite number > min_range ({})", self.min_range),
            ));
        }
        check_range(&f("noise_sd"), self.noise_sd, 0.0, true, inf, false)?;
        if let Some(a) = self.specular_max_incidence_deg {
            check_range(&f("specular_max_incidence_deg"), a, 0.0, true, 90.0, true)?;
        }
        if let Some(w) = self.lobe_deg {
            // In radians it must stay above 0 too (a subnormal width would blind the sonar).
            check_range(&f("lobe_deg"), w, 0.0, false, inf, false)?;
            if w.to_radians() <= 0.0 {
                return Err(Error::invalid(
                    f("lobe_deg"),
                    w,
                    "a positive number, also in radians",
                ));
            }
        }
        check_range(&f("dropout"), self.dropout, 0.0, true, 1.0, false)?;
        Ok(())
    }
}

/// What one sonar reading returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Echo {
    /// The range in metres, in `[min_range, max_range]`; `max_range` when nothing echoed.
    pub range: f64,
    /// Where the echoing ray hit (before noise), or `None` when nothing echoed.
    pub point: Option<[f64; 2]>,
}

impl Default for Echo {
    /// A placeholder for buffers: range 0, no point.
    fn default() -> Self {
        Echo {
            range: 0.0,
            point: None,
        }
    }
}

/// A validated sonar, ready to read.
///
/// # Example
/// ```
/// use streams::{Purpose, Stream};
/// use sim2d::{Pose, Sonar, SonarSpec, World, WorldSpec};
/// let world = World::new(&WorldSpec::landmark(1)?)?;
/// let sonar = Sonar::new(&SonarSpec::default())?;
/// let mut stream = Stream::new(0, 0, Purpose::Trial, 0, 0);
/// // Heading +x at (3, 1): the left sonar looks +y at the landmark's bottom face y = 2.2,
/// // 2.2 - 1 - 0.265 = 0.935 m from the transducer on the rim.
/// let echo = sonar.read(&world, &Pose::new(3.0, 1.0, 0.0), &mut stream);
/// assert!((echo.range - 0.935).abs() < 1e-5);
/// assert!((sim2d::input(echo.range, sim2d::DEFAULT_D0) - 0.5 / 0.935).abs() < 1e-5);
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Sonar {
    spec: SonarSpec,
    /// The angle of the first ray relative to the axis, radians.
    first_ray: f64,
    /// The angle between neighbouring rays, radians.
    ray_step: f64,
    /// The cosine of the steepest incidence that still echoes (-1: no specular misses).
    min_cos_incidence: f64,
    /// The lobe width in radians (`None`: a uniform cone).
    lobe: Option<f64>,
}

impl Sonar {
    /// Validates `spec` and prepares the ray angles.
    pub fn new(spec: &SonarSpec) -> Result<Sonar, Error> {
        spec.validate()?;
        Ok(Self::new_unchecked(spec))
    }

    /// Prepares a sonar whose spec was validated.
    pub(crate) fn new_unchecked(spec: &SonarSpec) -> Sonar {
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
        Sonar {
            spec: spec.clone(),
            first_ray,
            ray_step,
            min_cos_incidence,
            lobe: spec.lobe_deg.map(f64::to_radians),
        }
    }

    /// The sonar's spec.
    pub fn spec(&self) -> &SonarSpec {
        &self.spec
    }

    /// Where the transducer is for a robot at `pose`.
    pub fn mount_point(&self, pose: &Pose) -> [f64; 2] {
        let [dx, dy] = pose.direction_at(self.spec.mount_angle_deg.to_radians());
        [
            pose.x + self.spec.mount_offset * dx,
            pose.y + self.spec.mount_offset * dy,
        ]
    }

    /// One reading for a robot at `pose`: the nearest echo over the cone's rays (see the
    /// [module docs](self)).
    ///
    /// Draws one normal variate from `stream` only when `noise_sd > 0` and something echoed, then
    /// one uniform variate only when `dropout > 0`; otherwise draws nothing. Allocates nothing.
    pub fn read(&self, world: &World, pose: &Pose, stream: &mut Stream) -> Echo {
        let s = &self.spec;
        let origin = self.mount_point(pose);
        let axis = s.mount_angle_deg.to_radians();
        let mut nearest: Option<(f64, [f64; 2])> = None;
        for i in 0..s.rays {
            let dir = pose.direction_at(axis + self.first_ray + self.ray_step * i as f64);
            let ray_range = match self.lobe {
                None => s.max_range,
                Some(w) => {
                    // The ray's angle from the axis (the direction above adds it to the axis in
                    // the order the sonar always has, so a sonar without a lobe keeps its bits).
                    let off_axis = self.first_ray + self.ray_step * i as f64;
                    s.max_range * (-(off_axis / w).powi(2)).exp()
                }
            };
            let reach = nearest.map_or(ray_range, |(d, _)| d.min(ray_range));
            let Some(hit) = world.cast_ray(origin, dir, reach) else {
                continue;
            };
            // cos(incidence) = -dir . normal; a ray from inside a surface (distance 0) echoes.
            let cos_inc = -(dir[0] * hit.normal[0] + dir[1] * hit.normal[1]);
            if hit.distance > 0.0 && cos_inc < self.min_cos_incidence {
                continue;
            }
            if nearest.is_none_or(|(d, _)| hit.distance < d) {
                nearest = Some((hit.distance, hit.point));
            }
        }
        let echo = self.echo(nearest, stream);
        if s.dropout > 0.0 && stream.bernoulli(s.dropout) {
            return Echo {
                range: s.max_range,
                point: None,
            };
        }
        echo
    }

    /// The reading for the nearest return (with its noise).
    fn echo(&self, nearest: Option<(f64, [f64; 2])>, stream: &mut Stream) -> Echo {
        let s = &self.spec;
        match nearest {
            None => Echo {
                range: s.max_range,
                point: None,
            },
            Some((d, point)) => {
                let noisy = if s.noise_sd > 0.0 {
                    d + s.noise_sd * stream.normal()
                } else {
                    d
                };
                Echo {
                    range: noisy.clamp(s.min_range, s.max_range),
                    point: Some(point),
                }
            }
        }
    }
}

/// The network's sonar input: `min(1, d0 / range)`, inversely proportional to the range beyond
/// `d0` (default [`DEFAULT_D0`] = 0.5 m) and 1 closer than that (also for `range <= 0`).
///
/// # Example
/// ```
/// assert_eq!(sim2d::input(0.25, 0.5), 1.0);
/// assert_eq!(sim2d::input(2.0, 0.5), 0.25);
/// ```
pub fn input(range: f64, d0: f64) -> f64 {
    if range <= d0 {
        1.0
    } else {
        d0 / range
    }
}
