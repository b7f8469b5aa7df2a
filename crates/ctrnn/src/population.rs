//! The population integrator: P networks of the same shape, stepped block by block in parallel.
//!
//! Networks are packed into [`Block`]s of [`LANES`] networks; rayon runs blocks on all cores, and
//! within a block the arithmetic is vectorised across networks (see [`crate::integrate`]). Blocks
//! are independent, so the result does not depend on the number of threads, and each network's
//! result is bit-identical to [`Network::run`] on that network alone.
//!
//! A population may also compute in single precision ([`Population::with_precision`],
//! [`Precision::F32`]): parameters rounded to `f32` once, when packed, states `f32` throughout,
//! and the results widened (exactly) to `f64` on the way out.

use std::borrow::Borrow;
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::integrate::{check_inputs, Integrator, Lanes, Precision, Shortest, LANES};
use crate::limits;
use crate::network::{Network, Params};
use crate::vector::Elem;

/// A block of [`LANES`] networks stepped together.
pub type Block = Lanes<LANES>;

/// Packs `networks` (at least one, all with the same N and M), given as networks or as
/// references to them, into blocks of [`LANES`] computing in `E`, for tasks that compute each
/// row's inputs from the networks' outputs. Block `b`, lane `l` is network `b * LANES + l`; a
/// block's unused lanes repeat its first network. In `f32` the parameters and initial states are
/// rounded here, once.
///
/// # Example
/// ```
/// use ctrnn::{Integrator, Network, LANES};
/// let nets = vec![Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None)?; LANES + 1];
/// let mut blocks = ctrnn::population::pack::<f32, _>(&nets)?;
/// assert_eq!((blocks.len(), blocks[1].len()), (2, 1));
/// blocks[1].step_row(&[[1.0; LANES]], &Integrator::default());
/// assert_eq!(blocks[1].state(0)[0], 0.1f32);
/// # Ok::<(), ctrnn::Error>(())
/// ```
pub fn pack<E: Elem, N: Borrow<Network>>(networks: &[N]) -> Result<Vec<Lanes<LANES, E>>> {
    let params: Vec<Params> = networks.iter().map(|n| n.borrow().params()).collect();
    pack_params(&params)
}

/// [`pack`] from borrowed parameters, which must be valid ([`Params::validate`]).
fn pack_params<E: Elem>(nets: &[Params]) -> Result<Vec<Lanes<LANES, E>>> {
    let first = nets
        .first()
        .ok_or_else(|| Error::InvalidArgument("a population needs at least 1 network".into()))?;
    let (n, m) = (first.size(), first.n_inputs());
    if let Some(p) = nets.iter().position(|x| (x.size(), x.n_inputs()) != (n, m)) {
        return Err(Error::InvalidArgument(format!(
            "network {p} has N = {}, M = {}; every network of a population must have N = {n}, M = {m}",
            nets[p].size(),
            nets[p].n_inputs()
        )));
    }
    nets.par_chunks(LANES)
        .map(Lanes::from_params)
        .collect::<Result<Vec<_>>>()
}

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
    blocks: Blocks,
    /// The shortest time constant, which limits the step ([`Integrator::check_step`]).
    shortest: Option<Shortest>,
}

/// The blocks of a population, in the precision it computes in.
#[derive(Clone, Debug)]
enum Blocks {
    F64(Vec<Block>),
    F32(Vec<Lanes<LANES, f32>>),
}

impl Population {
    /// Packs `networks` (at least one, all with the same N and M), given as networks or as
    /// references to them, to compute in `f64`.
    pub fn new<N: Borrow<Network>>(networks: &[N]) -> Result<Self> {
        Self::with_precision(networks, Precision::F64)
    }

    /// [`new`](Self::new) computing in `precision`. In [`Precision::F32`] the parameters and
    /// initial states are rounded to `f32` here, once.
    ///
    /// # Example
    /// ```
    /// use ctrnn::{Inputs, Integrator, Network, Population, Precision};
    /// let net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None)?;
    /// let mut pop = Population::with_precision(&[net], Precision::F32)?;
    /// let v = pop.run(Inputs::Shared(&[1.0, 1.0]), 2, &Integrator::default(), false, None)?;
    /// // v += 0.1 * (-v + 1) in f32: 0.1, then 0.19, widened to f64.
    /// assert_eq!(v, [(0.1f32 + 0.1f32 * (1.0 - 0.1f32)) as f64]);
    /// # Ok::<(), ctrnn::Error>(())
    /// ```
    pub fn with_precision<N: Borrow<Network>>(
        networks: &[N],
        precision: Precision,
    ) -> Result<Self> {
        let params: Vec<Params> = networks.iter().map(|n| n.borrow().params()).collect();
        Self::packed(&params, precision)
    }

