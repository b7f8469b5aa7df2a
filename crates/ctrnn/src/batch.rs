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
//! same kernel in the same order of operations.

use std::borrow::Borrow;
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::integrate::{Integrator, CANCEL_CHECK_STEPS, LANES};
use crate::limits::{check_work, MAX_BATCH_ROWS};
use crate::network::Network;
use crate::population::Block;
use crate::spin;

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
    blocks: Vec<Block>,
    /// Each block's work arrays, reused from step to step so that a step allocates nothing.
    slots: Vec<Slot>,
    /// The row in each lane, `row_at[b * LANES + l]`, and each row's lane, `lane_of[row]`.
    row_at: Vec<usize>,
    lane_of: Vec<usize>,
}

/// One block's work arrays.
#[derive(Clone, Debug)]
struct Slot {
    /// The lanes that take part in the current step, one bit per lane.
    on: u32,
    /// The inputs of the step, `[sensor][lane]`.
    inputs: Vec<[f64; LANES]>,
    /// The states of the lanes left out of the step, lane by lane.
    kept: Vec<f64>,
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
        let slot = Slot {
            on: 0,
            inputs: vec![[0.0; LANES]; m],
            kept: vec![0.0; LANES * n],
        };
        let mut batch = Batch {
            size: n,
            n_inputs: m,
            replicas,
            integ,
            networks,
            network_of: (0..rows).map(|r| r / replicas).collect(),
            blocks: Vec::new(),
            slots: vec![slot; rows.div_ceil(LANES)],
            row_at: (0..rows).collect(),
            lane_of: (0..rows).collect(),
        };
        batch.blocks = batch.pack(&batch.row_at, None)?;
        Ok(batch)
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

    /// Blocks with the rows of `order` lane by lane, each row's state taken from `states`
    /// (row-major `B x N`), or from its network when `None`.
    fn pack(&self, order: &[usize], states: Option<&[f64]>) -> Result<Vec<Block>> {
        let n = self.size;
        order
            .par_chunks(LANES)
            .map(|rows| {
                let refs: Vec<&Network> = rows
                    .iter()
                    .map(|&r| &self.networks[self.network_of[r]])
                    .collect();
                let mut block = Block::new(&refs)?;
                if let Some(states) = states {
                    for (l, &r) in rows.iter().enumerate() {
                        block.set_lane_state(l, &states[r * n..(r + 1) * n]);
                    }
                }
                Ok(block)
            })
            .collect()
    }

