//! A continuous-time recurrent neural network: its parameters, its state, and their validation.
//!
//! The model (paper §2.1, with the sigmoid misprint corrected as in `docs/paper.md`, "The
//! network") is
//!
//! ```text
//! tau_i dv_i/dt = -v_i + sum_j weights[i][j] f(v_j - theta_j) + sum_k sensor_weights[i][k] I_k
//! f(x) = 1 / (1 + e^-x)
//! ```
//!
//! Matrices are stored row-major: `weights[i * size + j]` is the weight from neuron j to neuron i,
//! and `sensor_weights[i * n_inputs + k]` the weight from sensor k to neuron i.
//!
//! There is no gain: Beer's `tau_i dy_i/dt = -y_i + sum_j w_ji sigma(g_j (y_j + bias_j)) + I_i`
//! is this model in `v_i = g_i y_i`, with `theta_i = -g_i bias_i`, `weights[i][j] = g_i w_ji`,
//! sensor weights multiplied by `g_i` and the state `v = g y` (a gain of 0 has no such form);
//! the firing rates are the same (`docs/network-format.md`).

use crate::error::{check_finite, Error, Result};
use crate::math::firing_rates;
use crate::rng::Stream;

/// A network of `size` neurons and `n_inputs` sensors, always valid once constructed.
#[derive(Clone, Debug, PartialEq)]
pub struct Network {
    size: usize,
    n_inputs: usize,
    tau: Vec<f64>,
    theta: Vec<f64>,
    weights: Vec<f64>,
    sensor_weights: Vec<f64>,
    state: Vec<f64>,
}

impl Network {
    /// Builds a network from flat row-major parameters, validating every field.
    ///
    /// `state` defaults to zeros. Errors name the field and the index of the first bad value.
    ///
    /// # Example
    /// ```
    /// use ctrnn::Network;
    /// // Two neurons, one sensor.
    /// let net = Network::new(
    ///     vec![1.0, 2.0],             // tau
    ///     vec![0.0, -1.0],            // theta
    ///     vec![0.0, 1.0, -1.0, 0.0],  // weights, row i = inputs of neuron i
    ///     vec![0.5, 0.0],             // sensor_weights, 2 x 1
    ///     None,
    /// ).unwrap();
    /// assert_eq!((net.size(), net.n_inputs()), (2, 1));
    /// assert!(Network::new(vec![-1.0], vec![0.0], vec![0.0], vec![], None).is_err());
    /// ```
    pub fn new(
        tau: Vec<f64>,
        theta: Vec<f64>,
        weights: Vec<f64>,
        sensor_weights: Vec<f64>,
        state: Option<Vec<f64>>,
    ) -> Result<Self> {
        let state = state.unwrap_or_else(|| vec![0.0; tau.len()]);
        let params = Params {
            tau: &tau,
            theta: &theta,
            weights: &weights,
            sensor_weights: &sensor_weights,
            state: &state,
        };
        params.validate()?;
        let (size, n_inputs) = (params.size(), params.n_inputs());
        Ok(Network {
            size,
            n_inputs,
            tau,
            theta,
            weights,
            sensor_weights,
            state,
        })
    }

    /// Checks the values: every one finite and every `tau > 0`.
    pub fn validate(&self) -> Result<()> {
        self.params().validate()
    }

