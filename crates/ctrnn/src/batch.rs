//! [`Batch`]: many networks stepped one input row at a time, for tasks whose next inputs depend
//! on the last outputs (closed loop).
//!
//! A batch holds `P` networks times `E` replicas, `B = P * E` rows; row `p * E + e` is replica
//! `e` of network `p`, so that one network's episodes sit side by side. Each call of
//! [`Batch::step`] holds one row of inputs per row for `substeps` integration steps and returns
//! every row's firing rates. Rows can be left out of a step (an ended episode), reset to zero (a
//! new one), or given any state.
//!
//! A batch can also hold fewer rows than `P * E` ([`Batch::with_rows`]) and hand a row to another
//! network when the row's episode ends ([`Batch::assign`]): a closed-loop rollout then keeps every
//! row busy with the episodes still waiting, instead of stepping ended rows' environments.
//!
//! One row fed the same inputs gives the same bits as [`Network::run`]: both step through the
//! same kernel in the same order of operations. A batch may compute in single precision
//! ([`Batch::with_rows_in`], [`Precision::F32`]), with the bits of [`Network::run_in`] in `f32`.

use std::borrow::Borrow;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::error::{counted, Error, Result};
use crate::integrate::{check_step, Integrator, Lanes, Precision, CANCEL_CHECK_STEPS, LANES};
use crate::limits::{check_batch_step, MAX_BATCH_ROWS};
use crate::network::{Network, Params};
use crate::spin;
use crate::vector::Elem;

/// Block-steps (blocks x N x N x substeps) from which a step runs its blocks on all cores; below
/// it, handing the blocks to the thread pool costs more than it saves.
const PARALLEL_WORK: usize = 1 << 14;

/// Block-steps from which a smaller step shares its blocks with the spinning helpers of
/// [`spin`], which are awake between the steps of a closed loop; below it, a step is over
/// before a helper would have taken its first chunk.
const SPIN_WORK: usize = 1 << 8;

/// `P` networks times `E` replicas, stepped together one input row per call.
///
/// # Example
/// ```
/// use ctrnn::{Batch, Integrator, Network};
/// let net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None)?;
/// let mut batch = Batch::new(&[net], 2, Integrator::default())?;
/// let mut rates = vec![0.0; batch.rows() * batch.size()];
/// // Row 1 senses 1, row 0 senses 0; only row 1 is stepped.
/// batch.step(&[0.0, 1.0], Some(&[false, true]), &mut rates, None)?;
/// assert_eq!(batch.states(), vec![0.0, 0.1]);
/// # Ok::<(), ctrnn::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Batch {
    size: usize,
    n_inputs: usize,
    replicas: usize,
    integ: Integrator,
    networks: Vec<Network>,
    /// The network each row runs, an index into `networks`.
    network_of: Vec<usize>,
    /// The blocks, in the precision the batch computes in.
    store: Store,
    /// The lanes of each block that take part in the current step, one bit per lane.
    on: Vec<u32>,
    /// The row in each lane, `row_at[b * LANES + l]`, and each row's lane, `lane_of[row]`.
    row_at: Vec<usize>,
    lane_of: Vec<usize>,
}

/// A batch's blocks in the precision it computes in.
#[derive(Clone, Debug)]
enum Store {
    F64(Blocks<f64>),
    F32(Blocks<f32>),
}

/// Runs `$body` with `$b` bound to the [`Blocks`] of `$store`, whatever their precision.
macro_rules! with_blocks {
    ($store:expr, $b:ident => $body:expr) => {
        match $store {
            Store::F64($b) => $body,
            Store::F32($b) => $body,
        }
    };
}

/// Blocks of [`LANES`] rows and their work arrays, reused from step to step so that a step
/// allocates nothing.
#[derive(Clone, Debug)]
struct Blocks<E: Elem> {
    blocks: Vec<Lanes<LANES, E>>,
    slots: Vec<Slot<E>>,
}

