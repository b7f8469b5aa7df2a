//! [`Lanes`]: `L` networks of the same shape packed parameter by parameter, side by side, and
//! stepped together by the kernel, in `f64` (the default) or in `f32`.

use std::any::Any;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::error::{Error, Result};
use crate::math::sigmoid_of;
use crate::network::{Network, Params};
use crate::rows::Rows;
use crate::simd::{self, Kernel};
#[cfg(target_arch = "x86_64")]
use crate::vector::{avx2, avx512};
use crate::vector::{Elem, Portable, Vector};

use super::kernel::{rates, weight_order, Work};
use super::settings::short;
use super::{Integrator, Method};

/// How many networks a population block steps together: two AVX-512 registers of f64, four
/// AVX2 ones or eight NEON ones, so that every row of the kernel has independent dependency chains in flight.
pub const LANES: usize = 16;
const _: () = assert!(
    LANES == 16,
    "with_backend's register groups assume 16 lanes"
);

/// Integration steps (rows times substeps) between two looks at the cancel flag, so that Ctrl-C
/// is seen within milliseconds however many substeps a row has.
pub(crate) const CANCEL_CHECK_STEPS: usize = 1024;

/// Calls `self.method::<V>(args)` with `V` the lane vector type of `kernel` for `L` lanes of
/// `E`: registers of the kernel for a block of [`LANES`] ([`Elem`] names them), plain lanes for
/// any other width (a single network, the tests' odd widths). Either way the code is compiled
/// for the kernel's CPU features (so plain lanes get hardware fused multiply-adds too). The
/// widths are `const` conditions, so the arms a width does not take are never compiled.
macro_rules! with_backend {
    ($kernel:expr, $self:ident . $method:ident ( $($arg:expr),* )) => {{
        match $kernel {
            // The closures are always inlined into `enabled`, which compiles them, and the kernel
            // in them, for the kernel's features.
            // SAFETY (both): `simd` only hands out kernels that the CPU supports.
            #[cfg(target_arch = "x86_64")]
            #[allow(unsafe_code)]
            Kernel::Avx512 => unsafe {
                avx512::enabled(#[inline(always)] || {
                    if const { L == LANES } {
                        $self.$method::<E::Avx512Block>($($arg),*)
                    } else {
                        $self.$method::<Portable<L, E>>($($arg),*)
                    }
                })
            },
            #[cfg(target_arch = "x86_64")]
            #[allow(unsafe_code)]
            Kernel::Avx2 => unsafe {
                avx2::enabled(#[inline(always)] || {
                    if const { L == LANES } {
                        $self.$method::<E::Avx2Block>($($arg),*)
                    } else {
                        $self.$method::<Portable<L, E>>($($arg),*)
                    }
                })
            },
            // NEON is part of every AArch64 CPU: no features to enable.
            #[cfg(target_arch = "aarch64")]
            Kernel::Neon => {
                if const { L == LANES } {
                    $self.$method::<E::NeonBlock>($($arg),*)
                } else {
                    $self.$method::<Portable<L, E>>($($arg),*)
                }
            }
            _ => $self.$method::<Portable<L, E>>($($arg),*),
        }
    }};
}

/// `L` networks of the same shape, laid out for stepping together, computing in `E`: `f64`
/// (the default and the reference), or `f32`, single precision, where the parameters are rounded
/// to `f32` once, when packed, and every state, rate and step is `f32`.
///
/// This is the kernel's own type, and its stepping methods trust their caller for speed: the
/// inputs must have one row per sensor, the integrator must be valid ([`Integrator::validate`])
/// and a lane index below `L`; a wrong call may panic or give wrong states, and the states are
/// checked only by [`Lanes::check_finite`]. [`Network::run`](crate::Network::run),
/// [`Population`](crate::Population) and [`Batch`](crate::Batch) check everything first.
#[derive(Clone, Debug)]
pub struct Lanes<const L: usize, E: Elem = f64> {
    size: usize,
    n_inputs: usize,
    len: usize,
    tau: Rows<L, E>,
    theta: Rows<L, E>,
    weights: Rows<L, E>,
    sensor_weights: Rows<L, E>,
    state: Rows<L, E>,
    scratch: Scratch<L, E>,
}

