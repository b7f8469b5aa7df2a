//! The line world and its trial loop: where the goal and the landmark are, what the sensors read,
//! how the agent moves, and when a trial ends.
//!
//! # One update of the world
//! The world is updated once per *tick*: in the continuous world (the default, see
//! [`World`](super::World)) a tick is one integration step of `dt` (one Euler step, or one RK4
//! step), `substeps` of them to a time step; in the stepped world a tick is a whole time step.
//! With `tick_time` the simulated time of a tick (`dt`, or `dt * substeps`):
//! 1. The sensors are read at the agent's position `x`: input 0 is 1 while the agent is on the
//!    landmark (`|x - landmark| <= landmark_width / 2`), else 0; input 1 (the reinforcement, if
//!    the network has it) is 0 while the agent moves.
//! 2. The network integrates the tick with these inputs held.
//! 3. The agent moves: `x += tick_time * (f(v_R) - f(v_L))`, with the firing rates after the
//!    tick. In the continuous world this is a forward Euler step of `dx/dt = f(v_R) - f(v_L)`
//!    taken together with the network's; with RK4 the network takes one RK4 step with the inputs
//!    held and the agent then the same Euler step, so `x` stays first-order accurate in `dt`.
//! 4. The trial ends when `x >= half_length` or `x <= -half_length` (the agent reached that end),
//!    or after `max_steps` time steps (`max_steps * substeps` ticks in the continuous world). The
//!    goal is reached when the end is the goal's.
//!
//! After the trial, the network runs `reinforcement_steps` more time steps (as many ticks as that
//! takes) with the landmark input 0 and the reinforcement input 1 if the goal was reached, 0
//! otherwise. The classifier's output `f(v_C)` at the end of that period is the trial's
//! classification. The next trial of a chain starts at its own start position, from the state the
//! last one left.

use ctrnn::{Elem, Integrator, Lanes, Stream};
use serde::{Deserialize, Serialize};

use super::config::Nav1dConfig;
use super::environment::Environment;
use crate::common::Diverged;

/// One end of the line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// The end at `-half_length`.
    Left,
    /// The end at `+half_length`.
    Right,
}

impl Side {
    /// -1 for left, +1 for right.
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => -1.0,
            Side::Right => 1.0,
        }
    }

    /// The other side.
    pub fn opposite(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

/// Everything that defines one trial's world.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Condition {
    /// The environment type.
    pub environment: Environment,
    /// The goal's end.
    pub goal: Side,
    /// The agent's start position.
    pub start: f64,
    /// The landmark's centre.
    pub landmark: f64,
}

impl Condition {
    /// The trial with the config's exact geometry: start at `start`, the landmark centred at
    /// `landmark_offset` on the goal's side (near) or the other side (far).
    ///
    /// # Example
    /// ```
    /// use tasks::nav1d::{Condition, Environment, Nav1dConfig, Side};
    /// let c = Condition::exact(&Nav1dConfig::default(), Environment::Far, Side::Right);
    /// assert_eq!((c.start, c.landmark), (0.0, -10.0));
    /// ```
    pub fn exact(config: &Nav1dConfig, environment: Environment, goal: Side) -> Condition {
        let landmark_side = match environment {
            Environment::Near => goal,
            Environment::Far => goal.opposite(),
        };
        Condition {
            environment,
            goal,
            start: config.start,
            landmark: landmark_side.sign() * config.landmark_offset,
        }
    }

    /// [`exact`](Self::exact), then the start shifted by `U(-start_jitter, start_jitter)` and the
    /// landmark by `U(-landmark_jitter, landmark_jitter)`, drawn in that order from `stream`. With
    /// both jitters 0 nothing is drawn.
    pub fn drawn(
        config: &Nav1dConfig,
        environment: Environment,
        goal: Side,
        stream: &mut Stream,
    ) -> Condition {
        let mut c = Condition::exact(config, environment, goal);
        if config.start_jitter > 0.0 {
            c.start += stream.range(-config.start_jitter, config.start_jitter);
        }
        if config.landmark_jitter > 0.0 {
            c.landmark += stream.range(-config.landmark_jitter, config.landmark_jitter);
        }
        c
    }

