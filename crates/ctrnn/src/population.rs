//! The population integrator: P networks of the same shape, stepped block by block in parallel.
//!
//! Networks are packed into [`Block`]s of [`LANES`] networks; rayon runs blocks on all cores, and
//! within a block the arithmetic is vectorised across networks (see [`crate::integrate`]). Blocks
//! are independent, so the result does not depend on the number of threads, and each network's
//! result is bit-identical to [`Network::run`] on that network alone.

use std::borrow::Borrow;
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::integrate::{check_inputs, copy_lane, Integrator, Lanes, LANES};
use crate::limits;
use crate::network::Network;

/// A block of [`LANES`] networks stepped together.
pub type Block = Lanes<LANES>;

/// Input rows for a population run.
#[derive(Clone, Copy, Debug)]
pub enum Inputs<'a> {
    /// One `T x M` array (row-major) shared by every network.
    Shared(&'a [f64]),
    /// A `P x T x M` array (row-major), one input series per network.
    PerNetwork(&'a [f64]),
}

/// P networks of the same N and M, laid out for fast stepping.
#[derive(Clone, Debug)]
pub struct Population {
    size: usize,
    n_inputs: usize,
    len: usize,
    blocks: Vec<Block>,
}

impl Population {
    /// Packs `networks` (at least one, all with the same N and M), given as networks or as
    /// references to them.
    pub fn new<N: Borrow<Network>>(networks: &[N]) -> Result<Self> {
        let refs: Vec<&Network> = networks.iter().map(Borrow::borrow).collect();
        let first = refs.first().ok_or_else(|| {
            Error::InvalidArgument("a population needs at least 1 network".into())
        })?;
        let (n, m) = (first.size(), first.n_inputs());
        if let Some(p) = refs.iter().position(|x| (x.size(), x.n_inputs()) != (n, m)) {
            return Err(Error::InvalidArgument(format!(
                "network {p} has N = {}, M = {}; every network of a population must have N = {n}, M = {m}",
                refs[p].size(),
                refs[p].n_inputs()
            )));
        }
        let blocks = refs
            .par_chunks(LANES)
            .map(Block::new)
            .collect::<Result<Vec<_>>>()?;
        Ok(Population {
            size: n,
            n_inputs: m,
            len: refs.len(),
            blocks,
        })
    }

    /// Number of networks P.
    pub fn len(&self) -> usize {
        self.len
    }
    /// Always false: a population has at least one network.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Neurons per network N.
    pub fn size(&self) -> usize {
        self.size
    }
    /// Sensors per network M.
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }
    /// The blocks, for tasks that compute each row's inputs from the networks' outputs.
    /// Block `b`, lane `l` is network `b * LANES + l`.
    pub fn blocks_mut(&mut self) -> &mut [Block] {
        &mut self.blocks
    }

    /// The current states, row-major `P x N`.
    pub fn states(&self) -> Vec<f64> {
        let n = self.size;
        let mut out = vec![0.0; self.len * n];
        for (b, block) in self.blocks.iter().enumerate() {
            for l in 0..block.len() {
                let p = b * LANES + l;
                block.lane_state(l, &mut out[p * n..(p + 1) * n]);
            }
        }
        out
    }

    /// Integrates every network through `steps` input rows and returns the state after every row
    /// (`P x T x N`, row-major) when `record`, else the final states (`P x N`).
    ///
    /// Stops with [`Error::Interrupted`] soon after `cancel` is set.
    pub fn run(
        &mut self,
        inputs: Inputs<'_>,
        steps: usize,
        integ: &Integrator,
        record: bool,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        integ.validate()?;
        let (m, p_len) = (self.n_inputs, self.len);
        limits::check_work(p_len, steps, integ.substeps)?;
        match inputs {
            Inputs::Shared(x) => {
                check_inputs(x, steps * m, "T x M")?;
                self.run_filled(steps, integ, record, cancel, |_, t, row| {
                    for (r, &v) in row.iter_mut().zip(&x[t * m..(t + 1) * m]) {
                        *r = [v; LANES];
                    }
                })
            }
            Inputs::PerNetwork(x) => {
                check_inputs(x, p_len * steps * m, "P x T x M")?;
                self.run_filled(steps, integ, record, cancel, |b, t, row| {
                    for l in 0..LANES {
                        // Padding lanes repeat the block's first network.
                        let p = b * LANES + if b * LANES + l < p_len { l } else { 0 };
                        let at = (p * steps + t) * m;
                        for (r, &v) in row.iter_mut().zip(&x[at..at + m]) {
                            r[l] = v;
                        }
                    }
                })
            }
        }
    }

    /// [`run`](Self::run) with `fill(b, t, row)` writing block `b`'s inputs of row `t`.
    fn run_filled(
        &mut self,
        steps: usize,
        integ: &Integrator,
        record: bool,
        cancel: Option<&AtomicBool>,
        fill: impl Fn(usize, usize, &mut [[f64; LANES]]) + Sync,
    ) -> Result<Vec<f64>> {
        let n = self.size;
        let fill = &fill;
        // One call of `run_rows` for both cases, so that the kernel under it is compiled once.
        let len = if record {
            limits::product(&[self.len, steps, n], "recorded states")?
        } else {
            0
        };
        let mut out = limits::zeros(len, "recorded states")?;
        let mut chunks: Vec<Option<&mut [f64]>> = if record {
            out.chunks_mut(LANES * steps * n).map(Some).collect()
        } else {
            self.blocks.iter().map(|_| None).collect()
        };
        // The lowest failing block's error, as in order: not whichever thread failed first.
        let failed = self
            .blocks
            .par_iter_mut()
            .zip(chunks.par_iter_mut())
            .enumerate()
            .filter_map(|(b, (block, chunk))| {
                let row = |t, row: &mut [[f64; LANES]]| fill(b, t, row);
                let real = block.len();
                block
                    .run_rows(steps, integ, cancel, row, |t, state| {
                        if let Some(chunk) = chunk.as_deref_mut() {
                            for l in 0..real {
                                let at = (l * steps + t) * n;
                                copy_lane(state, l, &mut chunk[at..at + n]);
                            }
                        }
                    })
                    .and_then(|()| block.check_finite(|l| format!("network {}", b * LANES + l)))
                    .err()
                    .map(|e| (b, e))
            })
            .min_by_key(|&(b, _)| b);
        if let Some((_, e)) = failed {
            return Err(e);
        }
        Ok(if record { out } else { self.states() })
    }
}
