//! Forward Euler and classical RK4 for one network or a block of networks stepped together.
//!
//! The kernel works on [`Lanes`]: `L` networks of the same shape, stored parameter by parameter
//! with the networks side by side (`weights[i * N + j][lane]`), so that one step is straight-line
//! arithmetic over `[f64; L]` rows that the compiler vectorises across networks. A single network
//! is `Lanes<1>` and a population block is `Lanes<LANES>`: both run the same code in the same
//! order, which is why the two paths agree bit for bit.
//!
//! One Euler step of size `dt`, with `h = dt / tau`:
//! `v += h * (-v + W f(v - theta) + S I)`. Each row of inputs is held for `substeps` steps.

use std::sync::atomic::{AtomicBool, Ordering};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::math::sigmoid;
use crate::network::Network;

/// How many networks a population block steps together (one AVX-512 register of f64).
pub const LANES: usize = 8;

/// Rows between two looks at the cancel flag.
const CANCEL_CHECK_ROWS: usize = 64;

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
        match s {
            "euler" => Ok(Method::Euler),
            "rk4" => Ok(Method::Rk4),
            _ => Err(Error::InvalidArgument(format!(
                "method is {s:?}; expected \"euler\" or \"rk4\""
            ))),
        }
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

/// `L` networks of the same shape, laid out for stepping together.
#[derive(Clone, Debug)]
pub struct Lanes<const L: usize> {
    size: usize,
    n_inputs: usize,
    len: usize,
    tau: Vec<[f64; L]>,
    theta: Vec<[f64; L]>,
    weights: Vec<[f64; L]>,
    sensor_weights: Vec<[f64; L]>,
    state: Vec<[f64; L]>,
    scratch: Scratch<L>,
}