impl<E: Elem> Blocks<E> {
    fn empty() -> Self {
        Blocks {
            blocks: Vec::new(),
            slots: Vec::new(),
        }
    }
}

/// One block's work arrays.
#[derive(Clone, Debug)]
struct Slot<E> {
    /// The inputs of the step, `[sensor][lane]`.
    inputs: Vec<[E; LANES]>,
    /// The states of the lanes left out of the step, lane by lane.
    kept: Vec<E>,
}

impl Batch {
    /// `replicas` rows for each of `networks` (at least one, all of the same N and M), each
    /// starting from its network's state, stepped with `integ`.
    pub fn new<N: Borrow<Network>>(
        networks: &[N],
        replicas: usize,
        integ: Integrator,
    ) -> Result<Self> {
        let rows = (networks.len() as u128).saturating_mul(replicas as u128);
        Self::with_rows(
            networks,
            replicas,
            usize::try_from(rows).unwrap_or(usize::MAX),
            integ,
        )
    }

    /// `rows` rows (at least one, at most `networks.len() * replicas`) for `replicas` episodes of
    /// each of `networks`: row `r` starts as replica `r % replicas` of network `r / replicas`,
    /// as in [`Batch::new`], which holds every replica. [`Batch::assign`] then gives a row to
    /// another network.
    pub fn with_rows<N: Borrow<Network>>(
        networks: &[N],
        replicas: usize,
        rows: usize,
        integ: Integrator,
    ) -> Result<Self> {
        Self::with_rows_in(networks, replicas, rows, integ, Precision::F64)
    }

    /// [`Batch::with_rows`] computing in `precision`. In [`Precision::F32`] each row's
    /// parameters and state are rounded to `f32` when it is packed, each input and each state
    /// set when it is read; states and rates are the `f32` values widened (exactly) to `f64`.
    ///
    /// # Example
    /// ```
    /// use ctrnn::{Batch, Integrator, Network, Precision};
    /// let net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None)?;
    /// let mut batch = Batch::with_rows_in(&[net], 1, 1, Integrator::default(), Precision::F32)?;
    /// let mut rates = vec![0.0];
    /// batch.step(&[1.0], None, &mut rates, None)?;
    /// batch.step(&[1.0], None, &mut rates, None)?;
    /// // v += 0.1 * (-v + 1) in f32: 0.1, then 0.19, widened to f64.
    /// assert_eq!(batch.states(), [(0.1f32 + 0.1f32 * (1.0 - 0.1f32)) as f64]);
    /// assert_eq!(batch.precision(), Precision::F32);
    /// # Ok::<(), ctrnn::Error>(())
    /// ```
    pub fn with_rows_in<N: Borrow<Network>>(
        networks: &[N],
        replicas: usize,
        rows: usize,
        integ: Integrator,
        precision: Precision,
    ) -> Result<Self> {
        integ.validate()?;
        if replicas == 0 {
            return Err(Error::InvalidArgument(
                "replicas is 0; a batch needs at least 1 replica per network".into(),
            ));
        }
        if networks.is_empty() {
            return Err(Error::InvalidArgument(
                "a batch needs at least 1 network".into(),
            ));
        }
        let params: Vec<Params> = networks.iter().map(|n| n.borrow().params()).collect();
        check_step(&params, &integ)?;
        let all = (networks.len() as u128).saturating_mul(replicas as u128);
        if rows as u128 > MAX_BATCH_ROWS {
            let what = if rows as u128 == all {
                format!(
                    "{} networks x {replicas} replicas make {all} rows",
                    networks.len()
                )
            } else {
                format!("rows is {rows}")
            };
            return Err(Error::InvalidArgument(format!(
                "{what}; the limit is {MAX_BATCH_ROWS} (2^24)"
            )));
        }
        if rows == 0 || rows as u128 > all {
            return Err(Error::InvalidArgument(format!(
                "rows is {rows}; expected 1 to networks x replicas = {all}"
            )));
        }
        let networks: Vec<Network> = networks.iter().map(|n| n.borrow().clone()).collect();
        let first = &networks[0];
        let (n, m) = (first.size(), first.n_inputs());
        if let Some(p) = networks
            .iter()
            .position(|x| (x.size(), x.n_inputs()) != (n, m))
        {
            return Err(Error::InvalidArgument(format!(
                "network {p} has N = {}, M = {}; every network of a batch must have N = {n}, M = {m}",
                networks[p].size(),
                networks[p].n_inputs()
            )));
        }
        let mut batch = Batch {
            size: n,
            n_inputs: m,
            replicas,
            integ,
            networks,
            network_of: (0..rows).map(|r| r / replicas).collect(),
            // Empty until packed below, in the precision asked for.
            store: match precision {
                Precision::F64 => Store::F64(Blocks::empty()),
                Precision::F32 => Store::F32(Blocks::empty()),
            },
            on: vec![0; rows.div_ceil(LANES)],
            row_at: (0..rows).collect(),
            lane_of: (0..rows).collect(),
        };
        batch.store = batch.pack(&batch.row_at, None)?;
        Ok(batch)
    }

