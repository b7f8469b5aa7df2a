//! Varied training: a Jakobi-style minimal simulation for the landmark task.
//!
//! The ideal simulator is exact in ways the real robot is not: the landmark always stands at the
//! same spot, the robot always drives at the same speed the same distance from the wall, the
//! sonar always has the same beam, and its reading always maps to the same input. An evolved
//! network can use any of these as a cue (the exact height of a bump, the exact time between two
//! bumps), and then fails on a robot. [`Training`] varies, trial by trial, what a network must
//! *not* rely on, so that only the cue that tells the landmarks apart on any robot is left: the
//! shape of the sonar's time course as the robot passes a landmark. (With the default 25-degree
//! beam the gap between landmark 2's crates hardly shows; what shows is landmark 2's greater
//! extent, whose ends come nearer the walls: `docs/landmark.md`.)
//!
//! The variations of `landmark-robust` were chosen to differ in kind from the robot-like *test*
//! ([`RobotLike`](super::RobotLike): Gaussian range noise, specular misses, each box shifted on
//! its own, the room scaled), so that passing the test measures transfer to conditions training
//! never saw. `docs/worlds.md` gives the argument for each element. `room_scale`, added later for
//! the wider `landmark-wide`, scales the room as that test does, so for training that uses it the
//! robot-like test is not a transfer test.
//!
//! # One varied trial
//! Trial `t` of a generation keeps its own stream `Stream::new(seed, generation, Purpose::Trial,
//! 0, t)` for the start pose, exactly as an unvaried trial, and draws its variation from a second
//! stream, `Stream::new(seed, generation, Purpose::Trial, 1, t)`, in this order: the landmark's
//! shift in x and y, its turn, its scale, the follower's speed factor and distance offset, the
//! sonar's cone offset, the trial-length offset, the input's gain and offset, then one normal
//! variate per step for the input noise (only when `input_noise_sd > 0`). The variations added
//! later draw from a third stream, `Stream::new(seed, generation, Purpose::Trial, 2, t)`, so that
//! they leave the first two streams' draws as they were: the room's scale in x and in y, then the
//! sonar's axis offset. Every draw is made even when its range is 0, so changing one range never
//! moves another's draws.
//!
//! # Validation
//! A champion chosen on the ideal world alone can be one that relies on exactly what training
//! varies. So when training varies, the validation set ([`Task::validate`](ctrnn::Task)) holds
//! `validation_trials` varied trials per landmark besides the ideal ones, drawn as above from
//! `Purpose::Validate`'s streams at generation 0 instead of `Purpose::Trial`'s.

use ctrnn::{Error, Result, Stream};
use serde::{Deserialize, Serialize};
use sim2d::{BoxSpec, WorldSpec};

/// How the training trials vary (all ranges default to 0: no variation, the paper's training).
///
/// Each trial draws its own values, each uniform over its range. The test trials
/// ([`LandmarkTask::assess`](crate::landmark::LandmarkTask::assess)) never vary.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Training {
    /// The first this-many trials of each landmark in a generation stay unvaried (ideal), the
    /// rest vary. At most `trials_per_landmark`. Default 0.
    pub ideal_trials_per_landmark: usize,
    /// The whole landmark (all its boxes together, keeping their layout) moves by up to this much
    /// in x and in y, in metres. Default 0.
    pub landmark_shift: f64,
    /// The whole landmark turns about its centre by up to this many degrees, in [0, 180].
    /// Default 0.
    pub landmark_turn_deg: f64,
    /// The whole landmark (its boxes' sizes and their distances from its centre) scales by a
    /// factor in `1 ± landmark_scale`, in [0, 0.5]. Default 0.
    pub landmark_scale: f64,
    /// The wall follower's speed scales by a factor in `1 ± follower_speed`, in [0, 0.5].
    /// Default 0.
    pub follower_speed: f64,
    /// The wall follower's distance from the wall changes by up to this much, in metres; the
    /// follower must stay valid at both ends. Default 0.
    pub follower_distance: f64,
    /// The network's sonar's cone widens or narrows by up to this many degrees; the cone must
    /// stay in (0, 180) at both ends. Default 0.
    pub cone_deg: f64,
    /// The trial (and so the moment the answer is read) lengthens or shortens by up to this many
    /// seconds, less than `trial_seconds`. Default 0.
    pub trial_seconds: f64,
    /// The input `x` becomes `gain x + offset` (then clipped to [0, 1]), with the gain in
    /// `1 ± input_gain`, in [0, 0.9]. Default 0.
    pub input_gain: f64,
    /// The offset of `input_gain`'s line is in `± input_offset`, in [0, 0.5]. Default 0.
    pub input_offset: f64,
    /// Gaussian noise added to the input itself (not the range) at every step, sd in [0, 1].
    /// Default 0.
    pub input_noise_sd: f64,
    /// The room and its start region scale by a factor in `1 ± room_scale` in x and another in y,
    /// in [0, 0.3], and the landmark, whole (its boxes keep their layout and sizes), keeps its
    /// place relative to the room, before it moves. Drawn from the third stream. Default 0.
    pub room_scale: f64,
    /// The network's sonar's axis turns by up to this many degrees, in [0, 90]. Drawn from the
    /// third stream. Default 0.
    pub sonar_axis_deg: f64,
    /// Every range above is drawn at one of its two ends, each end with probability 1/2, instead
    /// of uniformly over it: each varied trial is a corner of the envelope, where a network that
    /// relies on its middle fails. The draws are the same as without it, each mapped to the end
    /// on its side, so the ideal trials and the input noise are unchanged. Default false.
    pub at_ends: bool,
}