/// Work arrays, reused from step to step so that stepping allocates nothing.
#[derive(Clone, Debug)]
struct Scratch<const L: usize, E: Elem> {
    dt: f64,
    /// The method of the last step, for a divergence's message.
    method: Method,
    /// dt / tau, and its half and sixth for RK4.
    h: Rows<L, E>,
    h2: Rows<L, E>,
    h6: Rows<L, E>,
    /// Sensor drive S I of the current row.
    ext: Rows<L, E>,
    /// Whether `ext` is the sensor drive of the last [`Lanes::step_row`], for
    /// [`Lanes::step_held`].
    held: bool,
    /// Firing rates.
    out: Rows<L, E>,
    /// Whether `out` holds the firing rates of the current state, computed by
    /// [`Lanes::outputs`]; the next step then starts from them instead of computing them again.
    fresh: bool,
    /// RK4's first three slopes (the fourth is used as soon as it is known).
    k: [Rows<L, E>; 3],
    probe: Rows<L, E>,
}

impl<const L: usize, E: Elem> Lanes<L, E> {
    /// Packs up to `L` networks of the same shape. Unused lanes repeat the first network, so they
    /// stay finite; their results are ignored.
    pub fn new(nets: &[&Network]) -> Result<Self> {
        let params: Vec<Params> = nets.iter().map(|net| net.params()).collect();
        Self::from_params(&params)
    }