    /// The parameters and state, borrowed.
    ///
    /// # Example
    /// ```
    /// let net = ctrnn::Network::new(vec![2.0], vec![0.0], vec![1.0], vec![], None)?;
    /// assert_eq!(net.params().tau, &[2.0]);
    /// # Ok::<(), ctrnn::Error>(())
    /// ```
    pub fn params(&self) -> Params<'_> {
        Params {
            tau: &self.tau,
            theta: &self.theta,
            weights: &self.weights,
            sensor_weights: &self.sensor_weights,
            state: &self.state,
        }
    }

    /// Number of neurons N.
    pub fn size(&self) -> usize {
        self.size
    }
    /// Number of sensors M.
    pub fn n_inputs(&self) -> usize {
        self.n_inputs
    }
    /// Time constants, length N.
    pub fn tau(&self) -> &[f64] {
        &self.tau
    }
    /// Thresholds, length N.
    pub fn theta(&self) -> &[f64] {
        &self.theta
    }
    /// Recurrent weights, N x N row-major; `[i * N + j]` is from neuron j to neuron i.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
    /// Sensor weights, N x M row-major; `[i * M + k]` is from sensor k to neuron i.
    pub fn sensor_weights(&self) -> &[f64] {
        &self.sensor_weights
    }
    /// The state v, length N.
    pub fn state(&self) -> &[f64] {
        &self.state
    }

    /// Replaces the state; `None` resets it to zeros.
    pub fn set_state(&mut self, state: Option<&[f64]>) -> Result<()> {
        match state {
            None => self.state.fill(0.0),
            Some(s) => {
                expect_len("state", s.len(), self.size, "N")?;
                check_finite("state", s, 0)?;
                self.state.copy_from_slice(s);
            }
        }
        Ok(())
    }

    /// Firing rates `f(v_i - theta_i)` of the current state.
    pub fn outputs(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.size()];
        firing_rates(&self.state, &self.theta, &mut out);
        out
    }

    /// Mutable access for the integrator, which keeps values finite only if the inputs are.
    pub(crate) fn state_mut(&mut self) -> &mut [f64] {
        &mut self.state
    }
}

/// A network's parameters and state borrowed from elsewhere (stacked arrays, for example), laid
/// out as [`Network`] holds them, so that a population can be packed without an owned `Network`
/// per member ([`crate::Population::from_params`]). Nothing is checked until [`validate`](Self::validate).
#[derive(Clone, Copy, Debug)]
pub struct Params<'a> {
    /// Time constants, length N.
    pub tau: &'a [f64],
    /// Thresholds, length N.
    pub theta: &'a [f64],
    /// Recurrent weights, N x N row-major.
    pub weights: &'a [f64],
    /// Sensor weights, N x M row-major.
    pub sensor_weights: &'a [f64],
    /// The state v, length N.
    pub state: &'a [f64],
}

impl Params<'_> {
    /// Number of neurons N (the length of `tau`).
    pub fn size(&self) -> usize {
        self.tau.len()
    }
    /// Number of sensors M (`sensor_weights` over N; 0 for N = 0).
    pub fn n_inputs(&self) -> usize {
        self.sensor_weights
            .len()
            .checked_div(self.size())
            .unwrap_or(0)
    }

    /// Checks what [`Network::new`] checks, with the same messages: at least one neuron, every
    /// length consistent with N, every value finite and every `tau > 0`.
    ///
    /// # Example
    /// ```
    /// let p = ctrnn::Params { tau: &[1.0], theta: &[0.0], weights: &[f64::NAN],
    ///                         sensor_weights: &[], state: &[0.0] };
    /// assert!(p.validate().unwrap_err().to_string().contains("weights"));
    /// ```
    pub fn validate(&self) -> Result<()> {
        let size = self.size();
        if size == 0 {
            return Err(Error::InvalidNetwork(
                "tau is empty; a network needs at least 1 neuron".into(),
            ));
        }
        let n_inputs = self.n_inputs();
        expect_len("theta", self.theta.len(), size, "N")?;
        expect_len("weights", self.weights.len(), size * size, "N x N")?;
        if self.sensor_weights.len() != size * n_inputs {
            return Err(Error::InvalidNetwork(format!(
                "sensor_weights has {} values, which is not a multiple of N = {size}; expected N x M",
                self.sensor_weights.len()
            )));
        }
        expect_len("state", self.state.len(), size, "N")?;
        check_finite("tau", self.tau, 0)?;
        if let Some(i) = self.tau.iter().position(|&t| t <= 0.0) {
            return Err(Error::InvalidNetwork(format!(
                "tau[{i}] is {}; every time constant must be > 0",
                self.tau[i]
            )));
        }
        check_finite("theta", self.theta, 0)?;
        check_finite("weights", self.weights, size)?;
        check_finite("sensor_weights", self.sensor_weights, n_inputs)?;
        check_finite("state", self.state, 0)
    }
}

impl Params<'_> {
    /// [`validate`](Self::validate) for each of `rows`, the members of a population: an invalid
    /// member's error names its index (`network 1: tau[0] is -1; ...`).
    pub fn validate_each(rows: &[Params]) -> Result<()> {
        for (p, row) in rows.iter().enumerate() {
            row.validate().map_err(|e| match e {
                Error::InvalidNetwork(m) => Error::InvalidNetwork(format!("network {p}: {m}")),
                other => other,
            })?;
        }
        Ok(())
    }

    /// An owned [`Network`] of these parameters, checked as [`Network::new`] checks them.
    pub fn to_network(&self) -> Result<Network> {
        Network::new(
            self.tau.to_vec(),
            self.theta.to_vec(),
            self.weights.to_vec(),
            self.sensor_weights.to_vec(),
            Some(self.state.to_vec()),
        )
    }
}

