//! Forward Euler and classical RK4 for one network or a block of networks stepped together.
//!
//! The kernel works on [`Lanes`]: `L` networks of the same shape, stored parameter by parameter
//! with the networks side by side (`theta[i][lane]`), so that one step is straight-line
//! arithmetic over rows of `L` values, one per network. A single network is `Lanes<1>` and a
//! population block is `Lanes<LANES>`. The kernel is written once over the crate's lane vectors:
//! where the build's target CPU has AVX-512F a block keeps each row in 512-bit registers (8 lanes
//! each), elsewhere it runs lane by lane. Every path performs the same operations in the same
//! order, which is why single networks and populations agree bit for bit.
//!
//! One Euler step of size `dt`, with `h = dt / tau`:
//! `v += h * (-v + W f(v - theta) + S I)`. Each row of inputs is held for `substeps` steps.

use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::math::{sigmoid, sigmoid_lanes};
use crate::network::Network;
use crate::rows::Rows;
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
use crate::vector::Avx512;
use crate::vector::{Group, Portable, Vector};

/// How many networks a population block steps together: two AVX-512 registers of f64, so that
/// every row of the kernel has two independent dependency chains in flight.
pub const LANES: usize = 16;

/// Integration steps (rows times substeps) between two looks at the cancel flag, so that Ctrl-C
/// is seen within milliseconds however many substeps a row has.
const CANCEL_CHECK_STEPS: usize = 1024;

/// The integration method.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Forward Euler, the paper's method (default).
    #[default]
    Euler,
    /// Classical fourth-order Runge-Kutta.
    Rk4,
}

impl std::str::FromStr for Method {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        crate::names::parse_name("method", s).map_err(Error::InvalidArgument)
    }
}

impl Method {
    /// The lower-case name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Euler => "euler",
            Method::Rk4 => "rk4",
        }
    }
}

/// Integration settings: each input row is held for `substeps` steps of `dt`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Integrator {
    /// Integration method. Default: Euler.
    pub method: Method,
    /// Step size in units of simulated time. Default: 0.1.
    pub dt: f64,
    /// Integration steps per input row. Default: 1.
    pub substeps: usize,
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator {
            method: Method::Euler,
            dt: 0.1,
            substeps: 1,
        }
    }
}

impl Integrator {
    /// Checks `dt` is finite and > 0 and `substeps >= 1`.
    pub fn validate(&self) -> Result<()> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "dt is {}; it must be finite and > 0",
                self.dt
            )));
        }
        if self.substeps == 0 {
            return Err(Error::InvalidArgument(
                "substeps is 0; it must be >= 1".into(),
            ));
        }
        Ok(())
    }
}

/// Calls `self.method::<V>(args)` with `V` the lane vector type for `L` lanes: AVX-512 registers
/// where the build's target CPU has them and `L` is 8 or 16, plain lanes otherwise.
macro_rules! with_backend {
    ($self:ident . $method:ident ( $($arg:expr),* )) => {{
        #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
        if L == 8 {
            return $self.$method::<Avx512>($($arg),*);
        }
        #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
        if L == 16 {
            return $self.$method::<Group<Avx512, 2>>($($arg),*);
        }
        $self.$method::<Portable<L>>($($arg),*)
    }};
}

/// `L` networks of the same shape, laid out for stepping together.
#[derive(Clone, Debug)]
pub struct Lanes<const L: usize> {
    size: usize,
    n_inputs: usize,
    len: usize,
    tau: Rows<L>,
    theta: Rows<L>,
    weights: Rows<L>,
    sensor_weights: Rows<L>,
    state: Rows<L>,
    scratch: Scratch<L>,
}

/// Work arrays, reused from step to step so that stepping allocates nothing.
#[derive(Clone, Debug)]
struct Scratch<const L: usize> {
    dt: f64,
    /// dt / tau, and its half and sixth for RK4.
    h: Rows<L>,
    h2: Rows<L>,
    h6: Rows<L>,
    /// Sensor drive S I of the current row.
    ext: Rows<L>,
    /// Whether `ext` is the sensor drive of the last [`Lanes::step_row`], for
    /// [`Lanes::step_held`].
    held: bool,
    /// Firing rates.
    out: Rows<L>,
    /// Whether `out` holds the firing rates of the current state, computed by
    /// [`Lanes::outputs`]; the next step then starts from them instead of computing them again.
    fresh: bool,
    /// RK4's first three slopes (the fourth is used as soon as it is known).
    k: [Rows<L>; 3],
    probe: Rows<L>,
}