/// Work arrays, reused from step to step so that stepping allocates nothing.
#[derive(Clone, Debug)]
struct Scratch<const L: usize> {
    dt: f64,
    /// dt / tau, and its half and sixth for RK4.
    h: Vec<[f64; L]>,
    h2: Vec<[f64; L]>,
    h6: Vec<[f64; L]>,
    /// Sensor drive S I of the current row.
    ext: Vec<[f64; L]>,
    /// Firing rates.
    out: Vec<[f64; L]>,
    k: [Vec<[f64; L]>; 4],
    probe: Vec<[f64; L]>,
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
        let gather = |get: fn(&Network) -> &[f64], count: usize| -> Vec<[f64; L]> {
            (0..count)
                .map(|q| std::array::from_fn(|l| get(nets.get(l).unwrap_or(first))[q]))
                .collect()
        };
        let zeros = |count: usize| vec![[0.0; L]; count];
        Ok(Lanes {
            size: n,
            n_inputs: m,
            len: nets.len(),
            tau: gather(Network::tau, n),
            theta: gather(Network::theta, n),
            weights: gather(Network::weights, n * n),
            sensor_weights: gather(Network::sensor_weights, n * m),
            state: gather(Network::state, n),
            scratch: Scratch {
                dt: f64::NAN,
                h: zeros(n),
                h2: zeros(n),
                h6: zeros(n),
                ext: zeros(n),
                out: zeros(n),
                k: [zeros(n), zeros(n), zeros(n), zeros(n)],
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
    /// Sets every lane's state to zero.
    pub fn reset(&mut self) {
        self.state.fill([0.0; L]);
    }
    /// Sets the state of lane `l` (length N).
    pub fn set_lane_state(&mut self, l: usize, state: &[f64]) {
        for (row, &v) in self.state.iter_mut().zip(state) {
            row[l] = v;
        }
    }
    /// Copies the state of lane `l` into `into` (length N).
    pub fn lane_state(&self, l: usize, into: &mut [f64]) {
        for (dst, row) in into.iter_mut().zip(&self.state) {
            *dst = row[l];
        }
    }

    fn prepare(&mut self, dt: f64) {
        let s = &mut self.scratch;
        if s.dt.to_bits() == dt.to_bits() {
            return;
        }
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
    pub fn step_row(&mut self, inputs: &[[f64; L]], integ: &Integrator) {
        debug_assert_eq!(inputs.len(), self.n_inputs);
        self.prepare(integ.dt);
        let (n, m) = (self.size, self.n_inputs);
        for i in 0..n {
            let mut acc = [0.0; L];
            for k in 0..m {
                let s = &self.sensor_weights[i * m + k];
                for l in 0..L {
                    acc[l] = s[l].mul_add(inputs[k][l], acc[l]);
                }
            }
            self.scratch.ext[i] = acc;
        }
        for _ in 0..integ.substeps {
            match integ.method {
                Method::Euler => self.euler_step(),
                Method::Rk4 => self.rk4_step(),
            }
        }
    }

    fn euler_step(&mut self) {
        let Lanes {
            theta,
            weights,
            state,
            scratch: s,
            ..
        } = self;
        let net = Weights { theta, weights };
        let [d, ..] = &mut s.k;
        derivative(&net, state, d, &mut s.out, &s.ext);
        for (v, (h, d)) in state.iter_mut().zip(s.h.iter().zip(d.iter())) {
            for l in 0..L {
                v[l] = h[l].mul_add(d[l], v[l]);
            }
        }
    }

    fn rk4_step(&mut self) {
        let Lanes {
            theta,
            weights,
            state,
            scratch: s,
            ..
        } = self;
        let net = Weights { theta, weights };
        let [k1, k2, k3, k4] = &mut s.k;
        let probe = &mut s.probe;
        derivative(&net, state, k1, &mut s.out, &s.ext);
        offset(probe, state, &s.h2, k1);
        derivative(&net, probe, k2, &mut s.out, &s.ext);
        offset(probe, state, &s.h2, k2);
        derivative(&net, probe, k3, &mut s.out, &s.ext);
        offset(probe, state, &s.h, k3);
        derivative(&net, probe, k4, &mut s.out, &s.ext);
        for i in 0..state.len() {
            for l in 0..L {
                let sum = k1[i][l] + 2.0 * k2[i][l] + 2.0 * k3[i][l] + k4[i][l];
                state[i][l] = s.h6[i][l].mul_add(sum, state[i][l]);
            }
        }
    }

    /// Runs `steps` input rows. `row(t, inputs)` fills the sensors of row `t`; after each row
    /// `record(t, self)` may read the state. Stops with [`Error::Interrupted`] when `cancel` is set.
    pub fn run_rows(
        &mut self,
        steps: usize,
        integ: &Integrator,
        cancel: Option<&AtomicBool>,
        mut row: impl FnMut(usize, &mut [[f64; L]]),
        mut record: impl FnMut(usize, &Self),
    ) -> Result<()> {
        let mut inputs = vec![[0.0; L]; self.n_inputs];
        for t in 0..steps {
            if t % CANCEL_CHECK_ROWS == 0 && cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                return Err(Error::Interrupted);
            }
            row(t, &mut inputs);
            self.step_row(&inputs, integ);
            record(t, self);
        }
        self.check_finite()
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

/// The parameters the derivative reads, borrowed apart from the state and the scratch arrays.
struct Weights<'a, const L: usize> {
    theta: &'a [[f64; L]],
    weights: &'a [[f64; L]],
}

/// `d = -v + W f(v - theta) + ext`, lane by lane.
#[inline(always)]
fn derivative<const L: usize>(
    net: &Weights<'_, L>,
    v: &[[f64; L]],
    d: &mut [[f64; L]],
    out: &mut [[f64; L]],
    ext: &[[f64; L]],
) {
    let n = v.len();
    for j in 0..n {
        for l in 0..L {
            out[j][l] = sigmoid(v[j][l] - net.theta[j][l]);
        }
    }
    // Rows go ROWS at a time: independent sums keep the adders busy, and each sum still adds
    // its terms in the order j = 0, 1, ..., so the result does not depend on the blocking.
    let mut i = 0;
    while i + ROWS <= n {
        let mut acc: [[f64; L]; ROWS] = std::array::from_fn(|r| ext[i + r]);
        for j in 0..n {
            let o = &out[j];
            for (r, a) in acc.iter_mut().enumerate() {
                let w = &net.weights[(i + r) * n + j];
                for l in 0..L {
                    a[l] = w[l].mul_add(o[l], a[l]);
                }
            }
        }
        for (r, a) in acc.iter().enumerate() {
            for l in 0..L {
                d[i + r][l] = a[l] - v[i + r][l];
            }
        }
        i += ROWS;
    }
    for i in i..n {
        let mut acc = ext[i];
        let w = &net.weights[i * n..(i + 1) * n];
        for j in 0..n {
            for l in 0..L {
                acc[l] = w[j][l].mul_add(out[j][l], acc[l]);
            }
        }
        for l in 0..L {
            d[i][l] = acc[l] - v[i][l];
        }
    }
}

/// Rows of `W f` computed together in [`derivative`].
const ROWS: usize = 4;

/// `probe = v + h * k`, lane by lane.
#[inline(always)]
fn offset<const L: usize>(probe: &mut [[f64; L]], v: &[[f64; L]], h: &[[f64; L]], k: &[[f64; L]]) {
    for i in 0..v.len() {
        for l in 0..L {
            probe[i][l] = h[i][l].mul_add(k[i][l], v[i][l]);
        }
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
            |t, lanes| lanes.lane_state(0, &mut states[t * n..(t + 1) * n]),
        )?;
        lanes.lane_state(0, self.state_mut());
        Ok(states)
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
    fn cancel_flag_interrupts() {
        let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![], None).unwrap();
        let flag = AtomicBool::new(true);
        let r = net.run_cancellable(&[], 10, &Integrator::default(), Some(&flag));
        assert!(matches!(r, Err(Error::Interrupted)));
    }
}
