//! The two ways a task runs many networks on many trials in parallel, with the same Ctrl-C and
//! divergence checks everywhere.
//!
//! - [`by_block`] scores a population: networks packed [`LANES`] to a block, blocks in parallel,
//!   every block meeting the same trials in order. Lane `l` of block `b` is network
//!   `b * LANES + l`.
//! - [`by_pair`] assesses a few networks on many trials: (network, trial) pairs [`LANES`] at a
//!   time, groups in parallel, so that one network still fills every lane and core.
//!
//! A lane's result never depends on its neighbours, so both give the same bits for a pair. When
//! blocks or groups fail, the error is the first one's in order, whatever the threads. Both
//! compute in the element type `E` of the lanes their callback takes: `f64`, or `f32` (see
//! [`ctrnn::Precision`]).

use std::borrow::Borrow;
use std::collections::HashMap;
use std::sync::atomic::AtomicBool;

use ctrnn::{Elem, Error, Lanes, Network, Result, LANES};
use rayon::prelude::*;

use crate::common::{interrupted, Diverged};

/// Runs `trials` trials on every block of `networks`. For each block, `start(len)` makes its accumulator (`len` real networks, the rest of
/// the lanes padding), `trial(&mut acc, first, block, t)` runs trial `t` on every lane (`first`
/// is the block's first network), and `finish(acc)` gives the block's results, which are joined
/// in block order. Stops with
/// [`Error::Interrupted`] between trials once `cancel` is set; a divergence names its network.
pub fn by_block<E: Elem, A, T: Send>(
    networks: &[Network],
    trials: usize,
    cancel: Option<&AtomicBool>,
    start: impl Fn(usize) -> A + Sync,
    trial: impl Fn(&mut A, usize, &mut Lanes<LANES, E>, usize) -> std::result::Result<(), Diverged>
        + Sync,
    finish: impl Fn(A) -> Vec<T> + Sync,
) -> Result<Vec<T>> {
    blocks(networks, &|p| p, trials, cancel, start, trial, finish)
}

/// [`by_block`] on `networks` that stand for others: a divergence on `networks[p]` names
/// network `names[p]`.
pub fn by_block_named<E: Elem, A, T: Send>(
    networks: &[&Network],
    names: &[usize],
    trials: usize,
    cancel: Option<&AtomicBool>,
    start: impl Fn(usize) -> A + Sync,
    trial: impl Fn(&mut A, usize, &mut Lanes<LANES, E>, usize) -> std::result::Result<(), Diverged>
        + Sync,
    finish: impl Fn(A) -> Vec<T> + Sync,
) -> Result<Vec<T>> {
    debug_assert_eq!(networks.len(), names.len());
    blocks(
        networks,
        &|p| names[p],
        trials,
        cancel,
        start,
        trial,
        finish,
    )
}

fn blocks<E: Elem, N: Borrow<Network> + Sync, A, T: Send>(
    networks: &[N],
    name: &(dyn Fn(usize) -> usize + Sync),
    trials: usize,
    cancel: Option<&AtomicBool>,
    start: impl Fn(usize) -> A + Sync,
    trial: impl Fn(&mut A, usize, &mut Lanes<LANES, E>, usize) -> std::result::Result<(), Diverged>
        + Sync,
    finish: impl Fn(A) -> Vec<T> + Sync,
) -> Result<Vec<T>> {
    if networks.is_empty() {
        return Ok(vec![]);
    }
    let per_block = ctrnn::population::pack::<E, N>(networks)?
        .par_iter_mut()
        .enumerate()
        .map(|(b, block)| {
            let first = b * LANES;
            let mut acc = start(block.len());
            for t in 0..trials {
                if interrupted(cancel) {
                    return Err(Error::Interrupted);
                }
                trial(&mut acc, first, block, t).map_err(|d| d.error(|lane| name(first + lane)))?;
            }
            Ok(finish(acc))
        })
        .collect::<Vec<Result<_>>>();
    // In block order, so that the error reported (the first block's) does not depend on which
    // thread failed first.
    let per_block = per_block.into_iter().collect::<Result<Vec<_>>>()?;
    Ok(per_block.into_iter().flatten().collect())
}

