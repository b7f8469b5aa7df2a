//! The description of a world: the room, its boxes and the robot's start region, read from TOML.
//!
//! A world file looks like this (lengths in metres; the room spans `[0, width] x [0, height]`):
//!
//! ```toml
//! room = [6.0, 5.0]
//!
//! [start]
//! min = [0.4, 0.4]
//! max = [5.6, 4.6]
//!
//! [[boxes]]
//! center = [3.0, 2.5]
//! size = [1.2, 0.6]
//! angle_deg = 0.0
//! ```
//!
//! The two worlds of the landmark-recognition experiment ship with the crate
//! (`crates/sim2d/worlds/landmark1.toml` and `landmark2.toml`) and are returned by
//! [`WorldSpec::landmark`].

use serde::{Deserialize, Serialize};
use streams::Stream;

use crate::error::{check_finite, check_range, Error};

/// The longest side of a room, in metres. The geometry is computed in `f32` (parry2d), whose
/// steps are about 6e-5 m at 1000 m: in a larger room a robot's step of a few millimetres is
/// lost to rounding and it stands still without a word.
pub const MAX_ROOM: f64 = 1000.0;

/// The shipped world of landmark 1: two crates pushed together.
const LANDMARK1_TOML: &str = include_str!("../worlds/landmark1.toml");
/// The shipped world of landmark 2: the same two crates one crate width apart.
const LANDMARK2_TOML: &str = include_str!("../worlds/landmark2.toml");

/// A rectangular room with boxes in it, and where the robot may start.
///
/// `Default` is landmark 1 ([`WorldSpec::landmark`]`(1)`).
///
/// # Example
/// ```
/// use sim2d::WorldSpec;
/// let spec = WorldSpec::from_toml_str(
///     "room = [4.0, 3.0]\n\
///      start = { min = [0.5, 0.5], max = [3.5, 2.5] }\n\
///      [[boxes]]\n\
///      center = [2.0, 1.5]\n\
///      size = [0.6, 0.6]\n",
/// )?;
/// assert_eq!(spec.boxes[0].angle_deg, 0.0);
/// assert!(WorldSpec::from_toml_str("room = [-4.0, 3.0]\nstart = { min = [0, 0], max = [1, 1] }")
///     .unwrap_err()
///     .to_string()
///     .contains("room[0] is -4"));
/// # Ok::<(), sim2d::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// The room's `[width, height]` in metres; the room spans `[0, width] x [0, height]`, walled on
    /// all four sides. Both must be > 0 and at most [`MAX_ROOM`]. Default `[6, 5]`.
    #[serde(deserialize_with = "pair")]
    pub room: [f64; 2],
    /// The boxes standing in the room, each wholly inside it (boxes may touch or overlap each
    /// other). Default: landmark 1's one 1.2 m x 0.6 m box at the centre; empty when left out of a
    /// file.
    #[serde(default)]
    pub boxes: Vec<BoxSpec>,
    /// Where the robot may start. Default `min = [0.4, 0.4]`, `max = [5.6, 4.6]`.
    pub start: StartRegion,
}

/// One box (a crate): a rectangle of `size` centred at `center`, turned by `angle_deg`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// The box's centre `[x, y]` in metres (no default in a file).
    #[serde(deserialize_with = "pair")]
    pub center: [f64; 2],
    /// The box's side lengths `[sx, sy]` in metres before turning, both > 0 (no default in a file).
    #[serde(deserialize_with = "pair")]
    pub size: [f64; 2],
    /// The box's rotation in degrees, counter-clockwise, in [-360, 360] (default 0).
    #[serde(default)]
    pub angle_deg: f64,
}

/// The axis-aligned rectangle `[min, max]` in which a random start position is drawn.
///
/// A start position is drawn uniformly in the rectangle and redrawn while the robot there would
/// touch a wall or a box (see [`World::random_pose`](crate::World::random_pose)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartRegion {
    /// The lower-left corner `[x, y]` in metres, inside the room (landmark default `[0.4, 0.4]`).
    #[serde(deserialize_with = "pair")]
    pub min: [f64; 2],
    /// The upper-right corner `[x, y]` in metres, inside the room and `>= min` (landmark default
    /// `[5.6, 4.6]`).
    #[serde(deserialize_with = "pair")]
    pub max: [f64; 2],
}

impl Default for WorldSpec {
    fn default() -> Self {
        // The shipped file is checked by the tests, so this parse cannot fail.
        parse(LANDMARK1_TOML).expect("landmark1.toml is a valid world")
    }
}