fn expect_len(field: &str, got: usize, want: usize, shape: &str) -> Result<()> {
    if got == want {
        Ok(())
    } else {
        Err(Error::InvalidNetwork(format!(
            "{field} has {}; expected {shape} = {want}",
            crate::error::counted(got, "value")
        )))
    }
}

/// Builds the fully interconnected network of `a` and `b` (paper §5.3).
///
/// `a`'s neurons come first, so `a`'s neuron 0 stays neuron 0 (the output); `b`'s neuron j becomes
/// neuron `a.size() + j`. Every sensor feeds both parts as before. The cross weights between the
/// parts start at 0, so the composite first behaves exactly like its two parts side by side;
/// [`compose_with`] draws them instead.
///
/// # Example
/// ```
/// use ctrnn::{compose, Network};
/// let a = Network::new(vec![1.0], vec![0.0], vec![2.0], vec![1.0], None).unwrap();
/// let b = Network::new(vec![3.0], vec![1.0], vec![-2.0], vec![0.5], None).unwrap();
/// let ab = compose(&a, &b).unwrap();
/// assert_eq!(ab.weights(), &[2.0, 0.0, 0.0, -2.0]);
/// ```
pub fn compose(a: &Network, b: &Network) -> Result<Network> {
    join(a, b, || 0.0)
}

/// [`compose`], with each cross weight (from a neuron of one part to a neuron of the other)
/// drawn uniformly in `[-cross_scale, cross_scale]` from `stream`, in row-major order. With
/// `cross_scale = 0` nothing is drawn and the cross weights are 0.
///
/// # Example
/// ```
/// use ctrnn::{compose_with, Network};
/// use ctrnn::rng::{Purpose, Stream};
/// let a = Network::new(vec![1.0], vec![0.0], vec![2.0], vec![1.0], None).unwrap();
/// let b = Network::new(vec![3.0], vec![1.0], vec![-2.0], vec![0.5], None).unwrap();
/// let mut stream = Stream::new(7, 0, Purpose::Seeding, 0, 1);
/// let ab = compose_with(&a, &b, 1.0, &mut stream).unwrap();
/// let w = ab.weights();
/// assert_eq!((w[0], w[3]), (2.0, -2.0));
/// assert!(w[1] != 0.0 && w[1].abs() <= 1.0 && w[2].abs() <= 1.0);
/// ```
pub fn compose_with(
    a: &Network,
    b: &Network,
    cross_scale: f64,
    stream: &mut Stream,
) -> Result<Network> {
    if !(cross_scale.is_finite() && cross_scale >= 0.0) {
        return Err(Error::InvalidArgument(format!(
            "cross_scale is {cross_scale}; it must be a finite number >= 0"
        )));
    }
    if cross_scale == 0.0 {
        return compose(a, b);
    }
    join(a, b, || stream.range(-cross_scale, cross_scale))
}

/// `a` and `b` side by side, each cross weight (row-major) taken from `cross`.
fn join(a: &Network, b: &Network, mut cross: impl FnMut() -> f64) -> Result<Network> {
    if a.n_inputs != b.n_inputs {
        return Err(Error::InvalidNetwork(format!(
            "cannot compose networks with {} and {} inputs; both must have the same M",
            a.n_inputs, b.n_inputs
        )));
    }
    let n = a.size + b.size;
    let in_a = |k: usize| k < a.size;
    let mut weights = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            weights[i * n + j] = match (in_a(i), in_a(j)) {
                (true, true) => a.weights[i * a.size + j],
                (false, false) => b.weights[(i - a.size) * b.size + (j - a.size)],
                _ => cross(),
            };
        }
    }
    let cat = |x: &[f64], y: &[f64]| [x, y].concat();
    Network::new(
        cat(&a.tau, &b.tau),
        cat(&a.theta, &b.theta),
        weights,
        cat(&a.sensor_weights, &b.sensor_weights),
        Some(cat(&a.state, &b.state)),
    )
}
