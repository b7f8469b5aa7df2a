//! The network's vector field under a constant input, its Jacobian, and the box its equilibria
//! lie in.
//!
//! With the sensors held at a constant vector `I`, the drive `c_i = sum_k sensor_weights[i][k] I_k`
//! is a constant, and the network is the autonomous system
//!
//! ```text
//! dv_i/dt = F_i(v) = G_i(v) / tau_i,   G_i(v) = -v_i + sum_j weights[i][j] f(v_j - theta_j) + c_i
//! ```
//!
//! Its equilibria are the zeros of `G` (the time constants do not move them), and its Jacobian is
//! `J_ij = (-delta_ij + weights[i][j] f'(v_j - theta_j)) / tau_i` with `f' = f (1 - f)`.
//!
//! Since `0 < f < 1`, every equilibrium `v_i = sum_j weights[i][j] f_j + c_i` lies between `c_i`
//! plus the sum of the negative weights of row i and `c_i` plus the sum of its positive ones.

use nalgebra::DMatrix;

use crate::error::{Error, Result};
use crate::math::firing_rates;
use crate::Network;

/// A network with its sensors held at one constant input vector.
#[derive(Clone, Debug)]
pub(crate) struct Field<'a> {
    pub(crate) net: &'a Network,
    /// `c_i`, the constant sensor drive of neuron i.
    pub(crate) drive: Vec<f64>,
}

impl<'a> Field<'a> {
    /// Checks `input` (length M, every value finite) and computes the drive.
    pub(crate) fn new(net: &'a Network, input: &[f64]) -> Result<Self> {
        let (n, m) = (net.size(), net.n_inputs());
        if input.len() != m {
            return Err(Error::InvalidArgument(format!(
                "input has {}; this network has M = {m} sensors, so it needs {m}",
                crate::error::counted(input.len(), "value")
            )));
        }
        if let Some(k) = input.iter().position(|x| !x.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "input[{k}] is {}; every input must be finite",
                input[k]
            )));
        }
        let s = net.sensor_weights();
        let drive = (0..n)
            .map(|i| (0..m).map(|k| s[i * m + k] * input[k]).sum())
            .collect();
        Ok(Field { net, drive })
    }

    pub(crate) fn size(&self) -> usize {
        self.net.size()
    }

    /// `G(v)` into `out`: zero exactly at the equilibria.
    pub(crate) fn residual(&self, v: &[f64], out: &mut [f64]) {
        let (n, w, theta) = (self.size(), self.net.weights(), self.net.theta());
        let mut f = vec![0.0; n];
        firing_rates(v, theta, &mut f);
        for i in 0..n {
            let row = &w[i * n..(i + 1) * n];
            out[i] = -v[i] + row.iter().zip(&f).map(|(a, b)| a * b).sum::<f64>() + self.drive[i];
        }
    }

    /// `dv/dt = G(v) / tau` into `out`.
    pub(crate) fn rate(&self, v: &[f64], out: &mut [f64]) {
        self.residual(v, out);
        for (o, t) in out.iter_mut().zip(self.net.tau()) {
            *o /= t;
        }
    }

    /// The Jacobian of `G` (without the time constants).
    pub(crate) fn residual_jacobian(&self, v: &[f64]) -> DMatrix<f64> {
        let (n, w, theta) = (self.size(), self.net.weights(), self.net.theta());
        let mut slope = vec![0.0; n];
        firing_rates(v, theta, &mut slope);
        for f in &mut slope {
            *f *= 1.0 - *f;
        }
        DMatrix::from_fn(n, n, |i, j| {
            w[i * n + j] * slope[j] - if i == j { 1.0 } else { 0.0 }
        })
    }

    /// The Jacobian of the vector field `dv/dt`.
    pub(crate) fn jacobian(&self, v: &[f64]) -> DMatrix<f64> {
        let mut j = self.residual_jacobian(v);
        for (i, t) in self.net.tau().iter().enumerate() {
            j.row_mut(i).scale_mut(1.0 / t);
        }
        j
    }
}

/// The vector field `dv/dt` of `net` at `state` with the sensors held at `input`.
///
/// # Example
/// ```
/// use ctrnn::{analysis, Network};
/// let net = Network::new(vec![2.0], vec![0.0], vec![0.0], vec![1.0], None)?;
/// // tau dv/dt = -v + I: at v = 0 with I = 3, dv/dt = 3 / 2.
/// assert_eq!(analysis::vector_field(&net, &[3.0], &[0.0])?, vec![1.5]);
/// # Ok::<(), ctrnn::Error>(())
/// ```
pub fn vector_field(net: &Network, input: &[f64], state: &[f64]) -> Result<Vec<f64>> {
    let field = Field::new(net, input)?;
    check_state(net, state)?;
    let mut out = vec![0.0; net.size()];
    field.rate(state, &mut out);
    Ok(out)
}

/// The Jacobian of `dv/dt` at `state`, N x N row-major: `[i * N + j]` is `d(dv_i/dt) / dv_j`.
///
/// # Example
/// ```
/// use ctrnn::{analysis, Network};
/// let net = Network::new(vec![2.0], vec![0.0], vec![4.0], vec![], None)?;
/// // At v = theta the slope of f is 1/4: J = (-1 + 4 / 4) / 2 = 0.
/// assert_eq!(analysis::jacobian(&net, &[], &[0.0])?, vec![0.0]);
/// # Ok::<(), ctrnn::Error>(())
/// ```
pub fn jacobian(net: &Network, input: &[f64], state: &[f64]) -> Result<Vec<f64>> {
    let field = Field::new(net, input)?;
    check_state(net, state)?;
    Ok(field.jacobian(state).transpose().as_slice().to_vec())
}

/// Checks a state has N finite values.
pub(crate) fn check_state(net: &Network, state: &[f64]) -> Result<()> {
    if state.len() != net.size() {
        return Err(Error::InvalidArgument(format!(
            "state has {} values; this network has N = {} neurons",
            state.len(),
            net.size()
        )));
    }
    if let Some(i) = state.iter().position(|x| !x.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "state[{i}] is {}; every value must be finite",
            state[i]
        )));
    }
    Ok(())
}