/// A `[x, y]` of exactly two numbers. (The TOML reader fills a `[f64; 2]` from the first two
/// numbers of a longer array and drops the rest, so a world file's `room = [5, 4, 3]` would be
/// read as `[5, 4]` without a word.)
fn pair<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    let numbers = Vec::<f64>::deserialize(d)?;
    <[f64; 2]>::try_from(numbers.as_slice()).map_err(|_| {
        serde::de::Error::invalid_length(numbers.len(), &"an array of 2 numbers, [x, y]")
    })
}

/// Parses and validates a world file.
fn parse(text: &str) -> Result<WorldSpec, Error> {
    let de = toml::Deserializer::parse(text).map_err(|e| toml_error(text, "", &e))?;
    let spec: WorldSpec = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        toml_error(text, &path, e.inner())
    })?;
    spec.validate()?;
    Ok(spec)
}

/// A one-line message for a TOML error: the line, the field's path and what was wrong.
fn toml_error(text: &str, path: &str, e: &toml::de::Error) -> Error {
    let mut msg = String::new();
    if let Some(span) = e.span() {
        let line = 1 + text[..span.start.min(text.len())].matches('\n').count();
        msg.push_str(&format!("line {line}: "));
    }
    if !path.is_empty() && path != "." {
        msg.push_str(&format!("{path}: "));
    }
    msg.push_str(e.message().trim());
    Error::Toml(msg.replace('\n', " "))
}

impl WorldSpec {
    /// Reads a world from TOML text and validates it.
    ///
    /// Unknown fields are errors; messages give the line and the field, for example
    /// `world file: line 1: unknown field `rooms`, expected one of `room`, `boxes`, `start``.
    pub fn from_toml_str(text: &str) -> Result<WorldSpec, Error> {
        parse(text)
    }

    /// The world as TOML text that [`WorldSpec::from_toml_str`] reads back unchanged.
    pub fn to_toml_string(&self) -> Result<String, Error> {
        toml::to_string(self).map_err(|e| Error::Toml(e.to_string().replace('\n', " ")))
    }

    /// A shipped world of the landmark-recognition experiment: `1` for two crates pushed together
    /// (a 1.2 m x 0.6 m rectangle), `2` for the same crates one crate width (0.6 m) apart. Both
    /// stand at the centre of a 6 m x 5 m room.
    ///
    /// # Example
    /// ```
    /// let w2 = sim2d::WorldSpec::landmark(2)?;
    /// assert_eq!(w2.room, [6.0, 5.0]);
    /// assert_eq!(w2.boxes.len(), 2);
    /// assert!(sim2d::WorldSpec::landmark(3).is_err());
    /// # Ok::<(), sim2d::Error>(())
    /// ```
    pub fn landmark(n: u32) -> Result<WorldSpec, Error> {
        match n {
            1 => parse(LANDMARK1_TOML),
            2 => parse(LANDMARK2_TOML),
            _ => Err(Error::invalid("landmark", n, "1 or 2")),
        }
    }

    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<(), Error> {
        for (k, &v) in self.room.iter().enumerate() {
            check_range(&format!("room[{k}]"), v, 0.0, false, MAX_ROOM, true)?;
        }
        let [w, h] = self.room;
        for (i, b) in self.boxes.iter().enumerate() {
            for k in 0..2 {
                check_finite(&format!("boxes[{i}].center[{k}]"), b.center[k])?;
                check_range(
                    &format!("boxes[{i}].size[{k}]"),
                    b.size[k],
                    0.0,
                    false,
                    f64::INFINITY,
                    false,
                )?;
            }
            check_range(
                &format!("boxes[{i}].angle_deg"),
                b.angle_deg,
                -360.0,
                true,
                360.0,
                true,
            )?;
            let [ex, ey] = b.aabb_half_extents();
            let tol = 1e-9 * (w + h);
            let inside = b.center[0] - ex >= -tol
                && b.center[0] + ex <= w + tol
                && b.center[1] - ey >= -tol
                && b.center[1] + ey <= h + tol;
            if !inside {
                return Err(Error::invalid(
                    format!("boxes[{i}]"),
                    format!(
                        "centre {:?}, size {:?}, angle_deg {}",
                        b.center, b.size, b.angle_deg
                    ),
                    &format!("wholly inside the room [0, {w}] x [0, {h}]"),
                ));
            }
        }
        for k in 0..2 {
            let size = self.room[k];
            let lo = self.start.min[k];
            check_range(&format!("start.min[{k}]"), lo, 0.0, true, size, true)?;
            let hi = self.start.max[k];
            if !(hi.is_finite() && hi >= lo && hi <= size) {
                return Err(Error::invalid(
                    format!("start.max[{k}]"),
                    hi,
                    &format!("in [start.min[{k}], room[{k}]] = [{lo}, {size}]"),
                ));
            }
        }
        Ok(())
    }

