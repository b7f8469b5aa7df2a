//! A Polaroid-like sonar: a cone of rays, the nearest echo, optional range noise and specular
//! misses, and the network's input derived from the range.
//!
//! A sonar is mounted on the robot's rim at `mount_angle_deg` from the heading. Its cone of
//! `cone_deg` is sampled by `rays` rays spread evenly over it (one ray points along the axis).
//! Each ray is cast from the mount point; a ray that meets a surface at an angle of incidence
//! (between the reversed ray and the surface normal) above `specular_max_incidence_deg` is
//! reflected away and returns nothing. The echo is the nearest return, plus Gaussian noise of
//! `noise_sd`, clamped to `[min_range, max_range]`.

use streams::Stream;

use crate::error::{check_finite, check_range, Error};
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
        if self.rays == 0 {
            return Err(Error::invalid(f("rays"), 0, ">= 1"));
        }
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
    /// Draws one normal variate from `stream` only when `noise_sd > 0` and something echoed;
    /// otherwise draws nothing. Allocates nothing.
    pub fn read(&self, world: &World, pose: &Pose, stream: &mut Stream) -> Echo {
        let s = &self.spec;
        let origin = self.mount_point(pose);
        let axis = s.mount_angle_deg.to_radians();
        let mut nearest: Option<(f64, [f64; 2])> = None;
        for i in 0..s.rays {
            let dir = pose.direction_at(axis + self.first_ray + self.ray_step * i as f64);
            let reach = nearest.map_or(s.max_range, |(d, _)| d);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world_spec::{BoxSpec, StartRegion, WorldSpec};
    use streams::Purpose;

    const TOL: f64 = 2e-5;

    /// A 10 x 8 room with the given boxes.
    fn world(boxes: Vec<BoxSpec>) -> World {
        World::new(&WorldSpec {
            room: [10.0, 8.0],
            boxes,
            start: StartRegion {
                min: [0.5, 0.5],
                max: [9.5, 7.5],
            },
        })
        .unwrap()
    }

    /// A forward-looking sonar on the robot's centre, with the given cone and rays.
    fn forward(cone_deg: f64, rays: u32) -> SonarSpec {
        SonarSpec {
            mount_angle_deg: 0.0,
            mount_offset: 0.0,
            cone_deg,
            rays,
            max_range: 20.0,
            ..SonarSpec::default()
        }
    }

    fn stream() -> Stream {
        Stream::new(5, 0, Purpose::Trial, 0, 0)
    }

    #[test]
    fn an_off_axis_ray_finds_the_nearer_box() {
        // Looking +x from (1, 4): the axis meets the right wall 9 m away. A small box with faces
        // x in [3.9, 4.1], y in [4.4, 4.6] lies off the axis. The 7 rays are 25 / 6 = 4.1667 deg
        // apart. At x = 3.9 (2.9 m ahead) the ray at +4.1667 deg is at y = 4 + 2.9 tan = 4.211
        // (below the box, and 4.226 at x = 4.1: a miss); the ray at +8.3333 deg is at y = 4.4248,
        // on the face, at distance 2.9 / cos(8.3333 deg) = 2.93094; the ray at +12.5 deg is at
        // y = 4.643 (above the box; it crossed y = 4.6 at x = 3.706, before the box).
        let w = world(vec![BoxSpec {
            center: [4.0, 4.5],
            size: [0.2, 0.2],
            angle_deg: 0.0,
        }]);
        let pose = Pose::new(1.0, 4.0, 0.0);
        let axis_only = Sonar::new(&forward(25.0, 1)).unwrap();
        let e = axis_only.read(&w, &pose, &mut stream());
        assert!((e.range - 9.0).abs() < TOL, "{e:?}");
        let cone = Sonar::new(&forward(25.0, 7)).unwrap();
        let e = cone.read(&w, &pose, &mut stream());
        let expected = 2.9 / (25.0f64 / 6.0 * 2.0).to_radians().cos();
        assert!((e.range - expected).abs() < TOL, "{e:?} vs {expected}");
        let [px, py] = e.point.unwrap();
        assert!((px - 3.9).abs() < TOL && (4.4..=4.6).contains(&py));
    }

    #[test]
    fn nothing_in_range_gives_max_range_and_no_point() {
        let w = world(vec![]);
        let spec = SonarSpec {
            max_range: 5.0,
            ..forward(25.0, 7)
        };
        let e = Sonar::new(&spec)
            .unwrap()
            .read(&w, &Pose::new(1.0, 4.0, 0.0), &mut stream());
        assert_eq!(
            e,
            Echo {
                range: 5.0,
                point: None
            }
        );
    }

    #[test]
    fn near_echoes_clamp_to_min_range() {
        let w = world(vec![]);
        let s = Sonar::new(&forward(10.0, 3)).unwrap();
        // 0.05 m from the right wall.
        let e = s.read(&w, &Pose::new(9.95, 4.0, 0.0), &mut stream());
        assert_eq!(e.range, 0.15);
        assert!(e.point.is_some());
    }

    #[test]
    fn zero_noise_draws_nothing_and_noise_is_reproducible() {
        let w = world(vec![]);
        let pose = Pose::new(1.0, 4.0, 0.3);
        let quiet = Sonar::new(&forward(25.0, 7)).unwrap();
        let mut s = stream();
        let e = quiet.read(&w, &pose, &mut s);
        assert_eq!(s, stream(), "no draws with noise_sd = 0");
        let noisy = Sonar::new(&SonarSpec {
            noise_sd: 0.0,
            ..forward(25.0, 7)
        })
        .unwrap();
        assert_eq!(noisy.read(&w, &pose, &mut stream()), e);
        let noisy = Sonar::new(&SonarSpec {
            noise_sd: 0.05,
            ..forward(25.0, 7)
        })
        .unwrap();
        let run = |seed| {
            let mut s = Stream::new(seed, 0, Purpose::Trial, 0, 0);
            (0..50)
                .map(|k| noisy.read(&w, &Pose::new(1.0, 4.0, 0.01 * k as f64), &mut s))
                .collect::<Vec<_>>()
        };
        let a = run(11);
        assert_eq!(a, run(11));
        assert_ne!(a, run(12));
        let mean_err: f64 = a
            .iter()
            .zip(0..)
            .map(|(e, k)| {
                e.range
                    - quiet
                        .read(&w, &Pose::new(1.0, 4.0, 0.01 * k as f64), &mut stream())
                        .range
            })
            .sum::<f64>()
            / 50.0;
        assert!(mean_err.abs() < 0.03, "{mean_err}");
        assert!(a.iter().any(|e| e.range != a[0].range));
    }

    #[test]
    fn steep_incidence_loses_the_echo() {
        let w = world(vec![]);
        // One ray at 60 degrees of incidence to the right wall: from (9, 4) heading 60 deg from +x
        // the ray meets... the top wall y = 8 at incidence 30 deg (normal (0, -1)) after 4 / sin 60
        // = 4.6188 m, or the right wall x = 10 at incidence 60 deg after 1 / cos 60 = 2 m. It hits
        // the right wall first.
        let pose = Pose::new(9.0, 4.0, 60f64.to_radians());
        let spec = forward(25.0, 1);
        let e = Sonar::new(&spec).unwrap().read(&w, &pose, &mut stream());
        assert!((e.range - 2.0).abs() < TOL, "{e:?}");
        let lossy = SonarSpec {
            specular_max_incidence_deg: Some(45.0),
            ..spec.clone()
        };
        let e = Sonar::new(&lossy).unwrap().read(&w, &pose, &mut stream());
        assert_eq!(e.range, 20.0);
        assert_eq!(e.point, None);
        // Within the limit it echoes as before.
        let lenient = SonarSpec {
            specular_max_incidence_deg: Some(61.0),
            ..spec
        };
        let e = Sonar::new(&lenient).unwrap().read(&w, &pose, &mut stream());
        assert!((e.range - 2.0).abs() < TOL);
    }

    #[test]
    fn mount_geometry_and_validation() {
        let s = Sonar::new(&SonarSpec::default()).unwrap();
        let p = s.mount_point(&Pose::new(1.0, 1.0, 0.0));
        assert!((p[0] - 1.0).abs() < 1e-12 && (p[1] - 1.265).abs() < 1e-12);
        let bad = SonarSpec {
            cone_deg: -3.0,
            ..SonarSpec::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "sonar.cone_deg is -3; it must be in (0, 180)"
        );
        let bad = SonarSpec {
            rays: 0,
            ..SonarSpec::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "sonar.rays is 0; it must be >= 1"
        );
        let bad = SonarSpec {
            max_range: 0.1,
            ..SonarSpec::default()
        };
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("sonar.max_range is 0.1"));
        assert_eq!(input(0.5, 0.5), 1.0);
        assert_eq!(input(0.0, 0.5), 1.0);
        assert_eq!(input(6.5, 0.5), 0.5 / 6.5);
    }
}
