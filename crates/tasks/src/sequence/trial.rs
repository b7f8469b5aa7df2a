//! One trial's protocol, run on a block of lanes in lockstep: triggers, delays, reinforcement
//! and gaps, and the timings drawn for them.

use ctrnn::{Elem, Lanes, Stream};

use crate::common::Diverged;

use super::config::*;

/// Which part of a trigger's cycle a lane is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    Trigger,
    Delay,
    Reinforce,
    Gap,
    Done,
}

/// One lane's position in its trial: trigger `k`, `phase`, with `left` time steps to go.
#[derive(Clone, Copy, Debug)]
struct Cursor {
    k: usize,
    phase: Phase,
    left: usize,
}

impl Cursor {
    fn start(timing: &[(usize, usize)], trigger_steps: usize) -> Cursor {
        let phase = if timing.is_empty() {
            Phase::Done
        } else {
            Phase::Trigger
        };
        Cursor {
            k: 0,
            phase,
            left: trigger_steps,
        }
    }

    /// Moves on past finished (and empty) phases. Unless `full`, the trial ends with the last
    /// trigger window, after which nothing can change a score.
    fn settle(&mut self, timing: &[(usize, usize)], config: &SequenceConfig, full: bool) {
        while self.left == 0 && self.phase != Phase::Done {
            (self.phase, self.left) = match self.phase {
                Phase::Trigger if !full && self.k + 1 == timing.len() => (Phase::Done, 0),
                Phase::Trigger => (Phase::Delay, timing[self.k].0),
                Phase::Delay => (Phase::Reinforce, config.reinforcement_steps),
                Phase::Reinforce => (Phase::Gap, timing[self.k].1),
                Phase::Gap => {
                    self.k += 1;
                    if self.k == timing.len() {
                        (Phase::Done, 0)
                    } else {
                        (Phase::Trigger, config.trigger_steps)
                    }
                }
                Phase::Done => unreachable!(),
            };
        }
    }
}

/// Per-trigger results of one trial on every lane.
pub(super) struct Outcome<const L: usize> {
    /// R of trigger k on lane l: `r[k][l]`.
    pub(super) r: Vec<[f64; L]>,
    /// Mean output over the window of trigger k on lane l.
    pub(super) mean_output: Vec<[f64; L]>,
}

/// Runs one trial of target `bits` on every lane of `lanes` in lockstep, lane `l` with its own
/// `timings[l]` (all of the same length). `observe(inputs, lanes)` sees each time step's inputs and
/// the state after it. With `full` the trial runs to the end of the last gap; otherwise it stops
/// after the last trigger window, which gives the same R values. This is the only trial loop: the
/// population evaluation (`L = LANES`) and the single-network record (`L = 1`) both run it, so
/// they agree bit for bit.
pub(super) fn run_lanes<const L: usize, E: Elem>(
    config: &SequenceConfig,
    lanes: &mut Lanes<L, E>,
    bits: &[u8],
    timings: [&[(usize, usize)]; L],
    reset: bool,
    full: bool,
    mut observe: impl FnMut(&[[f64; L]; 2], &Lanes<L, E>),
) -> std::result::Result<Outcome<L>, Diverged> {
    let n_triggers = timings[0].len();
    debug_assert!(timings.iter().all(|t| t.len() == n_triggers));
    if reset {
        lanes.reset();
    }
    let steps = config.trigger_steps as f64;
    let mut cursors = timings.map(|t| Cursor::start(t, config.trigger_steps));
    let mut err = [0.0; L];
    let mut on = [0.0; L];
    let mut r = vec![[0.0; L]; n_triggers];
    let mut mean_output = vec![[0.0; L]; n_triggers];
    let mut inputs = [[0.0; L]; 2];
    while cursors.iter().any(|c| c.phase != Phase::Done) {
        for (l, c) in cursors.iter().enumerate() {
            inputs[0][l] = if c.phase == Phase::Trigger { 1.0 } else { 0.0 };
            inputs[1][l] = if c.phase == Phase::Reinforce {
                r[c.k][l]
            } else {
                0.0
            };
        }
        // The network reads its inputs in its own precision (an exact copy in `f64`).
        lanes.step_row(&inputs.map(|row| row.map(E::from_f64)), &config.integrator);
        // All the rates, in the kernel's vectors: the next step starts from them rather than
        // computing them again, so neuron 0's cost nothing (`output(0)`, one lane at a time, cost
        // 4% of an evaluation).
        let out = lanes.outputs()[0].map(E::to_f64);
        for (l, c) in cursors.iter_mut().enumerate() {
            if c.phase == Phase::Done {
                continue;
            }
            if c.phase == Phase::Trigger {
                let p = f64::from(bits[c.k % bits.len()]);
                err[l] += (p - out[l]).abs();
                on[l] += out[l];
            }
            c.left -= 1;
            if c.left == 0 {
                if c.phase == Phase::Trigger {
                    r[c.k][l] = 1.0 - err[l] / steps;
                    mean_output[c.k][l] = on[l] / steps;
                    err[l] = 0.0;
                    on[l] = 0.0;
                }
                c.settle(timings[l], config, full);
            }
        }
        observe(&inputs, lanes);
    }
    Diverged::find(lanes)?;
    Ok(Outcome { r, mean_output })
}

/// Draws `n` (delay, gap) pairs from `stream`, delay first.
pub(super) fn draw_timings(
    config: &SequenceConfig,
    mut stream: Stream,
    n: usize,
) -> Vec<(usize, usize)> {
    let mut draw = |(lo, hi): (usize, usize)| stream.range_inclusive_int(lo as u64, hi as u64);
    (0..n)
        .map(|_| {
            let d = draw(config.delay) as usize;
            let g = draw(config.gap) as usize;
            (d, g)
        })
        .collect()
}

/// Bits of a target string that has been validated.
pub(super) fn to_bits(target: &str) -> Vec<u8> {
    target.bytes().map(|b| b - b'0').collect()
}