    /// A randomly perturbed copy of this world, for testing that a behaviour does not depend on
    /// exact geometry.
    ///
    /// - The room's width and height are each scaled by their own factor `1 + u`, `u` uniform in
    ///   `[-room_scale_frac, room_scale_frac)`; box centres and the start region scale with them, so
    ///   the landmark stays where it was relative to the room. Box sizes do not scale.
    /// - Then each box's centre moves by an offset uniform in `[-box_shift_m, box_shift_m)` on each
    ///   axis, clamped so that the box stays inside the room.
    ///
    /// Draws, in this order: the width factor, the height factor, then x and y of each box's offset.
    /// `box_shift_m` must be finite and >= 0, `room_scale_frac` in `[0, 0.5)`. Returns an error if
    /// this world or the result is invalid (a box larger than the shrunken room).
    ///
    /// # Example
    /// ```
    /// use streams::{Purpose, Stream};
    /// let base = sim2d::WorldSpec::landmark(2)?;
    /// let mut s = Stream::new(1, 0, Purpose::Trial, 0, 0);
    /// let j = base.jittered(&mut s, 0.05, 0.1)?;
    /// assert!((j.room[0] - 6.0).abs() <= 0.6 && (j.room[1] - 5.0).abs() <= 0.5);
    /// assert_eq!(j.boxes[0].size, [0.6, 0.6]);
    /// # Ok::<(), sim2d::Error>(())
    /// ```
    pub fn jittered(
        &self,
        stream: &mut Stream,
        box_shift_m: f64,
        room_scale_frac: f64,
    ) -> Result<WorldSpec, Error> {
        self.validate()?;
        check_range("box_shift_m", box_shift_m, 0.0, true, f64::INFINITY, false)?;
        check_range("room_scale_frac", room_scale_frac, 0.0, true, 0.5, false)?;
        let scale = [
            1.0 + stream.range(-room_scale_frac, room_scale_frac),
            1.0 + stream.range(-room_scale_frac, room_scale_frac),
        ];
        let mut out = self.scaled(scale);
        let room = out.room;
        for b in &mut out.boxes {
            let half = b.aabb_half_extents();
            for k in 0..2 {
                let c = b.center[k] + stream.range(-box_shift_m, box_shift_m);
                // Clamp into [half, room - half]; if the box no longer fits, validate() says so.
                b.center[k] = c.min(room[k] - half[k]).max(half[k]);
            }
        }
        out.validate()?;
        Ok(out)
    }

    /// This world with the room, the boxes' centres and the start region scaled by `scale[0]` in
    /// x and `scale[1]` in y; the boxes keep their sizes and turns. Not validated.
    ///
    /// # Example
    /// ```
    /// let w = sim2d::WorldSpec::landmark(1)?.scaled([1.5, 0.8]);
    /// assert_eq!((w.room, w.boxes[0].center, w.boxes[0].size), ([9.0, 4.0], [4.5, 2.0], [1.2, 0.6]));
    /// # Ok::<(), sim2d::Error>(())
    /// ```
    pub fn scaled(&self, scale: [f64; 2]) -> WorldSpec {
        let at = |p: [f64; 2]| [p[0] * scale[0], p[1] * scale[1]];
        WorldSpec {
            room: at(self.room),
            boxes: self
                .boxes
                .iter()
                .map(|b| BoxSpec {
                    center: at(b.center),
                    ..b.clone()
                })
                .collect(),
            start: StartRegion {
                min: at(self.start.min),
                max: at(self.start.max),
            },
        }
    }
}

impl BoxSpec {
    /// Half the width and height of the box's axis-aligned bounding box, after turning.
    pub fn aabb_half_extents(&self) -> [f64; 2] {
        let (s, c) = self.angle_deg.to_radians().sin_cos();
        let (a, b) = (0.5 * self.size[0], 0.5 * self.size[1]);
        [c.abs() * a + s.abs() * b, s.abs() * a + c.abs() * b]
    }
}