/// One trial's draw of [`Training`]'s variations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Variation {
    pub(super) shift: [f64; 2],
    pub(super) turn_deg: f64,
    pub(super) scale: f64,
    pub(super) speed_factor: f64,
    pub(super) distance_offset: f64,
    pub(super) cone_offset: f64,
    pub(super) seconds_offset: f64,
    pub(super) gain: f64,
    pub(super) offset: f64,
    pub(super) room_scale: [f64; 2],
    pub(super) axis_offset: f64,
}

/// The ranges that move the landmark within its room, named in errors.
const REACH: &str = "training.landmark_shift, landmark_turn_deg, landmark_scale or room_scale";

impl Variation {
    /// No variation at all.
    const NONE: Variation = Variation {
        shift: [0.0; 2],
        turn_deg: 0.0,
        scale: 1.0,
        speed_factor: 1.0,
        distance_offset: 0.0,
        cone_offset: 0.0,
        seconds_offset: 0.0,
        gain: 1.0,
        offset: 0.0,
        room_scale: [1.0; 2],
        axis_offset: 0.0,
    };
}

/// `range(-r, r)`: uniform over `[-r, r)`, and exactly 0 when `r` is 0; with `at_ends`, the end of
/// `[-r, r]` on the draw's side (`-r` below 0, else `r`).
fn symmetric(stream: &mut Stream, r: f64, at_ends: bool) -> f64 {
    let x = stream.range(-r, r);
    match at_ends {
        false => x,
        true if x < 0.0 => -r,
        true => r,
    }
}

impl Training {
    /// Whether every range is 0, so that training is the paper's (no draws, no changes).
    pub fn is_off(&self) -> bool {
        self == &Training {
            ideal_trials_per_landmark: self.ideal_trials_per_landmark,
            at_ends: self.at_ends,
            ..Training::default()
        }
    }

    /// Checks every range on its own; the error names the field (`training.<field>`) and says
    /// what is allowed. How the ranges fit the rest of the config is checked by
    /// [`LandmarkConfig::validate`](super::LandmarkConfig::validate).
    pub fn validate(&self) -> Result<()> {
        let err = |msg: String| Err(Error::Config(format!("training.{msg}")));
        let inf = f64::INFINITY;
        for (name, value, hi) in [
            ("landmark_shift", self.landmark_shift, inf),
            ("landmark_turn_deg", self.landmark_turn_deg, 180.0),
            ("landmark_scale", self.landmark_scale, 0.5),
            ("follower_speed", self.follower_speed, 0.5),
            ("follower_distance", self.follower_distance, inf),
            ("cone_deg", self.cone_deg, inf),
            ("trial_seconds", self.trial_seconds, inf),
            ("input_gain", self.input_gain, 0.9),
            ("input_offset", self.input_offset, 0.5),
            ("input_noise_sd", self.input_noise_sd, 1.0),
            ("room_scale", self.room_scale, 0.3),
            ("sonar_axis_deg", self.sonar_axis_deg, 90.0),
        ] {
            if !(value.is_finite() && (0.0..=hi).contains(&value)) {
                return err(format!("{name} is {value}; it must be in [0, {hi}]"));
            }
        }
        Ok(())
    }