    /// What the landmark sensor reads at `x`: 1 on the closed segment, else 0.
    ///
    /// # Example
    /// ```
    /// use tasks::nav1d::{Condition, Environment, Nav1dConfig, Side};
    /// let c = Condition::exact(&Nav1dConfig::default(), Environment::Near, Side::Right);
    /// assert_eq!([c.landmark_input(8.0, 4.0), c.landmark_input(7.99, 4.0)], [1.0, 0.0]);
    /// ```
    pub fn landmark_input(&self, x: f64, width: f64) -> f64 {
        if (x - self.landmark).abs() <= 0.5 * width {
            1.0
        } else {
            0.0
        }
    }
}

/// What one tick did on one lane, for [`run_chains`]'s observer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Tick {
    /// The trial the tick belonged to.
    pub(crate) trial: usize,
    /// Whether the agent moved during the tick (false in the reinforcement period).
    pub(crate) moving: bool,
    /// The agent's position after the tick.
    pub(crate) x: f64,
    /// Whether the tick ends a time step of its phase: the `substeps`-th tick of the moving
    /// phase or of the reinforcement period, counted from the phase's start, or the phase's last
    /// tick. Every tick of the stepped world does.
    pub(crate) closes: bool,
}

/// Every lane's [`Tick`], worked out only when asked for: evaluation never asks.
pub(crate) struct Ticks<'a, const L: usize> {
    /// How many ticks were run together, each with the same inputs: 1 while any agent moves.
    pub(crate) count: usize,
    trial: &'a [usize; L],
    moving: &'a [bool; L],
    x: &'a [f64; L],
    left: &'a [usize; L],
    per_step: usize,
    half_length: f64,
}

impl<const L: usize> Ticks<'_, L> {
    /// What the tick did on lane `l`.
    pub(crate) fn get(&self, l: usize) -> Tick {
        let (x, h) = (self.x[l], self.half_length);
        let ended = self.left[l] == 0 || (self.moving[l] && (x >= h || x <= -h));
        Tick {
            trial: self.trial[l],
            moving: self.moving[l],
            x,
            closes: ended || self.left[l].is_multiple_of(self.per_step),
        }
    }
}

/// What each trial of a chain did, on every lane: `reached[t][l]`, `classification[t][l]`.
pub(crate) struct Outcome<const L: usize> {
    pub(crate) reached: Vec<[bool; L]>,
    pub(crate) classification: Vec<[f64; L]>,
}