    /// [`new`](Self::new) from borrowed parameters, which must be valid ([`Params::validate`]).
    pub(crate) fn from_params(nets: &[Params]) -> Result<Self> {
        let first = nets.first().ok_or_else(|| {
            Error::InvalidArgument("a population needs at least 1 network".into())
        })?;
        if nets.len() > L {
            return Err(Error::InvalidArgument(format!(
                "{} networks do not fit in {L} lanes",
                nets.len()
            )));
        }
        let (n, m) = (first.size(), first.n_inputs());
        for (p, net) in nets.iter().enumerate() {
            if (net.size(), net.n_inputs()) != (n, m) {
                return Err(Error::InvalidArgument(format!(
                    "network {p} has N = {}, M = {}; every network of a population must have N = {n}, M = {m}",
                    net.size(),
                    net.n_inputs()
                )));
            }
        }
        // Row r of an array holds value order[r] of every network; padding lanes repeat the first.
        let gather = |get: for<'p> fn(&Params<'p>) -> &'p [f64], order: &[usize]| {
            let mut rows = Rows::<L, E>::zeros(order.len());
            for l in 0..L {
                let source = get(nets.get(l).unwrap_or(first));
                for (row, &q) in rows.iter_mut().zip(order) {
                    row[l] = E::from_f64(source[q]);
                }
            }
            rows
        };
        let identity = |len: usize| (0..len).collect::<Vec<_>>();
        let (neurons, sensors) = (identity(n), identity(n * m));
        let weights: Vec<usize> = weight_order(n).collect();
        let zeros = Rows::zeros;
        Ok(Lanes {
            size: n,
            n_inputs: m,
            len: nets.len(),
            tau: gather(|p| p.tau, &neurons),
            theta: gather(|p| p.theta, &neurons),
            weights: gather(|p| p.weights, &weights),
            sensor_weights: gather(|p| p.sensor_weights, &sensors),
            state: gather(|p| p.state, &neurons),
            scratch: Scratch {
                dt: f64::NAN,
                method: Method::Euler,
                h: zeros(n),
                h2: zeros(n),
                h6: zeros(n),
                ext: zeros(n),
                held: false,
                out: zeros(n),
                fresh: false,
                k: [zeros(n), zeros(n), zeros(n)],
                probe: zeros(n),
            },
        })
    }

    /// Number of real (not padding) networks.
    pub fn len(&self) -> usize {
        self.len
    }
    /// Whether there are no real networks (never true for a constructed value).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Neurons per network.
    pub fn size(&self) -> usize {
        self.size
    }
    /// Sensors per network.
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }

    /// State of neuron `i` in every lane.
    pub fn state(&self, i: usize) -> &[E; L] {
        &self.state[i]
    }
    /// Firing rate `f(v_i - theta_i)` of neuron `i` in every lane.
    pub fn output(&self, i: usize) -> [E; L] {
        std::array::from_fn(|l| sigmoid_of(self.state[i][l] - self.theta[i][l]))
    }
    /// Every neuron's firing rate in every lane, `outputs()[i][l] = f(v_i - theta_i)`, with the
    /// same bits as [`output`](Self::output). Computed once per state, in the lane vectors of a
    /// step; the next step starts from these rates instead of computing them again, so reading
    /// them after every step costs nothing.
    ///
    /// # Example
    /// ```
    /// use ctrnn::{Integrator, Lanes, Network};
    /// let net = Network::new(vec![1.0], vec![0.5], vec![0.0], vec![1.0], None).unwrap();
    /// let mut lanes = Lanes::<1>::new(&[&net]).unwrap();
    /// lanes.step_row(&[[1.0]], &Integrator::default());
    /// let one = lanes.output(0);
    /// assert_eq!(lanes.outputs()[0], one);
    /// ```
    pub fn outputs(&mut self) -> &[[E; L]] {
        if !self.scratch.fresh {
            self.compute_outputs();
            self.scratch.fresh = true;
        }
        &self.scratch.out
    }

    /// [`outputs`](Self::outputs)' rates, through the shared copy of this width if there is one.
    fn compute_outputs(&mut self) {
        if const { L == LANES && !E::SINGLE } {
            shared::<L, LANES, E>(self).compute_outputs_once();
        } else if const { L == 1 && !E::SINGLE } {
            shared::<L, 1, E>(self).compute_outputs_once();
        } else {
            self.compute_outputs_on(simd::kernel());
        }
    }

    #[inline(always)]
    fn compute_outputs_on(&mut self, kernel: Kernel) {
        with_backend!(kernel, self.compute_outputs_with())
    }

    #[inline(always)]
    fn compute_outputs_with<V: Vector<Elem = E>>(&mut self) {
        rates::<V>(
            V::rows(self.theta.as_flattened()),
            V::rows(self.state.as_flattened()),
            V::rows_mut(self.scratch.out.as_flattened_mut()),
        );
    }

    /// Sets every lane's state to zero.
    pub fn reset(&mut self) {
        self.scratch.fresh = false;
        self.state.fill([E::default(); L]);
    }
    /// Sets the state of lane `l` (length N).
    pub fn set_lane_state(&mut self, l: usize, state: &[E]) {
        self.scratch.fresh = false;
        for (row, &v) in self.state.iter_mut().zip(state) {
            row[l] = v;
        }
    }
    /// Puts network `net` (of this block's N and M) in real lane `l`, parameters and state,
    /// as [`Lanes::new`] would have; the other lanes are unchanged.
    pub fn set_lane(&mut self, l: usize, net: &Network) -> Result<()> {
        if l >= self.len || (net.size(), net.n_inputs()) != (self.size, self.n_inputs) {
            return Err(Error::InvalidArgument(format!(
                "lane {l} of {} cannot take a network of N = {}, M = {} (the block's: N = {}, M = {})",
                self.len,
                net.size(),
                net.n_inputs(),
                self.size,
                self.n_inputs
            )));
        }
        let put =
            |rows: &mut Rows<L, E>, source: &[f64], order: &mut dyn Iterator<Item = usize>| {
                for (row, q) in rows.iter_mut().zip(order) {
                    row[l] = E::from_f64(source[q]);
                }
            };
        let n = self.size;
        put(&mut self.tau, net.tau(), &mut (0..n));
        put(&mut self.theta, net.theta(), &mut (0..n));
        put(&mut self.weights, net.weights(), &mut weight_order(n));
        put(
            &mut self.sensor_weights,
            net.sensor_weights(),
            &mut (0..n * self.n_inputs),
        );
        put(&mut self.state, net.state(), &mut (0..n));
        // The step sizes dt / tau and the rates are computed again at the next step.
        self.scratch.dt = f64::NAN;
        self.scratch.fresh = false;
        self.scratch.held = false;
        Ok(())
    }
    /// Copies the state of lane `l` into `into` (length N).
    pub fn lane_state(&self, l: usize, into: &mut [E]) {
        copy_lane(&self.state, l, into);
    }

    /// Makes the step sizes match `integ`'s `dt`.
    #[inline(always)]
    pub(super) fn prepare(&mut self, integ: &Integrator) {
        self.scratch.method = integ.method;
        if self.scratch.dt.to_bits() != integ.dt.to_bits() {
            self.set_step_sizes(integ.dt);
        }
    }

    /// In `f32`, `dt` is rounded to `f32` first and the step sizes are computed in `f32`.
    #[cold]
    fn set_step_sizes(&mut self, dt: f64) {
        let s = &mut self.scratch;
        s.dt = dt;
        let (dt, half, six) = (E::from_f64(dt), E::from_f64(0.5), E::from_f64(6.0));
        for i in 0..self.size {
            for l in 0..L {
                let h = dt / self.tau[i][l];
                s.h[i][l] = h;
                s.h2[i][l] = half * h;
                s.h6[i][l] = h / six;
            }
        }
    }

    /// Holds `inputs` (one `[E; L]` per sensor) for `integ.substeps` steps of `integ.dt`.
    /// `integ` must be valid.
    #[inline(always)]
    pub fn step_row(&mut self, inputs: &[[E; L]], integ: &Integrator) {
        debug_assert_eq!(inputs.len(), self.n_inputs);
        self.advance(Some(inputs), integ);
    }

    /// [`step_row`](Self::step_row) on a given kernel, which the CPU must support.
    pub(crate) fn step_row_on(&mut self, kernel: Kernel, inputs: &[[E; L]], integ: &Integrator) {
        self.advance_by(kernel, Some(inputs), integ);
    }

    /// One row of `integ.substeps` steps: with `inputs`, from their sensor drive; without, from
    /// the sensor drive held since the last row.
    #[inline(always)]
    fn advance(&mut self, inputs: Option<&[[E; L]]>, integ: &Integrator) {
        self.advance_by(simd::kernel(), inputs, integ);
    }

    /// [`advance`](Self::advance) on a given kernel, through the shared copy of its width if
    /// there is one.
    #[inline(always)]
    fn advance_by(&mut self, kernel: Kernel, inputs: Option<&[[E; L]]>, integ: &Integrator) {
        if const { L == LANES && !E::SINGLE } {
            shared::<L, LANES, E>(self).advance_once(kernel, inputs.map(as_rows), integ);
        } else if const { L == 1 && !E::SINGLE } {
            shared::<L, 1, E>(self).advance_once(kernel, inputs.map(as_rows), integ);
        } else {
            self.advance_on(kernel, inputs, integ);
        }
    }

    /// [`advance`](Self::advance) on a given kernel, which the CPU must support.
    #[inline(always)]
    fn advance_on(&mut self, kernel: Kernel, inputs: Option<&[[E; L]]>, integ: &Integrator) {
        self.prepare(integ);
        with_backend!(kernel, self.advance_with(inputs, integ))
    }

    #[inline(always)]
    fn advance_with<V: Vector<Elem = E>>(&mut self, inputs: Option<&[[E; L]]>, integ: &Integrator) {
        let fresh = std::mem::take(&mut self.scratch.fresh);
        self.scratch.held |= inputs.is_some();
        let (mut work, state) = self.work::<V>();
        work.step(
            V::rows_mut(state.as_flattened_mut()),
            inputs.map(|x| V::rows(x.as_flattened())),
            integ,
            fresh,
        );
    }

    /// [`step_row`](Self::step_row) with the inputs of the last `step_row` call, held: the same
    /// bits, without computing their sensor drive again. A world that moves one integration step
    /// at a time mostly holds its inputs.
    ///
    /// # Panics
    /// If `step_row` has not been called on these lanes, or [`run_rows`](Self::run_rows) has
    /// been called since.
    ///
    /// # Example
    /// ```
    /// use ctrnn::{Integrator, Lanes, Network};
    /// let net = Network::new(vec![1.0], vec![0.5], vec![0.0], vec![1.0], None).unwrap();
    /// let (mut a, integ) = (Lanes::<1>::new(&[&net]).unwrap(), Integrator::default());
    /// let mut b = a.clone();
    /// a.step_row(&[[1.0]], &integ);
    /// a.step_row(&[[1.0]], &integ);
    /// b.step_row(&[[1.0]], &integ);
    /// b.step_held(&integ);
    /// assert_eq!(a.state(0), b.state(0));
    /// ```
    #[inline(always)]
    pub fn step_held(&mut self, integ: &Integrator) {
        assert!(
            self.scratch.held,
            "step_held needs a step_row before it, with no run_rows in between"
        );
        self.advance(None, integ);
    }

    /// Runs `steps` input rows. `row(t, inputs)` fills the sensors of row `t`; after each row
    /// `record(t, state)` may read the state (one `[E; L]` per neuron). Stops with
    /// [`Error::Interrupted`] when `cancel` is set. The states are not checked: call
    /// [`Lanes::check_finite`] after.
    pub fn run_rows(
        &mut self,
        steps: usize,
        integ: &Integrator,
        cancel: Option<&AtomicBool>,
        row: impl FnMut(usize, &mut [[E; L]]),
        record: impl FnMut(usize, &[[E; L]]),
    ) -> Result<()> {
        self.prepare(integ);
        with_backend!(
            simd::kernel(),
            self.run_rows_with(steps, integ, cancel, row, record)
        )
    }

    #[inline(always)]
    fn run_rows_with<V: Vector<Elem = E>>(
        &mut self,
        steps: usize,
        integ: &Integrator,
        cancel: Option<&AtomicBool>,
        mut row: impl FnMut(usize, &mut [[E; L]]),
        mut record: impl FnMut(usize, &[[E; L]]),
    ) -> Result<()> {
        let mut inputs = Rows::<L, E>::zeros(self.n_inputs);
        // The row views are taken once: taken row by row, they cost 10% at N = 5.
        let inputs: &mut [[E; L]] = &mut inputs;
        let mut fresh = std::mem::take(&mut self.scratch.fresh);
        self.scratch.held = false;
        let (mut work, state) = self.work::<V>();
        let check_rows = (CANCEL_CHECK_STEPS / integ.substeps.max(1)).max(1);
        let mut rows_to_check = 0;
        for t in 0..steps {
            if rows_to_check == 0 {
                if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                    return Err(Error::Interrupted);
                }
                rows_to_check = check_rows;
            }
            rows_to_check -= 1;
            row(t, inputs);
            let v = V::rows_mut(state.as_flattened_mut());
            work.step(v, Some(V::rows(inputs.as_flattened())), integ, fresh);
            fresh = false;
            record(t, state);
        }
        Ok(())
    }

    /// Every array a step uses but the state, viewed as rows of `V`; and the state.
    #[inline(always)]
    fn work<V: Vector<Elem = E>>(&mut self) -> (Work<'_, V>, &mut [[E; L]]) {
        fn rows<V: Vector, const L: usize>(x: &[[V::Elem; L]]) -> &[V::Row] {
            V::rows(x.as_flattened())
        }
        fn rows_mut<V: Vector, const L: usize>(x: &mut [[V::Elem; L]]) -> &mut [V::Row] {
            V::rows_mut(x.as_flattened_mut())
        }
        let s = &mut self.scratch;
        let [k1, k2, k3] = &mut s.k;
        let work = Work {
            theta: rows::<V, L>(&self.theta),
            weights: rows::<V, L>(&self.weights),
            sensor_weights: rows::<V, L>(&self.sensor_weights),
            h: rows::<V, L>(&s.h),
            h2: rows::<V, L>(&s.h2),
            h6: rows::<V, L>(&s.h6),
            ext: rows_mut::<V, L>(&mut s.ext),
            out: rows_mut::<V, L>(&mut s.out),
            k: [
                rows_mut::<V, L>(k1),
                rows_mut::<V, L>(k2),
                rows_mut::<V, L>(k3),
            ],
            probe: rows_mut::<V, L>(&mut s.probe),
        };
        (work, &mut self.state)
    }

    /// Fails when a real lane's state is not finite, naming the first such neuron and lane (lane
    /// `l` as `name(l)`: what the caller knows it as), and what made it so ([`diverged`]).
    pub fn check_finite(&self, name: impl Fn(usize) -> String) -> Result<()> {
        for (i, row) in self.state.iter().enumerate() {
            if let Some(l) = (0..self.len).find(|&l| !row[l].finite()) {
                return Err(self.diverged(&name(l), i, l));
            }
        }
        Ok(())
    }

    /// The error of neuron `i` in lane `l` (of `what`) when its state is not finite
    /// ([`diverged`]), with the step and method of the last step.
    pub fn diverged(&self, what: &str, i: usize, l: usize) -> Error {
        let (h, method) = self.last_step(i, l);
        diverged(what, i, self.state[i][l].to_f64(), h, method)
    }

    /// `dt / tau` of neuron `i` in lane `l` at the last step (NaN before the first), and the
    /// step's method.
    pub fn last_step(&self, i: usize, l: usize) -> (f64, Method) {
        (self.scratch.h[i][l].to_f64(), self.scratch.method)
    }
}