    /// The precision it computes in.
    pub fn precision(&self) -> Precision {
        match self.store {
            Store::F64(_) => Precision::F64,
            Store::F32(_) => Precision::F32,
        }
    }

    /// Rows B: networks x replicas, or as many as [`Batch::with_rows`] was given.
    pub fn rows(&self) -> usize {
        self.row_at.len()
    }
    /// Networks P.
    pub fn networks(&self) -> usize {
        self.networks.len()
    }
    /// Replicas E of each network.
    pub fn replicas(&self) -> usize {
        self.replicas
    }
    /// Neurons per network N.
    pub fn size(&self) -> usize {
        self.size
    }
    /// Sensors per network M.
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }
    /// The integration settings of every step.
    pub fn integrator(&self) -> &Integrator {
        &self.integ
    }

    /// Blocks, in the batch's precision, with the rows of `order` lane by lane, each row's
    /// state taken from `states` (row-major `B x N`), or from its network when `None`.
    fn pack(&self, order: &[usize], states: Option<&[f64]>) -> Result<Store> {
        Ok(match self.store {
            Store::F64(_) => Store::F64(self.pack_as(order, states)?),
            Store::F32(_) => Store::F32(self.pack_as(order, states)?),
        })
    }

    /// [`Batch::pack`] in element type `E`.
    fn pack_as<E: Elem>(&self, order: &[usize], states: Option<&[f64]>) -> Result<Blocks<E>> {
        let (n, m) = (self.size, self.n_inputs);
        let pack = |rows: &[usize]| {
            let refs: Vec<&Network> = rows
                .iter()
                .map(|&r| &self.networks[self.network_of[r]])
                .collect();
            let mut block = Lanes::new(&refs)?;
            if let Some(states) = states {
                for (l, &r) in rows.iter().enumerate() {
                    set_lane_state(&mut block, l, &states[r * n..(r + 1) * n]);
                }
            }
            Ok(block)
        };
        // One block is packed here: a batch that never steps in parallel (a probe, one network)
        // leaves rayon's pool unstarted, so that a caller can still choose its size.
        let blocks = if order.len() <= LANES {
            order.chunks(LANES).map(pack).collect::<Result<Vec<_>>>()?
        } else {
            order
                .par_chunks(LANES)
                .map(pack)
                .collect::<Result<Vec<_>>>()?
        };
        let slot = Slot {
            inputs: vec![[E::default(); LANES]; m],
            kept: vec![E::default(); LANES * n],
        };
        Ok(Blocks {
            slots: vec![slot; blocks.len()],
            blocks,
        })
    }

    /// Moves the rows of `active` (`running` of them) to the first lanes, in row order, when
    /// they are spread over clearly more blocks than they fill.
    fn pack_active(&mut self, active: &[bool], running: usize) -> Result<()> {
        let touched = self.on.iter().filter(|&&on| on != 0).count();
        let needed = running.div_ceil(LANES);
        if touched <= needed + needed / 4 + 1 {
            return Ok(());
        }
        let states = self.states();
        let (on, off): (Vec<usize>, Vec<usize>) = (0..self.rows()).partition(|&r| active[r]);
        let order: Vec<usize> = on.into_iter().chain(off).collect();
        // The blocks first: if packing failed, the batch would be as it was.
        self.store = self.pack(&order, Some(&states))?;
        self.row_at = order;
        for (at, &r) in self.row_at.iter().enumerate() {
            self.lane_of[r] = at;
        }
        self.mark(Some(active));
        Ok(())
    }

    /// Marks the lanes whose row is in `active` (every lane without a mask); returns how many.
    fn mark(&mut self, active: Option<&[bool]>) -> usize {
        let mut running = 0;
        for (on, rows) in self.on.iter_mut().zip(self.row_at.chunks(LANES)) {
            *on = 0;
            for (l, &r) in rows.iter().enumerate() {
                *on |= u32::from(active.is_none_or(|mask| mask[r])) << l;
            }
            running += on.count_ones() as usize;
        }
        running
    }

    /// Fails on the first input of a stepped row that is not finite, in the order of the blocks'
    /// lanes (one pass over `inputs` when every value is finite, as it nearly always is).
    fn check_inputs<T: Copy + Into<f64>>(&self, inputs: &[T]) -> Result<()> {
        if inputs.iter().all(|&x| x.into().is_finite()) {
            return Ok(());
        }
        let m = self.n_inputs;
        for (&on, rows) in self.on.iter().zip(self.row_at.chunks(LANES)) {
            for (l, &r) in rows.iter().enumerate() {
                if on >> l & 1 == 0 {
                    continue;
                }
                for k in 0..m {
                    let x: f64 = inputs[r * m + k].into();
                    if !x.is_finite() {
                        return Err(Error::InvalidArgument(format!(
                            "inputs[{r}, {k}] is {x}; every input of a stepped row must be finite"
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// Holds each row's inputs (row-major `B x M`, any type that widens exactly to `f64`) for
    /// `substeps` integration steps, then writes each stepped row's firing rates `f(v - theta)`
    /// into `rates` (row-major `B x N`). With `active`, rows where it is false keep their state
    /// and their entries of `rates`, and cost nothing once they fill whole blocks: the rows
    /// still running are then moved together.
    ///
    /// Fails, with every state as it was, on arrays of the wrong length or inputs of a stepped
    /// row that are not finite. Fails with [`Error::Interrupted`] soon after `cancel` is set
    /// (between blocks, and every 1024 integration steps within one), and with
    /// [`Error::InvalidArgument`] when a stepped row's integration diverges. Rows left out then
    /// still keep their state and their rates, but the stepped rows' states are part-way through
    /// the step, and their rates may or may not have been written: reset or set them before
    /// stepping again.
    pub fn step<T: Copy + Into<f64> + Sync>(
        &mut self,
        inputs: &[T],
        active: Option<&[bool]>,
        rates: &mut [f64],
        cancel: Option<&AtomicBool>,
    ) -> Result<()> {
        let (rows, n, m) = (self.rows(), self.size, self.n_inputs);
        check_batch_step(rows, self.integ.substeps)?;
        self.check_len("inputs", inputs.len(), rows * m, "B x M")?;
        self.check_len("rates", rates.len(), rows * n, "B x N")?;
        if let Some(mask) = active {
            self.check_len("active", mask.len(), rows, "B")?;
        }
        // Rows left out may hold anything: an ended episode's last observation is not read.
        let running = self.mark(active);
        if let Some(mask) = active {
            self.pack_active(mask, running)?;
        }
        self.check_inputs(inputs)?;
        let shape = StepShape {
            n,
            m,
            integ: self.integ,
        };
        with_blocks!(&mut self.store, b => step_blocks(b, &self.on, &self.row_at, shape, inputs, rates, cancel))
    }

    fn check_len(&self, name: &str, len: usize, want: usize, shape: &str) -> Result<()> {
        if len == want {
            Ok(())
        } else {
            Err(Error::InvalidArgument(format!(
                "{name} has {}; expected {shape} = {want} (B = {}, M = {}, N = {})",
                crate::error::counted(len, "value"),
                self.rows(),
                self.n_inputs,
                self.size
            )))
        }
    }

    /// Every row's state, row-major `B x N` (widened to `f64` in `f32`).
    pub fn states(&self) -> Vec<f64> {
        let n = self.size;
        let mut out = vec![0.0; self.rows() * n];
        with_blocks!(&self.store, b => {
            for (r, &at) in self.lane_of.iter().enumerate() {
                let block = &b.blocks[at / LANES];
                for (i, into) in out[r * n..(r + 1) * n].iter_mut().enumerate() {
                    *into = block.state(i)[at % LANES].to_f64();
                }
            }
        });
        out
    }

    /// Every row's firing rates `f(v - theta)`, row-major `B x N` (widened to `f64` in `f32`).
    pub fn rates(&mut self) -> Vec<f64> {
        let n = self.size;
        let mut out = vec![0.0; self.rows() * n];
        with_blocks!(&mut self.store, b => {
            for (k, block) in b.blocks.iter_mut().enumerate() {
                let lanes = block.len();
                let rates = block.outputs();
                for l in 0..lanes {
                    let r = self.row_at[k * LANES + l];
                    for (i, rate) in rates.iter().enumerate() {
                        out[r * n + i] = rate[l].to_f64();
                    }
                }
            }
        });
        out
    }

    /// Sets the state of the rows where `rows` is true (every row without a mask) from
    /// `states` (row-major `B x N`, finite; other rows' values are not read).
    pub fn set_states(&mut self, states: &[f64], rows: Option<&[bool]>) -> Result<()> {
        let (b_len, n) = (self.rows(), self.size);
        self.check_len("states", states.len(), b_len * n, "B x N")?;
        if let Some(mask) = rows {
            self.check_len("rows", mask.len(), b_len, "B")?;
        }
        let chosen = |r: usize| rows.is_none_or(|mask| mask[r]);
        if let Some(k) = (0..b_len * n).find(|&k| chosen(k / n) && !states[k].is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "states[{}, {}] is {}; every state must be finite",
                k / n,
                k % n,
                states[k]
            )));
        }
        with_blocks!(&mut self.store, b => {
            for (r, &at) in self.lane_of.iter().enumerate() {
                if chosen(r) {
                    set_lane_state(&mut b.blocks[at / LANES], at % LANES, &states[r * n..(r + 1) * n]);
                }
            }
        });
        Ok(())
    }

    /// Sets the state of the rows where `rows` is true (every row without a mask) to zero, as
    /// every built-in task starts a trial.
    pub fn reset(&mut self, rows: Option<&[bool]>) -> Result<()> {
        let zeros = vec![0.0; self.rows() * self.size];
        self.set_states(&zeros, rows)
    }

    /// The network each row runs, as an index into the batch's networks.
    pub fn network_of(&self) -> &[usize] {
        &self.network_of
    }

    /// Gives row `rows[i]` to network `networks[i]` (an index into the batch's networks); the row
    /// then starts from that network's state, as in [`Batch::new`], and every other row keeps its
    /// state. Fails, with the batch as it was, on indices out of range, a row named twice or
    /// slices of different lengths.
    pub fn assign(&mut self, rows: &[usize], networks: &[usize]) -> Result<()> {
        if rows.len() != networks.len() {
            return Err(Error::InvalidArgument(format!(
                "{} and {}; expected one network per row",
                crate::error::counted(rows.len(), "row"),
                crate::error::counted(networks.len(), "network")
            )));
        }
        let (b_len, p_len) = (self.rows(), self.networks.len());
        let mut named = vec![false; b_len];
        for (&r, &p) in rows.iter().zip(networks) {
            if r >= b_len {
                return Err(Error::InvalidArgument(format!(
                    "row {r} is out of range; the batch has {}",
                    counted(b_len, "row")
                )));
            }
            if p >= p_len {
                return Err(Error::InvalidArgument(format!(
                    "network {p} is out of range; the batch has {}",
                    counted(p_len, "network")
                )));
            }
            if std::mem::replace(&mut named[r], true) {
                return Err(Error::InvalidArgument(format!(
                    "row {r} is named twice; a row runs one network"
                )));
            }
        }
        for (&r, &p) in rows.iter().zip(networks) {
            self.network_of[r] = p;
            let at = self.lane_of[r];
            let net = &self.networks[p];
            with_blocks!(&mut self.store, b => b.blocks[at / LANES].set_lane(at % LANES, net))?;
        }
        Ok(())
    }
}

/// The caller's rates (row-major `B x N`), written by the blocks' threads at once, each row by
/// the one block whose lane holds it.
struct RatesOut {
    rates: *mut f64,
    n: usize,
}

// SAFETY: a row sits in exactly one lane of one block (`row_at` is a permutation of the rows), and
// each block is stepped by one thread, so no two threads write the same row.
#[allow(unsafe_code)]
unsafe impl Sync for RatesOut {}

impl RatesOut {
    /// Row `r`'s `N` rates.
    ///
    /// # Safety
    /// `r` is a row of the batch whose `B x N` rates this points at, and no other reference to
    /// that row is alive.
    #[allow(unsafe_code, clippy::mut_from_ref)]
    unsafe fn row(&self, r: usize) -> &mut [f64] {
        unsafe { std::slice::from_raw_parts_mut(self.rates.add(r * self.n), self.n) }
    }
}

/// Sets lane `l`'s state from `state` (N values), rounded to `E`.
fn set_lane_state<E: Elem>(block: &mut Lanes<LANES, E>, l: usize, state: &[f64]) {
    let state: Vec<E> = state.iter().map(|&v| E::from_f64(v)).collect();
    block.set_lane_state(l, &state);
}

/// The sizes and settings of a step.
#[derive(Clone, Copy)]
struct StepShape {
    n: usize,
    m: usize,
    integ: Integrator,
}

/// [`Batch::step`] on blocks of element type `E`, its arrays checked and its lanes marked in
/// `on`: each block with a lane on is stepped, in parallel when the step is big enough.
fn step_blocks<E: Elem, T: Copy + Into<f64> + Sync>(
    store: &mut Blocks<E>,
    on: &[u32],
    row_at: &[usize],
    shape: StepShape,
    inputs: &[T],
    rates: &mut [f64],
    cancel: Option<&AtomicBool>,
) -> Result<()> {
    let StepShape { n, m, integ } = shape;
    let out = RatesOut {
        rates: rates.as_mut_ptr(),
        n,
    };
    let out = &out;
    let work = |b: usize, block: &mut Lanes<LANES, E>, slot: &mut Slot<E>| {
        let on = on[b];
        if on == 0 {
            return Ok(());
        }
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return Err(Error::Interrupted);
        }
        let lanes = block.len();
        let rows = &row_at[b * LANES..b * LANES + lanes];
        let off = |l: usize| on >> l & 1 == 0;
        // The inputs of the stepping lanes; 0 in the others.
        for (k, sensor) in slot.inputs.iter_mut().enumerate() {
            for (l, &r) in rows.iter().enumerate() {
                sensor[l] = if off(l) {
                    E::default()
                } else {
                    E::from_f64(inputs[r * m + k].into())
                };
            }
            sensor[lanes..].fill(E::default());
        }
        for l in (0..lanes).filter(|&l| off(l)) {
            block.lane_state(l, &mut slot.kept[l * n..(l + 1) * n]);
        }
        let stepped = step_held_in_chunks(block, &slot.inputs, &integ, cancel)
            .and_then(|()| check_finite(block, |l| (!off(l)).then(|| rows[l])));
        // Rows left out keep their state, whatever happened to the others.
        for l in (0..lanes).filter(|&l| off(l)) {
            block.set_lane_state(l, &slot.kept[l * n..(l + 1) * n]);
        }
        stepped?;
        let lane_rates = block.outputs();
        for (l, &r) in rows.iter().enumerate().filter(|&(l, _)| !off(l)) {
            // SAFETY: `r < B` and `rates` holds `B x N` values; a row sits in one lane of
            // one block, and each block is stepped by one thread, so no other reference to
            // this row's rates is alive.
            #[allow(unsafe_code)]
            let row = unsafe { out.row(r) };
            for (x, rate) in row.iter_mut().zip(lane_rates) {
                *x = rate[l].to_f64();
            }
        }
        Ok(())
    };
    let busy = on.iter().filter(|&&on| on != 0).count();
    let amount = busy * n * n * integ.substeps;
    let Blocks { blocks, slots } = store;
    if amount >= PARALLEL_WORK && busy > 1 {
        // The lowest failing block's error, as in order: not whichever thread failed first.
        let failed = blocks
            .par_iter_mut()
            .zip(slots.par_iter_mut())
            .enumerate()
            .filter_map(|(b, (block, slot))| work(b, block, slot).err().map(|e| (b, e)))
            .min_by_key(|&(b, _)| b);
        if let Some((_, e)) = failed {
            return Err(e);
        }
    } else if amount >= SPIN_WORK && busy > 1 {
        spin::try_for_each_zip(blocks, slots, work)?;
    } else {
        blocks
            .iter_mut()
            .zip(slots.iter_mut())
            .enumerate()
            .try_for_each(|(b, (block, slot))| work(b, block, slot))?;
    }
    Ok(())
}

/// One input row held for `integ.substeps` steps, taken [`CANCEL_CHECK_STEPS`] at a time with a
/// look at `cancel` in between (holding the inputs gives the same bits as one long row).
fn step_held_in_chunks<E: Elem>(
    block: &mut Lanes<LANES, E>,
    inputs: &[[E; LANES]],
    integ: &Integrator,
    cancel: Option<&AtomicBool>,
) -> Result<()> {
    let cancelled = || cancel.is_some_and(|c| c.load(Ordering::Relaxed));
    let chunk = |substeps: usize| Integrator { substeps, ..*integ };
    let mut left = integ.substeps;
    let first = left.min(CANCEL_CHECK_STEPS);
    block.step_row(inputs, &chunk(first));
    left -= first;
    while left > 0 {
        if cancelled() {
            return Err(Error::Interrupted);
        }
        let now = left.min(CANCEL_CHECK_STEPS);
        block.step_held(&chunk(now));
        left -= now;
    }
    Ok(())
}

/// Fails when a stepped lane's state is no longer finite (an Euler step with `dt / tau > 2`);
/// `row(l)` is the row in lane `l` if it was stepped.
fn check_finite<E: Elem>(
    block: &Lanes<LANES, E>,
    row: impl Fn(usize) -> Option<usize>,
) -> Result<()> {
    for i in 0..block.size() {
        let state = block.state(i);
        if state.iter().all(|v| v.finite()) {
            continue;
        }
        for l in 0..block.len() {
            if let Some(r) = row(l).filter(|_| !state[l].finite()) {
                return Err(block.diverged(&format!("row {r}"), i, l));
            }
        }
    }
    Ok(())
}
