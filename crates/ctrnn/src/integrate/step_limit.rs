//! The longest step a set of networks can take: `dt / tau` below where the method's steps make
//! a neuron's own decay grow ([`Integrator::check_step`]), for the shortest time constant.

use crate::error::Result;
use crate::integrate::Integrator;
use crate::network::Params;

/// Fails when a step of `integ` is too long for the shortest time constant among `rows`
/// ([`Integrator::check_step`]), naming the member and neuron (`network 1's tau[0]`) when there
/// is more than one member.
///
/// ```
/// use ctrnn::{integrate::check_step, Integrator, Network};
/// let slow = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![], None)?;
/// let fast = Network::new(vec![0.01], vec![0.0], vec![0.0], vec![], None)?;
/// let e = check_step(&[slow.params(), fast.params()], &Integrator::default()).unwrap_err();
/// assert!(e.to_string().contains("dt / tau is 10 for network 1's tau[0] = 0.01"), "{e}");
/// # Ok::<(), ctrnn::Error>(())
/// ```
pub fn check_step(rows: &[Params], integ: &Integrator) -> Result<()> {
    Shortest::of(rows).map_or(Ok(()), |s| s.check(integ))
}

/// The shortest time constant of a set of networks, and where it is.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shortest {
    network: usize,
    neuron: usize,
    tau: f64,
    many: bool,
}

impl Shortest {
    /// Among `rows`' time constants; None when there are none.
    pub(crate) fn of(rows: &[Params]) -> Option<Shortest> {
        rows.iter()
            .enumerate()
            .flat_map(|(p, row)| row.tau.iter().enumerate().map(move |(i, &t)| (p, i, t)))
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .map(|(network, neuron, tau)| Shortest {
                network,
                neuron,
                tau,
                many: rows.len() > 1,
            })
    }

    /// [`Integrator::check_step`] for it.
    pub(crate) fn check(&self, integ: &Integrator) -> Result<()> {
        let (p, i) = (self.network, self.neuron);
        match self.many {
            true => integ.check_step(self.tau, &format!("network {p}'s tau[{i}]")),
            false => integ.check_step(self.tau, &format!("tau[{i}]")),
        }
    }
}