/// The error of an integration in which neuron `neuron` of `what` (`network 3`, `row 7`) became
/// `value`, not a finite number, with a step of `dt / tau` = `h` of `method` there. From
/// [`Method::unstable_from`] on the step is too long; below it the neuron's own decay shrinks at
/// every step, so only a weight, threshold or input too large for the precision can have
/// overflowed it.
pub fn diverged(what: &str, neuron: usize, value: f64, h: f64, method: Method) -> Error {
    let limit = method.unstable_from();
    let why = if h >= limit {
        format!(
            "dt / tau is {} here, too long a step: use a smaller dt ({} steps grow without \
             bound from dt / tau = {} on)",
            short(h),
            method.name(),
            short(limit)
        )
    } else {
        format!(
            "dt / tau is {} here, so the step is not the cause: a weight, threshold or input too \
             large for the precision made it overflow",
            short(h)
        )
    };
    Error::InvalidArgument(format!(
        "integration diverged: state[{neuron}] of {what} became {value}; {why}"
    ))
}

/// Compiles the stepping methods of `Lanes<W>` once, in this crate, for each width `W` given.
///
/// A generic method is compiled again in every crate that calls it, and the kernel under it is
/// large: compiled in `tasks` as well, it cost about a third of a clean `cargo test` build. The
/// generic methods send the widths used outside this crate, one network (1) and a block
/// ([`LANES`]), to these non-generic copies, which every crate shares. Each does exactly what the
/// generic path does, so the bits are the same.
macro_rules! compile_once {
    ($($width:expr),*) => {$(
        impl Lanes<{ $width }> {
            fn advance_once(
                &mut self,
                kernel: Kernel,
                inputs: Option<&[[f64; $width]]>,
                integ: &Integrator,
            ) {
                self.advance_on(kernel, inputs, integ);
            }
            fn compute_outputs_once(&mut self) {
                self.compute_outputs_on(simd::kernel());
            }
        }
    )*};
}
compile_once!(1, LANES);