    /// A population of networks given by their borrowed parameters (rows of stacked arrays, for
    /// example), each checked as [`Network::new`] checks it, without an owned [`Network`] per
    /// member. An invalid member's error names its index: `network 1: tau[0] is -1; ...`.
    ///
    /// # Example
    /// ```
    /// use ctrnn::{Params, Population, Precision};
    /// let tau = [1.0, 2.0]; // two networks of one neuron and no sensors
    /// let rows: Vec<Params> = (0..2)
    ///     .map(|p| Params { tau: &tau[p..p + 1], theta: &[0.0], weights: &[1.0],
    ///                       sensor_weights: &[], state: &[0.0] })
    ///     .collect();
    /// let pop = Population::from_params(&rows, Precision::F64)?;
    /// assert_eq!((pop.len(), pop.size(), pop.n_inputs()), (2, 1, 0));
    /// # Ok::<(), ctrnn::Error>(())
    /// ```
    pub fn from_params(networks: &[Params], precision: Precision) -> Result<Self> {
        Params::validate_each(networks)?;
        Self::packed(networks, precision)
    }

    /// Packs valid `networks` in `precision`.
    fn packed(networks: &[Params], precision: Precision) -> Result<Self> {
        let blocks = match precision {
            Precision::F64 => Blocks::F64(pack_params(networks)?),
            Precision::F32 => Blocks::F32(pack_params(networks)?),
        };
        let (n, m) = (networks[0].size(), networks[0].n_inputs());
        Ok(Population {
            size: n,
            n_inputs: m,
            len: networks.len(),
            blocks,
            shortest: Shortest::of(networks),
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
    /// The precision it computes in.
    pub fn precision(&self) -> Precision {
        match self.blocks {
            Blocks::F64(_) => Precision::F64,
            Blocks::F32(_) => Precision::F32,
        }
    }
    /// The current states, row-major `P x N` (in `f64`, widened from `f32` if it computes in
    /// `f32`).
    pub fn states(&self) -> Vec<f64> {
        match &self.blocks {
            Blocks::F64(blocks) => states_of(blocks, self.len, self.size),
            Blocks::F32(blocks) => states_of(blocks, self.len, self.size),
        }
    }

    /// Integrates every network through `steps` input rows and returns the state after every row
    /// (`P x T x N`, row-major) when `record`, else the final states (`P x N`).
    ///
    /// In `f32` each input is rounded to `f32`, and the states returned are the `f32` states
    /// widened to `f64` (exactly: every `f32` is an `f64`).
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
        if let Some(shortest) = self.shortest {
            shortest.check(integ)?;
        }
        let (m, p_len) = (self.n_inputs, self.len);
        limits::check_work(p_len, steps, integ.substeps)?;
        match inputs {
            Inputs::Shared(x) => {
                check_inputs(x, steps * m, "T x M")?;
                self.run_filled(steps, integ, record, cancel, Fill::Shared(x))
            }
            Inputs::PerNetwork(x) => {
                check_inputs(x, p_len * steps * m, "P x T x M")?;
                self.run_filled(steps, integ, record, cancel, Fill::PerNetwork(x))
            }
        }
    }

    /// [`run`](Self::run) on the blocks of its precision.
    fn run_filled(
        &mut self,
        steps: usize,
        integ: &Integrator,
        record: bool,
        cancel: Option<&AtomicBool>,
        fill: Fill<'_>,
    ) -> Result<Vec<f64>> {
        let (len, n, m) = (self.len, self.size, self.n_inputs);
        let shape = Shape {
            len,
            n,
            m,
            steps,
            record,
        };
        let out = match &mut self.blocks {
            Blocks::F64(blocks) => run_blocks(blocks, shape, integ, cancel, fill)?,
            Blocks::F32(blocks) => run_blocks(blocks, shape, integ, cancel, fill)?,
        };
        Ok(if record { out } else { self.states() })
    }
}

/// Where a run's inputs come from (checked already).
#[derive(Clone, Copy)]
enum Fill<'a> {
    /// `T x M`, shared.
    Shared(&'a [f64]),
    /// `P x T x M`.
    PerNetwork(&'a [f64]),
}

impl Fill<'_> {
    /// Writes block `b`'s inputs of row `t` into `row`, rounded to `E`.
    #[inline(always)]
    fn row<E: Elem>(self, shape: Shape, b: usize, t: usize, row: &mut [[E; LANES]]) {
        let (m, steps, p_len) = (shape.m, shape.steps, shape.len);
        match self {
            Fill::Shared(x) => {
                for (r, &v) in row.iter_mut().zip(&x[t * m..(t + 1) * m]) {
                    *r = [E::from_f64(v); LANES];
                }
            }
            Fill::PerNetwork(x) => {
                for l in 0..LANES {
                    // Padding lanes repeat the block's first network.
                    let p = b * LANES + if b * LANES + l < p_len { l } else { 0 };
                    let at = (p * steps + t) * m;
                    for (r, &v) in row.iter_mut().zip(&x[at..at + m]) {
                        r[l] = E::from_f64(v);
                    }
                }
            }
        }
    }
}

/// The sizes of a run.
#[derive(Clone, Copy)]
struct Shape {
    len: usize,
    n: usize,
    m: usize,
    steps: usize,
    record: bool,
}

/// The states of `blocks` (`len` networks of `n` neurons), row-major `P x N`, in `f64`.
fn states_of<E: Elem>(blocks: &[Lanes<LANES, E>], len: usize, n: usize) -> Vec<f64> {
    let mut out = vec![0.0; len * n];
    for (b, block) in blocks.iter().enumerate() {
        for l in 0..block.len() {
            let p = b * LANES + l;
            widen_lane(block_states(block), l, &mut out[p * n..(p + 1) * n]);
        }
    }
    out
}

/// Every neuron's state row of `block`.
fn block_states<E: Elem>(block: &Lanes<LANES, E>) -> impl Iterator<Item = &[E; LANES]> {
    (0..block.size()).map(|i| block.state(i))
}

/// Copies lane `l` of `rows` (one value per row) into `into`, widened to `f64`.
#[inline(always)]
fn widen_lane<'a, E: Elem>(
    rows: impl IntoIterator<Item = &'a [E; LANES]>,
    l: usize,
    into: &mut [f64],
) {
    for (dst, row) in into.iter_mut().zip(rows) {
        *dst = row[l].to_f64();
    }
}

/// Runs `blocks` (in parallel) through `shape.steps` rows filled by `fill`; returns the recorded
/// states (`P x T x N`) if `shape.record`, else nothing.
fn run_blocks<E: Elem>(
    blocks: &mut [Lanes<LANES, E>],
    shape: Shape,
    integ: &Integrator,
    cancel: Option<&AtomicBool>,
    fill: Fill<'_>,
) -> Result<Vec<f64>> {
    let Shape {
        len,
        n,
        steps,
        record,
        ..
    } = shape;
    // One call of `run_rows` for every case (recorded or not, shared inputs or not), so that
    // the kernel under it is compiled once per precision.
    let len = if record {
        limits::product(&[len, steps, n], "recorded states")?
    } else {
        0
    };
    let mut out = limits::zeros(len, "recorded states")?;
    // No steps record nothing (and `chunks_mut` takes no chunks of length 0).
    let mut chunks: Vec<Option<&mut [f64]>> = if record && steps > 0 {
        out.chunks_mut(LANES * steps * n).map(Some).collect()
    } else {
        blocks.iter().map(|_| None).collect()
    };
    // The lowest failing block's error, as in order: not whichever thread failed first.
    let failed = blocks
        .par_iter_mut()
        .zip(chunks.par_iter_mut())
        .enumerate()
        .filter_map(|(b, (block, chunk))| {
            let row = |t, row: &mut [[E; LANES]]| fill.row(shape, b, t, row);
            let real = block.len();
            block
                .run_rows(steps, integ, cancel, row, |t, state| {
                    if let Some(chunk) = chunk.as_deref_mut() {
                        for l in 0..real {
                            let at = (l * steps + t) * n;
                            widen_lane(state, l, &mut chunk[at..at + n]);
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
    Ok(out)
}
