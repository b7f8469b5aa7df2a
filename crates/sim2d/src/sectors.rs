//! The pursuer sensor: how near the nearest pursuer is in each of a few equal sectors around
//! the robot.
//!
//! The circle around the robot is cut into `count` equal sectors; sector `q` is centred
//! `q * 360 / count` degrees counter-clockwise from the heading (sector 0 straight ahead) and
//! spans half a sector's width to either side (a bearing on the border between two sectors
//! belongs to the counter-clockwise one). A sector reads the gap between the robot's edge and
//! the edge of the nearest pursuer whose centre lies in it (the distance between centres minus
//! both radii, at least 0), or `range` when no pursuer is nearer than that.
//!
//! The sensor sees through walls and boxes: think of a scent, or a radio beacon that every
//! pursuer carries, rather than a camera. Pursuers also echo on the sonar ring, which walls do
//! block. This choice keeps the sensor cheap, exact and independent of the room; a task that
//! wants another can compute it from the pursuers' poses, which a [`Fleet`](crate::Fleet)
//! exposes.

use std::f64::consts::TAU;

use crate::error::{check_count, check_range, Error};
use crate::pose::{wrap_angle, Pose};

/// The pursuer sensor's sectors. `Default` is none (the sensor is off).
///
/// # Example
/// ```
/// use sim2d::{Pose, SectorSpec};
/// let sectors = SectorSpec { count: 4, range: 5.0 };
/// let mut out = [0.0; 4];
/// // A pursuer of radius 0.2 three metres to the left of a robot of radius 0.25 facing +x:
/// // sector 1 (centred at 90 degrees) reads 3 - 0.25 - 0.2 = 2.55.
/// sectors.read(&Pose::new(1.0, 1.0, 0.0), 0.25, &[Pose::new(1.0, 4.0, 0.0)], 0.2, &mut out);
/// assert_eq!(out[0], 5.0);
/// assert!((out[1] - 2.55).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SectorSpec {
    /// How many sectors, Q; 0 turns the sensor off. Default 0.
    pub count: u32,
    /// The longest gap reported, in metres, > 0; also the reading of a sector without a
    /// pursuer. Default 6.5.
    pub range: f64,
}

impl Default for SectorSpec {
    fn default() -> Self {
        SectorSpec {
            count: 0,
            range: 6.5,
        }
    }
}

impl SectorSpec {
    /// Checks every field; the error names the first bad one (as `sectors.<field>`).
    pub fn validate(&self) -> Result<(), Error> {
        check_count("sectors.count", u64::from(self.count), 0)?;
        check_range(
            "sectors.range",
            self.range,
            0.0,
            false,
            f64::INFINITY,
            false,
        )
    }

    /// The sector (in `0..count`) of a bearing in radians relative to the heading; 0 when
    /// `count` is 0 or the bearing is not finite.
    pub fn sector(&self, bearing: f64) -> usize {
        if self.count == 0 || !bearing.is_finite() {
            return 0;
        }
        let width = TAU / self.count as f64;
        let k = ((wrap_angle(bearing) + 0.5 * width) / width).floor() as i64;
        k.rem_euclid(self.count as i64) as usize
    }

    /// Reads every sector into `out` (`count` entries; extra ones are left alone) for a robot
    /// of `radius` at `robot` and pursuers of `pursuer_radius` at `pursuers` (see the
    /// [module docs](self)). Allocates nothing.
    pub fn read(
        &self,
        robot: &Pose,
        radius: f64,
        pursuers: &[Pose],
        pursuer_radius: f64,
        out: &mut [f64],
    ) {
        let n = (self.count as usize).min(out.len());
        out[..n].fill(self.range);
        if n == 0 {
            return;
        }
        for p in pursuers {
            let (dx, dy) = (p.x - robot.x, p.y - robot.y);
            let gap = (dx.hypot(dy) - radius - pursuer_radius).max(0.0);
            let q = self.sector(dy.atan2(dx) - robot.heading);
            if q < n && gap < out[q] {
                out[q] = gap;
            }
        }
    }
}