/// `lanes` as the `f64` block of width `W` whose stepping methods [`compile_once!`] compiled;
/// only called where it is one (`E` is `f64`, not [`Elem::SINGLE`], and `L == W`). The callers
/// decide that when they are compiled (`if const`), so the other widths and `f32` never compile
/// the branch, and this is a cast that costs nothing.
fn shared<const L: usize, const W: usize, E: Elem>(lanes: &mut Lanes<L, E>) -> &mut Lanes<W> {
    (lanes as &mut dyn Any)
        .downcast_mut()
        .expect("shared is only called on an f64 block of width W")
}

/// `rows` as the `f64` rows of width `W` of the block [`shared`] returns; only called where it
/// does, so it reinterprets nothing.
fn as_rows<const L: usize, const W: usize, E: Elem>(rows: &[[E; L]]) -> &[[f64; W]] {
    let (rows, rest) = bytemuck::cast_slice::<E, f64>(rows.as_flattened()).as_chunks::<W>();
    debug_assert!(rest.is_empty());
    rows
}

/// Copies lane `l` of `rows` (one value per row) into `into`.
pub fn copy_lane<const L: usize, E: Copy>(rows: &[[E; L]], l: usize, into: &mut [E]) {
    for (dst, row) in into.iter_mut().zip(rows) {
        *dst = row[l];
    }
}