/// Runs chains of trials on every lane in lockstep, lane `l` through `chains[l]` (all of the same
/// length), one tick at a time; while no agent moves, the ticks up to the next end of a time step
/// go together (the same integration steps, with the inputs held). With `reset` the state starts
/// at 0. `observe(inputs, outputs, ticks)` sees the inputs, every neuron's firing rate after the
/// ticks (`outputs[i][l]`, in the lanes' precision) and what the last of them did on each lane, while any lane's chain is
/// still running. This is the only trial loop: evaluation (`L = LANES`) and recording (`L = 1`)
/// both run it, so they agree bit for bit.
pub(crate) fn run_chains<const L: usize, E: Elem>(
    config: &Nav1dConfig,
    lanes: &mut Lanes<L, E>,
    chains: [&[Condition]; L],
    reset: bool,
    mut observe: impl FnMut(&[[f64; L]], &[[E; L]], &Ticks<L>),
) -> Result<Outcome<L>, Diverged> {
    let k = chains[0].len();
    debug_assert!(chains.iter().all(|c| c.len() == k));
    if reset {
        lanes.reset();
    }
    let (tick, per_step) = config.tick();
    let tick_time = tick.dt * tick.substeps as f64;
    let (h, half_width) = (config.half_length, 0.5 * config.landmark_width);
    let move_ticks = config.max_steps * per_step;
    let reinforce_ticks = config.reinforcement_steps * per_step;
    let (left_motor, right_motor) = (config.left_motor, config.right_motor);
    let classifier = (config.classifier < lanes.size()).then_some(config.classifier);
    let m = config.n_inputs();
    let mut reached = vec![[false; L]; k];
    let mut classification = vec![[0.0; L]; k];
    // Each lane's place in its chain: the trial, whether the agent is moving (else the trial is
    // in its reinforcement period, or the chain is over), its position, the landmark's centre,
    // the ticks left in the phase (usize::MAX once the chain is over) and whether the trial
    // reached the goal.
    let mut trial = [0usize; L];
    let mut moving = [k > 0; L];
    let mut x: [f64; L] = std::array::from_fn(|l| chains[l].first().map_or(0.0, |c| c.start));
    let mut centre: [f64; L] =
        std::array::from_fn(|l| chains[l].first().map_or(0.0, |c| c.landmark));
    let mut left = [if k > 0 { move_ticks } else { usize::MAX }; L];
    let mut goal = [false; L];
    let mut running = if k > 0 { L } else { 0 };
    let mut inputs = [[0.0; L]; 2];
    // Whether each lane's landmark input is 1.
    let mut sensing = [false; L];
    // Whether the inputs differ from the last tick's (they do at the first).
    let mut changed = true;
    while running > 0 {
        // Branch-free loops over the lanes, so that they compile to lane vectors.
        let mut any_moving = false;
        for l in 0..L {
            any_moving |= moving[l];
            let on = moving[l] & ((x[l] - centre[l]).abs() <= half_width);
            changed |= on != sensing[l];
            sensing[l] = on;
            inputs[0][l] = f64::from(u8::from(on));
        }
        // While no agent moves, nothing changes before some lane's time step ends.
        let count = if any_moving {
            1
        } else {
            (0..L)
                .filter(|&l| left[l] != usize::MAX)
                .map(|l| (left[l] - 1) % per_step + 1)
                .min()
                .unwrap_or(1)
        };
        // The one-tick path is kept apart: a tick count that changes from call to call costs it
        // 10 %.
        // The network reads its inputs in its own precision (0 and 1 are exact in both).
        let read = inputs.map(|row| row.map(E::from_f64));
        if count > 1 {
            let ticks = Integrator {
                substeps: tick.substeps * count,
                ..tick
            };
            if changed {
                lanes.step_row(&read[..m], &ticks);
            } else {
                lanes.step_held(&ticks);
            }
        } else if changed {
            lanes.step_row(&read[..m], &tick);
        } else {
            lanes.step_held(&tick);
        }
        changed = false;
        let out = lanes.outputs();
        let (vl, vr) = (&out[left_motor], &out[right_motor]);
        let mut event = false;
        for l in 0..L {
            let moved = x[l] + tick_time * (vr[l].to_f64() - vl[l].to_f64());
            let xl = if moving[l] { moved } else { x[l] };
            x[l] = xl;
            left[l] -= count;
            event |= (left[l] == 0) | (moving[l] & ((xl >= h) | (xl <= -h)));
        }
        let ticks = Ticks {
            count,
            trial: &trial,
            moving: &moving,
            x: &x,
            left: &left,
            per_step,
            half_length: h,
        };
        observe(&inputs[..m], out, &ticks);
        if !event {
            continue;
        }
        // A phase ends: the reinforcement input may change.
        changed = true;
        for l in 0..L {
            if moving[l] && (left[l] == 0 || x[l] >= h || x[l] <= -h) {
                let end = if x[l] >= h {
                    Some(Side::Right)
                } else if x[l] <= -h {
                    Some(Side::Left)
                } else {
                    None
                };
                goal[l] = end == Some(chains[l][trial[l]].goal);
                moving[l] = false;
                left[l] = reinforce_ticks;
                inputs[1][l] = if goal[l] { 1.0 } else { 0.0 };
            }
            if moving[l] || left[l] != 0 {
                continue;
            }
            // The trial is over.
            let t = trial[l];
            reached[t][l] = goal[l];
            classification[t][l] = classifier.map_or(f64::NAN, |c| out[c][l].to_f64());
            trial[l] += 1;
            inputs[1][l] = 0.0;
            goal[l] = false;
            match chains[l].get(t + 1) {
                Some(c) => {
                    moving[l] = true;
                    x[l] = c.start;
                    centre[l] = c.landmark;
                    left[l] = move_ticks;
                }
                None => {
                    left[l] = usize::MAX;
                    running -= 1;
                }
            }
        }
    }
    Diverged::find(lanes)?;
    Ok(Outcome {
        reached,
        classification,
    })
}