/// The networks of a batch with duplicates told apart: networks equal bit for bit in every
/// parameter and in their state are one kind. Where every network meets the same trials, a lane's
/// results depend only on its network (never on its neighbours), so one network of each kind can
/// run for all of its kind with the same bits. A GA population is full of such copies: children
/// that neither crossover nor mutation changed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Kinds {
    /// The index of each kind's first network, in order of first appearance.
    pub firsts: Vec<usize>,
    /// The kind of every network: an index into `firsts`.
    pub kind: Vec<usize>,
}

impl Kinds {
    /// The kinds of `networks`.
    pub fn of(networks: &[Network]) -> Kinds {
        let mut seen: HashMap<Vec<u64>, usize> = HashMap::with_capacity(networks.len());
        let mut firsts = Vec::new();
        let kind = networks
            .iter()
            .enumerate()
            .map(|(p, net)| {
                let shape = [net.size() as u64, net.n_inputs() as u64];
                let key: Vec<u64> = shape
                    .into_iter()
                    .chain(
                        [
                            net.tau(),
                            net.theta(),
                            net.weights(),
                            net.sensor_weights(),
                            net.state(),
                        ]
                        .iter()
                        .flat_map(|part| part.iter().map(|x| x.to_bits())),
                    )
                    .collect();
                *seen.entry(key).or_insert_with(|| {
                    firsts.push(p);
                    firsts.len() - 1
                })
            })
            .collect();
        Kinds { firsts, kind }
    }

    /// Whether every network is of its own kind.
    pub fn all_distinct(&self) -> bool {
        self.firsts.len() == self.kind.len()
    }
}

/// The (network, trial) pairs of `networks` x `trials`, network-major, cut into groups of
/// [`LANES`]: the usual grouping for [`by_pair`].
pub fn pairs(networks: usize, trials: usize) -> Vec<(usize, usize)> {
    (0..networks)
        .flat_map(|n| (0..trials).map(move |t| (n, t)))
        .collect()
}

/// Runs each group of (network, trial) pairs (at most [`LANES`] each) on one set of lanes, groups
/// in parallel, and returns the results of every group in order. Lanes past a group's end repeat
/// its first pair. `run(lanes, lane_pairs, len)` runs lane `l` on `lane_pairs[l]` from a fresh
/// state and returns the `len` real lanes' results. Stops with [`Error::Interrupted`] between
/// groups once `cancel` is set; a divergence names its network.
pub fn by_pair<E: Elem, T: Send>(
    networks: &[&Network],
    groups: &[&[(usize, usize)]],
    cancel: Option<&AtomicBool>,
    run: impl Fn(
            &mut Lanes<LANES, E>,
            [(usize, usize); LANES],
            usize,
        ) -> std::result::Result<Vec<T>, Diverged>
        + Sync,
) -> Result<Vec<T>> {
    let per_group = groups
        .par_iter()
        .map(|group| {
            if interrupted(cancel) {
                return Err(Error::Interrupted);
            }
            debug_assert!(!group.is_empty() && group.len() <= LANES);
            let lane_pairs: [(usize, usize); LANES] =
                std::array::from_fn(|l| group[if l < group.len() { l } else { 0 }]);
            let refs: [&Network; LANES] = std::array::from_fn(|l| networks[lane_pairs[l].0]);
            let mut lanes = Lanes::<LANES, E>::new(&refs)?;
            run(&mut lanes, lane_pairs, group.len()).map_err(|d| d.error(|lane| lane_pairs[lane].0))
        })
        .collect::<Vec<Result<_>>>();
    // In group order, as in `by_block`.
    let per_group = per_group.into_iter().collect::<Result<Vec<_>>>()?;
    Ok(per_group.into_iter().flatten().collect())
}
