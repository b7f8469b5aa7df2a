//! The line world and its trial loop: where the goal and the landmark are, what the sensors read,
//! how the agent moves, and when a trial ends.
//!
//! # One time step
//! 1. The sensors are read at the agent's position `x`: input 0 is 1 while the agent is on the
//!    landmark (`|x - landmark| <= landmark_width / 2`), else 0; input 1 (the reinforcement, if
//!    the network has it) is 0 while the agent moves.
//! 2. The network integrates one time step with these inputs held.
//! 3. The agent moves: `x += step_time * (f(v_R) - f(v_L))`, with the firing rates after the step.
//! 4. The trial ends when `x >= half_length` or `x <= -half_length` (the agent reached that end),
//!    or after `max_steps` time steps. The goal is reached when the end is the goal's.
//!
//! After the trial, the network runs `reinforcement_steps` more time steps with the landmark input
//! 0 and the reinforcement input 1 if the goal was reached, 0 otherwise. The classifier's output
//! `f(v_C)` at the end of that period is the trial's classification. The next trial of a chain
//! starts at its own start position, from the state the last one left.

use ctrnn::{Lanes, Stream};
use serde::{Deserialize, Serialize};

use super::config::Nav1dConfig;
use crate::common::Diverged;

/// Where the landmark is relative to the goal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Environment {
    /// The landmark is on the other side of the start from the goal.
    Far,
    /// The landmark is on the goal's side.
    Near,
}

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

/// Which part of a trial a lane is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Phase {
    /// The agent moves.
    Move,
    /// The trial has ended; this many time steps of the reinforcement period are left.
    Reinforce(usize),
    /// The chain is over.
    Done,
}

/// One lane's place in its chain of trials.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cursor {
    /// The trial of the chain.
    pub(crate) trial: usize,
    pub(crate) phase: Phase,
    /// The agent's position.
    pub(crate) x: f64,
    /// Time steps the agent has moved in this trial.
    pub(crate) steps: usize,
    /// Whether this trial reached the goal.
    pub(crate) reached: bool,
}

/// What each trial of a chain did, on every lane: `reached[t][l]`, `classification[t][l]`.
pub(crate) struct Outcome<const L: usize> {
    pub(crate) reached: Vec<[bool; L]>,
    pub(crate) classification: Vec<[f64; L]>,
}

/// Runs chains of trials on every lane in lockstep, lane `l` through `chains[l]` (all of the same
/// length). With `reset` the state starts at 0. `observe(inputs, lanes, before, after)` sees each
/// time step's inputs, the network after it, and each lane's cursor before the step and after the
/// agent moved (a finished trial's cursor has moved on to the next trial). This is the
/// only trial loop: evaluation (`L = LANES`) and recording (`L = 1`) both run it, so they agree
/// bit for bit.
pub(crate) fn run_chains<const L: usize>(
    config: &Nav1dConfig,
    lanes: &mut Lanes<L>,
    chains: [&[Condition]; L],
    reset: bool,
    mut observe: impl FnMut(&[[f64; L]], &Lanes<L>, &[Cursor; L], &[Cursor; L]),
) -> Result<Outcome<L>, Diverged> {
    let k = chains[0].len();
    debug_assert!(chains.iter().all(|c| c.len() == k));
    if reset {
        lanes.reset();
    }
    let (h, dt) = (config.half_length, config.step_time());
    let mut reached = vec![[false; L]; k];
    let mut classification = vec![[0.0; L]; k];
    let mut cursors: [Cursor; L] = std::array::from_fn(|l| Cursor {
        trial: 0,
        phase: if k == 0 { Phase::Done } else { Phase::Move },
        x: chains[l].first().map_or(0.0, |c| c.start),
        steps: 0,
        reached: false,
    });
    let mut inputs = [[0.0; L]; 2];
    let m = config.n_inputs();
    while cursors.iter().any(|c| c.phase != Phase::Done) {
        for (l, c) in cursors.iter().enumerate() {
            (inputs[0][l], inputs[1][l]) = match c.phase {
                Phase::Move => (
                    chains[l][c.trial].landmark_input(c.x, config.landmark_width),
                    0.0,
                ),
                Phase::Reinforce(_) if c.reached => (0.0, 1.0),
                _ => (0.0, 0.0),
            };
        }
        lanes.step_row(&inputs[..m], &config.integrator);
        let left = lanes.output(config.left_motor);
        let right = lanes.output(config.right_motor);
        let before = cursors;
        for (l, c) in cursors.iter_mut().enumerate() {
            let ended = match c.phase {
                Phase::Move => {
                    c.x += dt * (right[l] - left[l]);
                    c.steps += 1;
                    let end = if c.x >= h {
                        Some(Side::Right)
                    } else if c.x <= -h {
                        Some(Side::Left)
                    } else {
                        None
                    };
                    c.reached = end == Some(chains[l][c.trial].goal);
                    if end.is_some() || c.steps == config.max_steps {
                        c.phase = Phase::Reinforce(config.reinforcement_steps);
                    }
                    c.phase == Phase::Reinforce(0)
                }
                Phase::Reinforce(left) => {
                    c.phase = Phase::Reinforce(left - 1);
                    left == 1
                }
                Phase::Done => false,
            };
            if ended {
                reached[c.trial][l] = c.reached;
                classification[c.trial][l] = if config.classifier < lanes.size() {
                    lanes.output(config.classifier)[l]
                } else {
                    f64::NAN
                };
                c.trial += 1;
                if c.trial == k {
                    c.phase = Phase::Done;
                } else {
                    *c = Cursor {
                        trial: c.trial,
                        phase: Phase::Move,
                        x: chains[l][c.trial].start,
                        steps: 0,
                        reached: false,
                    };
                }
            }
        }
        observe(&inputs[..m], lanes, &before, &cursors);
    }
    Diverged::find(lanes)?;
    Ok(Outcome {
        reached,
        classification,
    })
}