    /// Moves the rows of `active` (`running` of them) to the first lanes, in row order, when
    /// they are spread over clearly more blocks than they fill.
    fn pack_active(&mut self, active: &[bool], running: usize) -> Result<()> {
        let touched = self.slots.iter().filter(|s| s.on != 0).count();
        let needed = running.div_ceil(LANES);
        if touched <= needed + needed / 4 + 1 {
            return Ok(());
        }
        let states = self.states();
        let (on, off): (Vec<usize>, Vec<usize>) = (0..self.rows()).partition(|&r| active[r]);
        let order: Vec<usize> = on.into_iter().chain(off).collect();
        // The blocks first: if packing failed, the batch would be as it was.
        self.blocks = self.pack(&order, Some(&states))?;
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
        for (slot, rows) in self.slots.iter_mut().zip(self.row_at.chunks(LANES)) {
            slot.on = 0;
            for (l, &r) in rows.iter().enumerate() {
                slot.on |= u32::from(active.is_none_or(|mask| mask[r])) << l;
            }
            running += slot.on.count_ones() as usize;
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
        for (slot, rows) in self.slots.iter().zip(self.row_at.chunks(LANES)) {
            for (l, &r) in rows.iter().enumerate() {
                if slot.on >> l & 1 == 0 {
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
        check_work(rows, 1, self.integ.substeps)?;
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
        let integ = self.integ;
        let row_at = &self.row_at;
        let out = RatesOut {
            rates: rates.as_mut_ptr(),
            n,
        };
        let out = &out;
        let work = |b: usize, block: &mut Block, slot: &mut Slot| {
            if slot.on == 0 {
                return Ok(());
            }
            if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                return Err(Error::Interrupted);
            }
            let lanes = block.len();
            let rows = &row_at[b * LANES..b * LANES + lanes];
            let off = |l: usize| slot.on >> l & 1 == 0;
            // The inputs of the stepping lanes; 0 in the others.
            for (k, sensor) in slot.inputs.iter_mut().enumerate() {
                for (l, &r) in rows.iter().enumerate() {
                    sensor[l] = if off(l) {
                        0.0
                    } else {
                        inputs[r * m + k].into()
                    };
                }
                sensor[lanes..].fill(0.0);
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
                    *x = rate[l];
                }
            }
            Ok(())
        };
        let busy = self.slots.iter().filter(|s| s.on != 0).count();
        let amount = busy * n * n * integ.substeps;
        if amount >= PARALLEL_WORK && busy > 1 {
            // The lowest failing block's error, as in order: not whichever thread failed first.
            let failed = self
                .blocks
                .par_iter_mut()
                .zip(self.slots.par_iter_mut())
                .enumerate()
                .filter_map(|(b, (block, slot))| work(b, block, slot).err().map(|e| (b, e)))
                .min_by_key(|&(b, _)| b);
            if let Some((_, e)) = failed {
                return Err(e);
            }
        } else if amount >= SPIN_WORK && busy > 1 {
            spin::try_for_each_zip(&mut self.blocks, &mut self.slots, work)?;
        } else {
            self.blocks
                .iter_mut()
                .zip(self.slots.iter_mut())
                .enumerate()
                .try_for_each(|(b, (block, slot))| work(b, block, slot))?;
        }
        Ok(())
    }

    fn check_len(&self, name: &str, len: usize, want: usize, shape: &str) -> Result<()> {
        if len == want {
            Ok(())
        } else {
            Err(Error::InvalidArgument(format!(
                "{name} has {len} values; expected {shape} = {want} (B = {}, M = {}, N = {})",
                self.rows(),
                self.n_inputs,
                self.size
            )))
        }
    }

    /// Every row's state, row-major `B x N`.
    pub fn states(&self) -> Vec<f64> {
        let n = self.size;
        let mut out = vec![0.0; self.rows() * n];
        for (r, &at) in self.lane_of.iter().enumerate() {
            self.blocks[at / LANES].lane_state(at % LANES, &mut out[r * n..(r + 1) * n]);
        }
        out
    }

    /// Every row's firing rates `f(v - theta)`, row-major `B x N`.
    pub fn rates(&mut self) -> Vec<f64> {
        let n = self.size;
        let mut out = vec![0.0; self.rows() * n];
        for (b, block) in self.blocks.iter_mut().enumerate() {
            let lanes = block.len();
            let rates = block.outputs();
            for l in 0..lanes {
                let r = self.row_at[b * LANES + l];
                for (i, rate) in rates.iter().enumerate() {
                    out[r * n + i] = rate[l];
                }
            }
        }
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
        for (r, &at) in self.lane_of.iter().enumerate() {
            if chosen(r) {
                self.blocks[at / LANES].set_lane_state(at % LANES, &states[r * n..(r + 1) * n]);
            }
        }
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
                "{} rows and {} networks; expected one network per row",
                rows.len(),
                networks.len()
            )));
        }
        let (b_len, p_len) = (self.rows(), self.networks.len());
        let mut named = vec![false; b_len];
        for (&r, &p) in rows.iter().zip(networks) {
            if r >= b_len {
                return Err(Error::InvalidArgument(format!(
                    "row {r} is out of range; the batch has {b_len} rows"
                )));
            }
            if p >= p_len {
                return Err(Error::InvalidArgument(format!(
                    "network {p} is out of range; the batch has {p_len} networks"
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
            self.blocks[at / LANES].set_lane(at % LANES, &self.networks[p])?;
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

/// One input row held for `integ.substeps` steps, taken [`CANCEL_CHECK_STEPS`] at a time with a
/// look at `cancel` in between (holding the inputs gives the same bits as one long row).
fn step_held_in_chunks(
    block: &mut Block,
    inputs: &[[f64; LANES]],
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
fn check_finite(block: &Block, row: impl Fn(usize) -> Option<usize>) -> Result<()> {
    for i in 0..block.size() {
        let state = block.state(i);
        if state.iter().all(|v| v.is_finite()) {
            continue;
        }
        for l in 0..block.len() {
            if let Some(r) = row(l).filter(|_| !state[l].is_finite()) {
                return Err(Error::InvalidArgument(format!(
                    "integration diverged: state[{i}] of row {r} became {}; use a smaller dt \
                     (Euler needs dt / tau well below 2)",
                    state[l]
                )));
            }
        }
    }
    Ok(())
}