impl<const L: usize> Lanes<L> {
    /// Packs up to `L` networks of the same shape. Unused lanes repeat the first network, so they
    /// stay finite; their results are ignored.
    pub fn new(nets: &[&Network]) -> Result<Self> {
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
        let gather = |get: fn(&Network) -> &[f64], order: &mut dyn Iterator<Item = usize>| {
            let sources: [&[f64]; L] = std::array::from_fn(|l| get(nets.get(l).unwrap_or(first)));
            let len = get(first).len();
            Rows::from_rows(len, order.map(|q| std::array::from_fn(|l| sources[l][q])))
        };
        let zeros = Rows::zeros;
        Ok(Lanes {
            size: n,
            n_inputs: m,
            len: nets.len(),
            tau: gather(Network::tau, &mut (0..n)),
            theta: gather(Network::theta, &mut (0..n)),
            weights: gather(Network::weights, &mut weight_order(n)),
            sensor_weights: gather(Network::sensor_weights, &mut (0..n * m)),
            state: gather(Network::state, &mut (0..n)),
            scratch: Scratch {
                dt: f64::NAN,
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
    pub fn state(&self, i: usize) -> &[f64; L] {
        &self.state[i]
    }
    /// Firing rate `f(v_i - theta_i)` of neuron `i` in every lane.
    pub fn output(&self, i: usize) -> [f64; L] {
        std::array::from_fn(|l| sigmoid(self.state[i][l] - self.theta[i][l]))
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
    pub fn outputs(&mut self) -> &[[f64; L]] {
        if !self.scratch.fresh {
            self.compute_outputs();
            self.scratch.fresh = true;
        }
        &self.scratch.out
    }

    fn compute_outputs(&mut self) {
        with_backend!(self.compute_outputs_with())
    }

    fn compute_outputs_with<V: Vector>(&mut self) {
        rates::<V>(
            V::rows(self.theta.as_flattened()),
            V::rows(self.state.as_flattened()),
            V::rows_mut(self.scratch.out.as_flattened_mut()),
        );
    }

    /// Sets every lane's state to zero.
    pub fn reset(&mut self) {
        self.scratch.fresh = false;
        self.state.fill([0.0; L]);
    }
    /// Sets the state of lane `l` (length N).
    pub fn set_lane_state(&mut self, l: usize, state: &[f64]) {
        self.scratch.fresh = false;
        for (row, &v) in self.state.iter_mut().zip(state) {
            row[l] = v;
        }
    }
    /// Copies the state of lane `l` into `into` (length N).
    pub fn lane_state(&self, l: usize, into: &mut [f64]) {
        copy_lane(&self.state, l, into);
    }

    /// Makes the step sizes match `dt`.
    #[inline(always)]
    fn prepare(&mut self, dt: f64) {
        if self.scratch.dt.to_bits() != dt.to_bits() {
            self.set_step_sizes(dt);
        }
    }

    #[cold]
    fn set_step_sizes(&mut self, dt: f64) {
        let s = &mut self.scratch;
        s.dt = dt;
        for i in 0..self.size {
            for l in 0..L {
                let h = dt / self.tau[i][l];
                s.h[i][l] = h;
                s.h2[i][l] = 0.5 * h;
                s.h6[i][l] = h / 6.0;
            }
        }
    }

    /// Holds `inputs` (one `[f64; L]` per sensor) for `integ.substeps` steps of `integ.dt`.
    /// `integ` must be valid.
    #[inline(always)]
    pub fn step_row(&mut self, inputs: &[[f64; L]], integ: &Integrator) {
        debug_assert_eq!(inputs.len(), self.n_inputs);
        self.prepare(integ.dt);
        with_backend!(self.step_row_with(inputs, integ))
    }

    #[inline(always)]
    fn step_row_with<V: Vector>(&mut self, inputs: &[[f64; L]], integ: &Integrator) {
        let fresh = std::mem::take(&mut self.scratch.fresh);
        self.scratch.held = true;
        let (mut work, state) = self.work::<V>();
        work.step(
            V::rows_mut(state.as_flattened_mut()),
            V::rows(inputs.as_flattened()),
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
        self.prepare(integ.dt);
        with_backend!(self.step_held_with(integ))
    }

    #[inline(always)]
    fn step_held_with<V: Vector>(&mut self, integ: &Integrator) {
        let fresh = std::mem::take(&mut self.scratch.fresh);
        let (mut work, state) = self.work::<V>();
        work.integrate(V::rows_mut(state.as_flattened_mut()), integ, fresh);
    }

    /// Runs `steps` input rows. `row(t, inputs)` fills the sensors of row `t`; after each row
    /// `record(t, state)` may read the state (one `[f64; L]` per neuron). Stops with
    /// [`Error::Interrupted`] when `cancel` is set.
    pub fn run_rows(
        &mut self,
        steps: usize,
        integ: &Integrator,
        cancel: Option<&AtomicBool>,
        row: impl FnMut(usize, &mut [[f64; L]]),
        record: impl FnMut(usize, &[[f64; L]]),
    ) -> Result<()> {
        self.prepare(integ.dt);
        with_backend!(self.run_rows_with(steps, integ, cancel, row, record))?;
        self.check_finite()
    }

    #[inline(always)]
    fn run_rows_with<V: Vector>(
        &mut self,
        steps: usize,
        integ: &Integrator,
        cancel: Option<&AtomicBool>,
        mut row: impl FnMut(usize, &mut [[f64; L]]),
        mut record: impl FnMut(usize, &[[f64; L]]),
    ) -> Result<()> {
        let mut inputs = Rows::<L>::zeros(self.n_inputs);
        // The row views are taken once: taken row by row, they cost 10% at N = 5.
        let inputs: &mut [[f64; L]] = &mut inputs;
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
            work.step(v, V::rows(inputs.as_flattened()), integ, fresh);
            fresh = false;
            record(t, state);
        }
        Ok(())
    }

    /// Every array a step uses but the state, viewed as rows of `V`; and the state.
    #[inline(always)]
    fn work<V: Vector>(&mut self) -> (Work<'_, V>, &mut [[f64; L]]) {
        fn rows<V: Vector, const L: usize>(x: &[[f64; L]]) -> &[V::Row] {
            V::rows(x.as_flattened())
        }
        fn rows_mut<V: Vector, const L: usize>(x: &mut [[f64; L]]) -> &mut [V::Row] {
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

    /// An Euler step with `dt / tau > 2` oscillates with growing amplitude; say so rather than
    /// return infinities.
    fn check_finite(&self) -> Result<()> {
        for (i, row) in self.state.iter().enumerate() {
            if let Some(l) = (0..self.len).find(|&l| !row[l].is_finite()) {
                return Err(Error::InvalidArgument(format!(
                    "integration diverged: state[{i}] of network {l} in its block became {}; \
                     use a smaller dt (dt / tau = {} here; Euler needs it well below 2)",
                    row[l], self.scratch.h[i][l]
                )));
            }
        }
        Ok(())
    }
}

/// The arrays of one step, viewed as rows of the lane vector `V`: the parameters, the step sizes
/// and the work rows (everything but the state).
struct Work<'a, V: Vector> {
    theta: &'a [V::Row],
    weights: &'a [V::Row],
    sensor_weights: &'a [V::Row],
    /// `dt/tau`, its half and its sixth.
    h: &'a [V::Row],
    h2: &'a [V::Row],
    h6: &'a [V::Row],
    /// `S I` for the current input row.
    ext: &'a mut [V::Row],
    /// Firing rates.
    out: &'a mut [V::Row],
    /// RK4's first three slopes (the fourth is used as soon as it is known).
    k: [&'a mut [V::Row]; 3],
    /// The point where RK4's next slope is taken.
    probe: &'a mut [V::Row],
}

impl<V: Vector> Work<'_, V> {
    /// Holds `inputs` for `integ.substeps` steps of the state `v`. With `fresh`, `out` already
    /// holds the firing rates of `v` and the first step starts from them.
    #[inline(always)]
    fn step(&mut self, v: &mut [V::Row], inputs: &[V::Row], integ: &Integrator, fresh: bool) {
        sensor_drive::<V>(self.sensor_weights, inputs, self.ext);
        self.integrate(v, integ, fresh);
    }

    /// `integ.substeps` steps of the state `v` with the sensor drive in `ext`; `fresh` as for
    /// [`step`](Self::step).
    #[inline(always)]
    fn integrate(&mut self, v: &mut [V::Row], integ: &Integrator, fresh: bool) {
        for s in 0..integ.substeps {
            let fresh = fresh && s == 0;
            match integ.method {
                Method::Euler => self.euler_step(v, fresh),
                Method::Rk4 => self.rk4_step(v, fresh),
            }
        }
    }

    /// One Euler step: `v += h * (ext + W f(v - theta) - v)`; with `fresh`, `out` already holds
    /// `f(v - theta)`.
    #[inline(always)]
    fn euler_step(&mut self, v: &mut [V::Row], fresh: bool) {
        let h = self.h;
        if !fresh {
            rates::<V>(self.theta, v, self.out);
        }
        drive::<V>(self.weights, self.ext, self.out, |i, acc| {
            let x = V::load(&v[i]);
            V::load(&h[i]).mul_add(acc - x, x).store(&mut v[i]);
        });
    }

    /// One classical RK4 step; with `fresh`, `out` already holds `f(v - theta)`.
    #[inline(always)]
    fn rk4_step(&mut self, v: &mut [V::Row], fresh: bool) {
        let Work {
            theta,
            weights,
            h,
            h2,
            h6,
            ext,
            out,
            k: [k1, k2, k3],
            probe,
            ..
        } = self;
        let (weights, ext) = (*weights, &**ext);
        // Slope 1 at v; the next probe is v + h/2 k1.
        if !fresh {
            rates::<V>(theta, v, out);
        }
        drive::<V>(weights, ext, out, |i, acc| {
            let x = V::load(&v[i]);
            let d = acc - x;
            d.store(&mut k1[i]);
            V::load(&h2[i]).mul_add(d, x).store(&mut probe[i]);
        });
        // Slopes 2 and 3 at the probe; the probes after them are v + h/2 k2 and v + h k3.
        for (k, h) in [(&mut **k2, *h2), (&mut **k3, *h)] {
            rates::<V>(theta, probe, out);
            drive::<V>(weights, ext, out, |i, acc| {
                let d = acc - V::load(&probe[i]);
                d.store(&mut k[i]);
                V::load(&h[i])
                    .mul_add(d, V::load(&v[i]))
                    .store(&mut probe[i]);
            });
        }
        // Slope 4 at the last probe, then v += h/6 (k1 + 2 k2 + 2 k3 + k4).
        rates::<V>(theta, probe, out);
        drive::<V>(weights, ext, out, |i, acc| {
            let k4 = acc - V::load(&probe[i]);
            let two = V::splat(2.0);
            let sum = V::load(&k1[i]) + two * V::load(&k2[i]) + two * V::load(&k3[i]) + k4;
            let x = V::load(&v[i]);
            V::load(&h6[i]).mul_add(sum, x).store(&mut v[i]);
        });
    }
}

/// `ext = S I`, each sum over the sensors in order.
#[inline(always)]
fn sensor_drive<V: Vector>(sensor_weights: &[V::Row], inputs: &[V::Row], ext: &mut [V::Row]) {
    if inputs.is_empty() {
        ext.iter_mut().for_each(|e| V::splat(0.0).store(e));
        return;
    }
    for (e, weights) in ext
        .iter_mut()
        .zip(sensor_weights.chunks_exact(inputs.len()))
    {
        let mut acc = V::splat(0.0);
        for (s, x) in weights.iter().zip(inputs) {
            acc = V::load(s).mul_add(V::load(x), acc);
        }
        acc.store(e);
    }
}

/// Firing rates `out = f(v - theta)`: [`RATE_GROUP`] neurons at a time where `V` allows it (see
/// [`Group`]), else one by one.
#[inline(always)]
fn rates<V: Vector>(theta: &[V::Row], v: &[V::Row], out: &mut [V::Row]) {
    let one = |o: &mut V::Row, x: &V::Row, t: &V::Row| {
        sigmoid_lanes(V::load(x) - V::load(t)).store(o);
    };
    if !V::INTERLEAVE {
        for (o, (x, t)) in out.iter_mut().zip(v.iter().zip(theta)) {
            one(o, x, t);
        }
        return;
    }
    let mut groups = out.chunks_exact_mut(RATE_GROUP);
    let mut at = 0;
    for o in &mut groups {
        let x = Group::<V, RATE_GROUP>(std::array::from_fn(|g| {
            V::load(&v[at + g]) - V::load(&theta[at + g])
        }));
        for (o, y) in o.iter_mut().zip(sigmoid_lanes(x).0) {
            y.store(o);
        }
        at += RATE_GROUP;
    }
    for (o, (x, t)) in groups
        .into_remainder()
        .iter_mut()
        .zip(v[at..].iter().zip(&theta[at..]))
    {
        one(o, x, t);
    }
}

/// Neurons whose firing rates are computed together in [`rates`].
const RATE_GROUP: usize = 4;

/// Rows of `W f` computed together in [`drive`].
const ROWS: usize = 4;
const PREFETCH_COLUMNS: usize = 4;

/// The order in which [`drive`] reads the row-major `N x N` weights, as one stream: each group
/// of [`ROWS`] rows column by column (`w[i][0], w[i+1][0], ..., w[i][1], ...`), then the rows
/// left over, row by row. Row `i`'s weights start at `i * N` either way.
fn weight_order(n: usize) -> impl Iterator<Item = usize> {
    let full = n - n % ROWS;
    let groups = (0..full)
        .step_by(ROWS)
        .flat_map(move |i| (0..n).flat_map(move |j| (i..i + ROWS).map(move |r| r * n + j)));
    groups.chain(full * n..n * n)
}

/// For every neuron `i`, `finish(i, ext_i + sum_j w_ij out_j)`, the sum taken in the order
/// `j = 0, 1, ...`. Rows go [`ROWS`] at a time: independent sums keep the multiply-add units
/// busy, and the result does not depend on the blocking.
#[inline(always)]
fn drive<V: Vector>(
    weights: &[V::Row],
    ext: &[V::Row],
    out: &[V::Row],
    mut finish: impl FnMut(usize, V),
) {
    let n = out.len();
    let mut i = 0;
    while i + ROWS <= n {
        let (columns, _) = weights[i * n..(i + ROWS) * n].as_chunks::<ROWS>();
        let mut acc: [V; ROWS] = std::array::from_fn(|r| V::load(&ext[i + r]));
        for (j, (w, o)) in columns.iter().zip(out).enumerate() {
            if let Some(ahead) = columns.get(j + PREFETCH_COLUMNS) {
                ahead.iter().for_each(V::prefetch);
            }
            let o = V::load(o);
            for (a, w) in acc.iter_mut().zip(w) {
                *a = V::load(w).mul_add(o, *a);
            }
        }
        for (r, a) in acc.into_iter().enumerate() {
            finish(i + r, a);
        }
        i += ROWS;
    }
    for i in i..n {
        let mut acc = V::load(&ext[i]);
        for (w, o) in weights[i * n..][..n].iter().zip(out) {
            acc = V::load(w).mul_add(V::load(o), acc);
        }
        finish(i, acc);
    }
}

impl Network {
    /// Integrates the network through `steps` rows of `inputs` (row-major `steps x n_inputs`),
    /// each held for `integ.substeps` steps, and returns the state after every row
    /// (row-major `steps x size`). The network keeps the final state.
    ///
    /// # Example
    /// ```
    /// use ctrnn::{Integrator, Network};
    /// let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    /// let states = net.run(&[1.0, 1.0], 2, &Integrator::default()).unwrap();
    /// // v += 0.1 * (-v + 1): 0.1, then 0.19
    /// assert!((states[0] - 0.1).abs() < 1e-15 && (states[1] - 0.19).abs() < 1e-15);
    /// ```
    pub fn run(&mut self, inputs: &[f64], steps: usize, integ: &Integrator) -> Result<Vec<f64>> {
        self.run_cancellable(inputs, steps, integ, None)
    }

    /// [`Network::run`] that stops with [`Error::Interrupted`] once `cancel` is set.
    pub fn run_cancellable(
        &mut self,
        inputs: &[f64],
        steps: usize,
        integ: &Integrator,
        cancel: Option<&AtomicBool>,
    ) -> Result<Vec<f64>> {
        integ.validate()?;
        let (n, m) = (self.size(), self.n_inputs());
        check_inputs(inputs, steps * m, "steps x n_inputs")?;
        let mut lanes = Lanes::<1>::new(&[self])?;
        let mut states = vec![0.0; steps * n];
        lanes.run_rows(
            steps,
            integ,
            cancel,
            |t, row| {
                for k in 0..m {
                    row[k][0] = inputs[t * m + k];
                }
            },
            |t, state| copy_lane(state, 0, &mut states[t * n..(t + 1) * n]),
        )?;
        lanes.lane_state(0, self.state_mut());
        Ok(states)
    }
}

/// Copies lane `l` of `rows` (one value per row) into `into`.
pub fn copy_lane<const L: usize>(rows: &[[f64; L]], l: usize, into: &mut [f64]) {
    for (dst, row) in into.iter_mut().zip(rows) {
        *dst = row[l];
    }
}

/// Checks an input array's length and that every value is finite.
pub(crate) fn check_inputs(inputs: &[f64], want: usize, shape: &str) -> Result<()> {
    if inputs.len() != want {
        return Err(Error::InvalidArgument(format!(
            "inputs have {} values; expected {shape} = {want}",
            inputs.len()
        )));
    }
    match inputs.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(k) => Err(Error::InvalidArgument(format!(
            "inputs contain {} at flat index {k}; every input must be finite",
            inputs[k]
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sig(x: f64) -> f64 {
        1.0 / (1.0 + (-x).exp())
    }

    #[test]
    fn euler_step_matches_hand_calculation() {
        // N = 2, M = 1, one step from v = (0.5, -1) with input 2.
        let mut net = Network::new(
            vec![1.0, 2.0],
            vec![0.25, -0.5],
            vec![1.0, -2.0, 0.5, 3.0],
            vec![0.3, -0.7],
            Some(vec![0.5, -1.0]),
        )
        .unwrap();
        let integ = Integrator::default();
        let s = net.run(&[2.0], 1, &integ).unwrap();
        let f0 = sig(0.5 - 0.25);
        let f1 = sig(-1.0 + 0.5);
        let d0 = -0.5 + (1.0 * f0 - 2.0 * f1) + 0.3 * 2.0;
        let d1 = 1.0 + (0.5 * f0 + 3.0 * f1) - 0.7 * 2.0;
        let want = [0.5 + 0.1 / 1.0 * d0, -1.0 + 0.1 / 2.0 * d1];
        for i in 0..2 {
            assert!((s[i] - want[i]).abs() < 1e-15, "{} vs {}", s[i], want[i]);
        }
        assert_eq!(net.state(), &s[..]);
    }

    /// With W = 0 and constant input, v(t) = c + (v0 - c) e^{-t / tau} with c = S I.
    fn rk4_error(dt: f64) -> f64 {
        let tau = [0.7, 1.3, 4.0];
        let mut net = Network::new(
            tau.to_vec(),
            vec![0.0; 3],
            vec![0.0; 9],
            vec![1.0, -2.0, 0.5],
            Some(vec![2.0, 1.0, -3.0]),
        )
        .unwrap();
        let t_end = 2.0;
        let steps = (t_end / dt).round() as usize;
        let integ = Integrator {
            method: Method::Rk4,
            dt,
            substeps: steps,
        };
        let s = net.run(&[1.5], 1, &integ).unwrap();
        let c = [1.5, -3.0, 0.75];
        let v0 = [2.0, 1.0, -3.0];
        (0..3)
            .map(|i| (s[i] - (c[i] + (v0[i] - c[i]) * (-t_end / tau[i]).exp())).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn rk4_converges_with_order_four() {
        let (e1, e2) = (rk4_error(0.2), rk4_error(0.1));
        let order = (e1 / e2).log2();
        assert!(
            (3.8..4.2).contains(&order),
            "order {order}, errors {e1} {e2}"
        );
    }

    #[test]
    fn euler_converges_with_order_one() {
        let err = |dt: f64| {
            let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
            let integ = Integrator {
                method: Method::Euler,
                dt,
                substeps: (1.0 / dt).round() as usize,
            };
            let s = net.run(&[1.0], 1, &integ).unwrap();
            (s[0] - (1.0 - (-1.0f64).exp())).abs()
        };
        let order = (err(0.01) / err(0.005)).log2();
        assert!((0.95..1.05).contains(&order), "order {order}");
    }

    #[test]
    fn bad_arguments_are_errors() {
        let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
        let bad_dt = Integrator {
            dt: -0.1,
            ..Integrator::default()
        };
        assert!(net
            .run(&[1.0], 1, &bad_dt)
            .unwrap_err()
            .to_string()
            .contains("dt"));
        let zero = Integrator {
            substeps: 0,
            ..Integrator::default()
        };
        assert!(net.run(&[1.0], 1, &zero).is_err());
        assert!(net.run(&[1.0, 2.0], 1, &Integrator::default()).is_err());
        assert!(net.run(&[f64::NAN], 1, &Integrator::default()).is_err());
        assert!("rk5".parse::<Method>().is_err());
    }

    #[test]
    fn divergence_is_reported_not_returned() {
        let mut net =
            Network::new(vec![0.5], vec![0.0], vec![0.0], vec![1.0], Some(vec![1.0])).unwrap();
        let huge = Integrator {
            dt: 5.0,
            substeps: 1000,
            ..Integrator::default()
        };
        let e = net.run(&[0.0], 1, &huge).unwrap_err().to_string();
        assert!(e.contains("diverged"), "{e}");
    }

    #[test]
    fn weights_are_stored_by_row_groups() {
        // 6 x 6 with ROWS = 4: rows 0-3 column by column, then rows 4 and 5 as they are.
        let order: Vec<usize> = weight_order(6).collect();
        assert_eq!(order[..8], [0, 6, 12, 18, 1, 7, 13, 19]);
        assert_eq!(order[20..24], [5, 11, 17, 23]);
        assert_eq!(order[24..], (24..36).collect::<Vec<_>>()[..]);
        // Fewer rows than a group: row-major.
        assert_eq!(
            weight_order(3).collect::<Vec<_>>(),
            (0..9).collect::<Vec<_>>()
        );
    }

    /// Random networks of one shape, from a fixed seed.
    fn random_networks(count: usize, n: usize, m: usize, seed: u64) -> Vec<Network> {
        use crate::rng::{Purpose, Stream};
        let mut rng = Stream::new(seed, 0, Purpose::Init, 0, 0);
        let mut draw = |count: usize, lo: f64, hi: f64| -> Vec<f64> {
            (0..count).map(|_| rng.range(lo, hi)).collect()
        };
        (0..count)
            .map(|_| {
                let (tau, theta) = (draw(n, 0.5, 10.0), draw(n, -16.0, 16.0));
                let (w, s, v) = (
                    draw(n * n, -16.0, 16.0),
                    draw(n * m, -16.0, 16.0),
                    draw(n, -5.0, 5.0),
                );
                Network::new(tau, theta, w, s, Some(v)).unwrap()
            })
            .collect()
    }

    /// Steps one block with vector backend `V` and with the portable backend: same bits.
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    fn backends_agree<V: Vector<Row = R>, R, const L: usize>() {
        for (n, m) in [
            (1, 0),
            (3, 1),
            (4, 2),
            (5, 2),
            (7, 3),
            (10, 2),
            (13, 1),
            (30, 2),
        ] {
            let nets = random_networks(L, n, m, (n * 10 + m) as u64);
            let refs: Vec<&Network> = nets.iter().collect();
            for method in [Method::Euler, Method::Rk4] {
                let integ = Integrator {
                    method,
                    dt: 0.05,
                    substeps: 3,
                };
                let mut fast = Lanes::<L>::new(&refs).unwrap();
                let mut portable = fast.clone();
                for t in 0..20 {
                    let inputs: Vec<[f64; L]> = (0..m)
                        .map(|k| std::array::from_fn(|l| ((t * 7 + k * 3 + l) % 5) as f64 - 2.0))
                        .collect();
                    fast.prepare(integ.dt);
                    fast.step_row_with::<V>(&inputs, &integ);
                    portable.prepare(integ.dt);
                    portable.step_row_with::<Portable<L>>(&inputs, &integ);
                }
                for i in 0..n {
                    let (a, b) = (fast.state(i), portable.state(i));
                    assert!(
                        a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
                        "N = {n}, M = {m}, {method:?}, neuron {i}: {a:?} vs {b:?}"
                    );
                }
            }
        }
    }

    #[test]
    #[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
    fn avx512_blocks_match_the_portable_kernel_bit_for_bit() {
        backends_agree::<Avx512, [f64; 8], 8>();
        backends_agree::<Group<Avx512, 2>, [[f64; 8]; 2], 16>();
    }

    #[test]
    fn reading_the_outputs_between_steps_changes_nothing() {
        let nets = random_networks(LANES, 5, 2, 3);
        let refs: Vec<&Network> = nets.iter().collect();
        for method in [Method::Euler, Method::Rk4] {
            let integ = Integrator {
                method,
                dt: 0.1,
                substeps: 3,
            };
            let mut plain = Lanes::<LANES>::new(&refs).unwrap();
            let mut read = plain.clone();
            let same = |a: &Lanes<LANES>, b: &Lanes<LANES>| {
                (0..5).all(|i| {
                    let (x, y) = (a.state(i), b.state(i));
                    x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits())
                })
            };
            for t in 0..30 {
                // Rates read after row 9 and row 19 must not survive the reset and the new state.
                if t == 10 {
                    plain.reset();
                    read.reset();
                }
                if t == 20 {
                    plain.set_lane_state(3, &[1.0; 5]);
                    read.set_lane_state(3, &[1.0; 5]);
                }
                let inputs = [[(t % 3) as f64; LANES], [1.0 - (t % 2) as f64; LANES]];
                plain.step_row(&inputs, &integ);
                read.step_row(&inputs, &integ);
                assert!(same(&plain, &read), "{method:?}, row {t}");
                if t % 4 != 2 {
                    let out: Vec<[f64; LANES]> = read.outputs().to_vec();
                    for (i, row) in out.iter().enumerate() {
                        let want = read.output(i);
                        assert!(row
                            .iter()
                            .zip(&want)
                            .all(|(a, b)| a.to_bits() == b.to_bits()));
                    }
                }
            }
            let mut rows = read.clone();
            let _ = rows.outputs();
            let record = |_: usize, _: &[[f64; LANES]]| {};
            rows.run_rows(5, &integ, None, |_, r| r[0][0] = 1.0, record)
                .unwrap();
            plain
                .run_rows(5, &integ, None, |_, r| r[0][0] = 1.0, record)
                .unwrap();
            assert!(same(&plain, &rows), "{method:?}, run_rows");
        }
    }

    #[test]
    fn holding_the_inputs_is_stepping_them_again() {
        let nets = random_networks(LANES, 5, 2, 4);
        let refs: Vec<&Network> = nets.iter().collect();
        for method in [Method::Euler, Method::Rk4] {
            let integ = Integrator {
                method,
                dt: 0.1,
                substeps: 2,
            };
            let mut again = Lanes::<LANES>::new(&refs).unwrap();
            let (mut held, mut together) = (again.clone(), again.clone());
            let same = |a: &Lanes<LANES>, b: &Lanes<LANES>| {
                (0..5).all(|i| {
                    let (x, y) = (a.state(i), b.state(i));
                    x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits())
                })
            };
            for t in 0..12 {
                let inputs = [[(t / 4) as f64; LANES], [0.5; LANES]];
                again.step_row(&inputs, &integ);
                if t % 4 == 0 {
                    held.step_row(&inputs, &integ);
                    // Four rows of the same inputs as one row of four times the steps.
                    let four = Integrator {
                        substeps: 4 * integ.substeps,
                        ..integ
                    };
                    together.step_row(&inputs, &four);
                } else {
                    held.step_held(&integ);
                }
                if t % 3 == 0 {
                    let _ = held.outputs();
                }
                assert!(same(&again, &held), "{method:?}, row {t}");
                if t % 4 == 3 {
                    assert!(same(&again, &together), "{method:?}, row {t}");
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "step_held needs a step_row before it")]
    fn holding_needs_a_row() {
        let net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
        Lanes::<1>::new(&[&net])
            .unwrap()
            .step_held(&Integrator::default());
    }

    #[test]
    fn cancel_flag_interrupts() {
        let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![], None).unwrap();
        let flag = AtomicBool::new(true);
        let r = net.run_cancellable(&[], 10, &Integrator::default(), Some(&flag));
        assert!(matches!(r, Err(Error::Interrupted)));
    }
}
