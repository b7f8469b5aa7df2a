//! The two ways a task runs many networks on many trials in parallel, with the same Ctrl-C and
//! divergence checks everywhere.
//!
//! - [`by_block`] scores a population: networks packed [`LANES`] to a block, blocks in parallel,
//!   every block meeting the same trials in order. Lane `l` of block `b` is network
//!   `b * LANES + l`.
//! - [`by_pair`] assesses a few networks on many trials: (network, trial) pairs [`LANES`] at a
//!   time, groups in parallel, so that one network still fills every lane and core.
//!
//! A lane's result never depends on its neighbours, so both give the same bits for a pair.

use std::sync::atomic::AtomicBool;

use ctrnn::{Block, Error, Lanes, Network, Population, Result, LANES};
use rayon::prelude::*;

use crate::common::{interrupted, Diverged};

/// Runs `trials` trials on every block of `networks`. For each block, `start(len)` makes its accumulator (`len` real networks, the rest of
/// the lanes padding), `trial(&mut acc, first, block, t)` runs trial `t` on every lane (`first`
/// is the block's first network), and `finish(acc)` gives the block's results, which are joined
/// in block order. Stops with
/// [`Error::Interrupted`] between trials once `cancel` is set; a divergence names its network.
pub fn by_block<A, T: Send>(
    networks: &[Network],
    trials: usize,
    cancel: Option<&AtomicBool>,
    start: impl Fn(usize) -> A + Sync,
    trial: impl Fn(&mut A, usize, &mut Block, usize) -> std::result::Result<(), Diverged> + Sync,
    finish: impl Fn(A) -> Vec<T> + Sync,
) -> Result<Vec<T>> {
    if networks.is_empty() {
        return Ok(vec![]);
    }
    let mut population = Population::new(networks)?;
    let per_block = population
        .blocks_mut()
        .par_iter_mut()
        .enumerate()
        .map(|(b, block)| {
            let first = b * LANES;
            let mut acc = start(block.len());
            for t in 0..trials {
                if interrupted(cancel) {
                    return Err(Error::Interrupted);
                }
                trial(&mut acc, first, block, t).map_err(|d| d.error(|lane| first + lane))?;
            }
            Ok(finish(acc))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(per_block.into_iter().flatten().collect())
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
pub fn by_pair<T: Send>(
    networks: &[&Network],
    groups: &[&[(usize, usize)]],
    cancel: Option<&AtomicBool>,
    run: impl Fn(
            &mut Lanes<LANES>,
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
            let mut lanes = Lanes::<LANES>::new(&refs)?;
            run(&mut lanes, lane_pairs, group.len()).map_err(|d| d.error(|lane| lane_pairs[lane].0))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(per_group.into_iter().flatten().collect())
}