    /// Checks that `world` keeps its landmark inside its room at the ends of the ranges that move
    /// it (each end of the room's scale in x and y, the shift in x and y and the landmark's scale,
    /// and the turn at both ends and none), so that a config whose ranges reach too far fails when
    /// it is read. A turn between its ends can reach further for a long landmark turned by more
    /// than about 25 degrees; a trial that draws such a turn fails with the same error.
    pub(super) fn check_world(&self, world: &WorldSpec) -> Result<()> {
        let ends = |r: f64| [-r, r];
        for sx in ends(self.room_scale) {
            for sy in ends(self.room_scale) {
                for dx in ends(self.landmark_shift) {
                    for dy in ends(self.landmark_shift) {
                        for k in ends(self.landmark_scale) {
                            for turn_deg in [-self.landmark_turn_deg, 0.0, self.landmark_turn_deg] {
                                let v = Variation {
                                    shift: [dx, dy],
                                    turn_deg,
                                    scale: 1.0 + k,
                                    room_scale: [1.0 + sx, 1.0 + sy],
                                    ..Variation::NONE
                                };
                                vary_world(world, &v)?;
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Draws one trial's variation from `stream` and `third` (see the [module docs](self) for the
    /// order).
    pub(crate) fn draw(&self, stream: &mut Stream, third: &mut Stream) -> Variation {
        let shift = [
            symmetric(stream, self.landmark_shift, self.at_ends),
            symmetric(stream, self.landmark_shift, self.at_ends),
        ];
        let turn_deg = symmetric(stream, self.landmark_turn_deg, self.at_ends);
        let scale = 1.0 + symmetric(stream, self.landmark_scale, self.at_ends);
        let speed_factor = 1.0 + symmetric(stream, self.follower_speed, self.at_ends);
        let distance_offset = symmetric(stream, self.follower_distance, self.at_ends);
        let cone_offset = symmetric(stream, self.cone_deg, self.at_ends);
        let seconds_offset = symmetric(stream, self.trial_seconds, self.at_ends);
        let gain = 1.0 + symmetric(stream, self.input_gain, self.at_ends);
        let offset = symmetric(stream, self.input_offset, self.at_ends);
        let room_scale = [
            1.0 + symmetric(third, self.room_scale, self.at_ends),
            1.0 + symmetric(third, self.room_scale, self.at_ends),
        ];
        let axis_offset = symmetric(third, self.sonar_axis_deg, self.at_ends);
        Variation {
            shift,
            turn_deg,
            scale,
            speed_factor,
            distance_offset,
            cone_offset,
            seconds_offset,
            gain,
            offset,
            room_scale,
            axis_offset,
        }
    }
}

/// `world` as one trial of `v` varies it: the room scaled (with its start region), the landmark
/// kept whole at the same place relative to the room, then the landmark moved. An error if a box
/// leaves the room.
pub(super) fn vary_world(world: &WorldSpec, v: &Variation) -> Result<WorldSpec> {
    move_landmark(&scale_room(world, v.room_scale), v)
}

/// `world` with its room and start region scaled by `scale` in x and y, and its landmark (all its
/// boxes, keeping their layout and sizes) moved so that its centre keeps its place relative to
/// the room. (Scaling each box's centre, as the robot-like test's jitter does, would stretch the
/// gap between landmark 2's crates, and so the extent that tells the landmarks apart.)
fn scale_room(world: &WorldSpec, scale: [f64; 2]) -> WorldSpec {
    let Some(centre) = landmark_centre(world) else {
        return world.scaled(scale);
    };
    let shift = [centre[0] * (scale[0] - 1.0), centre[1] * (scale[1] - 1.0)];
    WorldSpec {
        boxes: world
            .boxes
            .iter()
            .map(|b| BoxSpec {
                center: [b.center[0] + shift[0], b.center[1] + shift[1]],
                ..b.clone()
            })
            .collect(),
        ..world.scaled(scale)
    }
}

/// The centre of the landmark: of the bounding box of all of `world`'s boxes (None if it has
/// none).
fn landmark_centre(world: &WorldSpec) -> Option<[f64; 2]> {
    if world.boxes.is_empty() {
        return None;
    }
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for b in &world.boxes {
        let half = b.aabb_half_extents();
        for k in 0..2 {
            lo[k] = lo[k].min(b.center[k] - half[k]);
            hi[k] = hi[k].max(b.center[k] + half[k]);
        }
    }
    Some([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])])
}

/// `world` with its boxes, taken together as one landmark, scaled about the landmark's centre
/// (the centre of the boxes' bounding box), turned about it and moved. An error if a box leaves
/// the room.
fn move_landmark(world: &WorldSpec, v: &Variation) -> Result<WorldSpec> {
    let Some(centre) = landmark_centre(world) else {
        return Ok(world.clone());
    };
    let (s, c) = v.turn_deg.to_radians().sin_cos();
    let boxes = world
        .boxes
        .iter()
        .map(|b| {
            let rel = [
                (b.center[0] - centre[0]) * v.scale,
                (b.center[1] - centre[1]) * v.scale,
            ];
            BoxSpec {
                center: [
                    centre[0] + v.shift[0] + c * rel[0] - s * rel[1],
                    centre[1] + v.shift[1] + s * rel[0] + c * rel[1],
                ],
                size: [b.size[0] * v.scale, b.size[1] * v.scale],
                angle_deg: b.angle_deg + v.turn_deg,
            }
        })
        .collect();
    let out = WorldSpec {
        boxes,
        ..world.clone()
    };
    out.validate().map_err(|e| {
        Error::Config(format!(
            "training moved the landmark out of the room ({REACH} reach too far for this world): {e}"
        ))
    })?;
    Ok(out)
}
