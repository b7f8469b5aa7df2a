//! Every equilibrium of a network under a constant input: Newton's method from many starts,
//! deduplicated, each with its eigenvalues and stability.
//!
//! Starts are drawn in output space: a vector of firing rates `o` in (0, 1)^N maps to the state
//! `v = weights o + c`, which lies in the box that holds every equilibrium (each `v_i` between
//! `c_i` plus the negative and `c_i` plus the positive weights of row i). Half of the starts are near a random corner of the
//! output cube (each rate 0.05 or 0.95, jittered), where evolved networks tend to sit; the other
//! half are uniform. The draws come from a fixed seed, so a search is deterministic.
//!
//! Newton's method is damped (the step is halved until `|G|` falls), and a start that stalls is
//! dropped. This finds every equilibrium reachable from some start; none is guaranteed for large
//! N, so raise [`EquilibriumSearch::starts`] to check a result.
//!
//! A generic network has an **odd** number of equilibria: the vector field points inward on a
//! large enough box, so their indices add up to 1. An even count therefore means that some were
//! missed, and the search is repeated with [`EquilibriumSearch::retry_starts`] starts (default
//! [`RETRY_STARTS`]). This is the one place that rule lives: `dnnevo analyze`, its conditions and
//! its sweeps all search through here.

use std::sync::atomic::{AtomicBool, Ordering};

use serde::Serialize;

use super::field::Field;
use super::stability::{eigenvalues, time_scale, Stability};
use crate::error::{Error, Result};
use crate::math::sigmoid;
use crate::Network;

/// Starts of the second search when the first finds an even number of equilibria (the default
/// of [`EquilibriumSearch::retry_starts`]); 0.2 s for 10 neurons with weights up to 16.
pub const RETRY_STARTS: usize = 8192;

/// Settings of an equilibrium search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EquilibriumSearch {
    /// Newton starts. Default: 512.
    pub starts: usize,
    /// An equilibrium is accepted when every `|G_i(v)| = tau_i |dv_i/dt|` is below this.
    /// Default: 1e-10.
    pub tolerance: f64,
    /// Two equilibria closer than this in every coordinate are one. Default: 1e-6.
    pub distinct: f64,
    /// Newton iterations per start. Default: 100.
    pub max_iterations: usize,
    /// Seed of the starting points. Default: 0.
    pub seed: u64,
    /// When the search finds an even number of equilibria (so it missed some), it searches again
    /// with this many starts, if more than `starts`; 0 never searches again. Default:
    /// [`RETRY_STARTS`].
    pub retry_starts: usize,
}

impl Default for EquilibriumSearch {
    fn default() -> Self {
        EquilibriumSearch {
            starts: 512,
            tolerance: 1e-10,
            distinct: 1e-6,
            max_iterations: 100,
            seed: 0,
            retry_starts: RETRY_STARTS,
        }
    }
}

impl EquilibriumSearch {
    /// Checks every setting: `starts >= 1`, `max_iterations >= 1`, and
    /// `0 < tolerance < distinct`, both finite.
    pub fn validate(&self) -> Result<()> {
        if self.starts == 0 {
            return Err(Error::InvalidArgument(
                "starts is 0; an equilibrium search needs at least 1 start".into(),
            ));
        }
        if self.max_iterations == 0 {
            return Err(Error::InvalidArgument(
                "max_iterations is 0; it must be >= 1".into(),
            ));
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "tolerance is {}; it must be finite and > 0",
                self.tolerance
            )));
        }
        if !(self.distinct.is_finite() && self.distinct > self.tolerance) {
            return Err(Error::InvalidArgument(format!(
                "distinct is {}; it must be finite and > tolerance ({})",
                self.distinct, self.tolerance
            )));
        }
        Ok(())
    }
}

/// One equilibrium and its linear stability.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Equilibrium {
    /// The state v, length N.
    pub state: Vec<f64>,
    /// The firing rates `f(v - theta)` there.
    pub outputs: Vec<f64>,
    /// Eigenvalues of the Jacobian of `dv/dt` as `[re, im]`, largest real part first.
    pub eigenvalues: Vec<[f64; 2]>,
    /// The stability class the eigenvalues give.
    pub stability: Stability,
    /// How many eigenvalues have a positive real part.
    pub unstable_dimensions: usize,
    /// `1 / min |Re lambda|`: the slowest approach (or departure) time; None when non-hyperbolic.
    pub time_scale: Option<f64>,
    /// `max_i |G_i(v)|`, the distance from an exact zero of the vector field times tau.
    pub residual: f64,
}

impl Equilibrium {
    /// Linearises `field` at `state`.
    pub(crate) fn at(field: &Field<'_>, state: Vec<f64>) -> Result<Self> {
        let n = field.size();
        let mut g = vec![0.0; n];
        field.residual(&state, &mut g);
        let eigenvalues = eigenvalues(field.jacobian(&state))?;
        let theta = field.net.theta();
        Ok(Equilibrium {
            outputs: (0..n).map(|i| sigmoid(state[i] - theta[i])).collect(),
            stability: Stability::classify(&eigenvalues),
            unstable_dimensions: eigenvalues.iter().filter(|[re, _]| *re > 0.0).count(),
            time_scale: time_scale(&eigenvalues),
            residual: max_abs(&g),
            eigenvalues,
            state,
        })
    }
}

pub(crate) fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0, |m, v| m.max(v.abs()))
}

/// splitmix64: a small, fixed stream of starting points.
pub(crate) struct Draws(u64);

impl Draws {
    pub(crate) fn new(seed: u64) -> Self {
        Draws(seed ^ 0x5DEE_CE66_D1CE_4E5B)
    }
    /// A uniform value in [0, 1).
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `count` starting states: `v = weights o + c` for output vectors o, half near the corners of the
/// output cube and half uniform, the first one the centre (`o = 1/2`).
pub(crate) fn starting_states(field: &Field<'_>, count: usize, seed: u64) -> Vec<Vec<f64>> {
    let (n, w) = (field.size(), field.net.weights());
    let mut draws = Draws::new(seed);
    (0..count)
        .map(|s| {
            let o: Vec<f64> = (0..n)
                .map(|_| match s {
                    0 => 0.5,
                    _ if s % 2 == 1 => {
                        let jitter = 0.04 * draws.next();
                        if draws.next() < 0.5 {
                            0.01 + jitter
                        } else {
                            0.99 - jitter
                        }
                    }
                    _ => draws.next(),
                })
                .collect();
            (0..n)
                .map(|i| {
                    let row = &w[i * n..(i + 1) * n];
                    row.iter().zip(&o).map(|(a, b)| a * b).sum::<f64>() + field.drive[i]
                })
                .collect()
        })
        .collect()
}

/// Damped Newton on `G` from `v`; Some(root) when `max |G| <= tolerance` within `max_iterations`.
pub(crate) fn newton(
    field: &Field<'_>,
    mut v: Vec<f64>,
    tolerance: f64,
    max_iterations: usize,
) -> Option<Vec<f64>> {
    let n = field.size();
    let mut g = vec![0.0; n];
    let mut trial = vec![0.0; n];
    let mut g_trial = vec![0.0; n];
    field.residual(&v, &mut g);
    let norm = |x: &[f64]| x.iter().map(|a| a * a).sum::<f64>();
    for _ in 0..max_iterations {
        if within(&g, tolerance) {
            return Some(v);
        }
        let rhs = nalgebra::DVector::from_iterator(n, g.iter().map(|x| -x));
        let step = field.residual_jacobian(&v).lu().solve(&rhs)?;
        let before = norm(&g);
        let mut scale = 1.0;
        loop {
            for i in 0..n {
                trial[i] = v[i] + scale * step[i];
            }
            field.residual(&trial, &mut g_trial);
            if norm(&g_trial) < before || within(&g_trial, tolerance) {
                break;
            }
            scale *= 0.5;
            if scale < 1e-8 {
                return None;
            }
        }
        std::mem::swap(&mut v, &mut trial);
        std::mem::swap(&mut g, &mut g_trial);
    }
    within(&g, tolerance).then_some(v)
}

/// Whether every residual is within `tolerance` of 0; a NaN never is (a network whose sums
/// overflow has none, and `max_abs`, built on `f64::max`, would pass over it).
fn within(g: &[f64], tolerance: f64) -> bool {
    g.iter().all(|x| x.abs() <= tolerance)
}

/// How far apart (max norm) two roots may be and still be one degenerate equilibrium, when the
/// residual stays within tolerance between them ([`insert_distinct`]).
const DEGENERATE_SPAN: f64 = 1e-2;

/// Points between two roots at which [`insert_distinct`] checks the residual.
const BETWEEN: [f64; 3] = [0.25, 0.5, 0.75];

/// Adds `v` to `found` unless an equilibrium within `distinct` (max norm) is already there, or
/// one within [`DEGENERATE_SPAN`] with the residual within `tolerance` all along the way
/// between them ([`BETWEEN`]): then both are points of one degenerate equilibrium (at a fold
/// or a cusp `G` is flat, and Newton stops anywhere its residual is small, up to about `1e-3`
/// from the root), and the one with the smaller residual is kept. Two distinct simple roots
/// have a residual away from 0 between them.
pub(crate) fn insert_distinct(
    found: &mut Vec<Vec<f64>>,
    v: Vec<f64>,
    field: &Field<'_>,
    distinct: f64,
    tolerance: f64,
) {
    let gap = |u: &[f64]| {
        u.iter()
            .zip(&v)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    if found.iter().any(|u| gap(u) < distinct) {
        return;
    }
    let mut g = vec![0.0; v.len()];
    let mut residual = |x: &[f64]| {
        field.residual(x, &mut g);
        g.iter().map(|r| r.abs()).fold(0.0, f64::max)
    };
    let flat_to = |u: &[f64], residual: &mut dyn FnMut(&[f64]) -> f64| {
        gap(u) < DEGENERATE_SPAN
            && BETWEEN.iter().all(|&t| {
                let x: Vec<f64> = u.iter().zip(&v).map(|(a, b)| a + t * (b - a)).collect();
                residual(&x) <= tolerance
            })
    };
    match (0..found.len()).find(|&k| flat_to(&found[k], &mut residual)) {
        Some(k) => {
            if residual(&v) < residual(&found[k]) {
                found[k] = v;
            }
        }
        None => found.push(v),
    }
}

/// What one search found.
pub(crate) struct Found {
    /// Sorted by state, each linearised.
    pub(crate) equilibria: Vec<Equilibrium>,
    /// Whether the first search found an even number and the search was repeated with
    /// `retry_starts` starts.
    pub(crate) retried: bool,
}

/// Every equilibrium found from the search's starts (and from `extra` starts, if any), sorted by
/// state (lexicographic), each linearised; searched again with `retry_starts` starts when the
/// count is even.
pub(crate) fn search(
    field: &Field<'_>,
    settings: &EquilibriumSearch,
    extra: &[Vec<f64>],
    cancel: Option<&AtomicBool>,
) -> Result<Found> {
    settings.validate()?;
    let first = search_from(field, settings, settings.starts, extra, cancel)?;
    if first.len() % 2 == 1 || settings.retry_starts <= settings.starts {
        return Ok(Found {
            equilibria: first,
            retried: false,
        });
    }
    // The first search's roots are starts too, so the second finds no fewer.
    let mut again: Vec<Vec<f64>> = first.into_iter().map(|e| e.state).collect();
    again.extend_from_slice(extra);
    Ok(Found {
        equilibria: search_from(field, settings, settings.retry_starts, &again, cancel)?,
        retried: true,
    })
}

fn search_from(
    field: &Field<'_>,
    settings: &EquilibriumSearch,
    starts: usize,
    extra: &[Vec<f64>],
    cancel: Option<&AtomicBool>,
) -> Result<Vec<Equilibrium>> {
    let mut roots = Vec::new();
    let starts = starting_states(field, starts, settings.seed);
    for v in extra.iter().cloned().chain(starts) {
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return Err(Error::Interrupted);
        }
        if let Some(r) = newton(field, v, settings.tolerance, settings.max_iterations) {
            insert_distinct(&mut roots, r, field, settings.distinct, settings.tolerance);
        }
    }
    roots.sort_by(|a, b| {
        a.iter()
            .zip(b)
            .map(|(x, y)| x.total_cmp(y))
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    roots
        .into_iter()
        .map(|r| Equilibrium::at(field, r))
        .collect()
}

/// Every equilibrium of `net` with its sensors held at `input` that Newton's method reaches from
/// the search's starts, sorted by state. When their count is even, some were missed, and the
/// search is repeated with [`EquilibriumSearch::retry_starts`] starts; a count that is still even
/// is returned as found (the caller can tell by its parity).
///
/// # Example
/// ```
/// use ctrnn::analysis::{equilibria, EquilibriumSearch, Stability};
/// use ctrnn::Network;
/// // One neuron exciting itself (w = 8 > 4) with its threshold at the centre (theta = w / 2):
/// // two stable states with an unstable one between them.
/// let net = Network::new(vec![1.0], vec![4.0], vec![8.0], vec![], None)?;
/// let eq = equilibria(&net, &[], &EquilibriumSearch::default())?;
/// let kinds: Vec<_> = eq.iter().map(|e| e.stability).collect();
/// assert_eq!(kinds, [Stability::StableNode, Stability::UnstableNode, Stability::StableNode]);
/// assert!((eq[1].state[0] - 4.0).abs() < 1e-9);
/// # Ok::<(), ctrnn::Error>(())
/// ```
pub fn equilibria(
    net: &Network,
    input: &[f64],
    settings: &EquilibriumSearch,
) -> Result<Vec<Equilibrium>> {
    equilibria_cancellable(net, input, settings, None)
}

/// [`equilibria`] that stops with [`Error::Interrupted`] soon after `cancel` is set (checked
/// before each start's Newton search).
pub fn equilibria_cancellable(
    net: &Network,
    input: &[f64],
    settings: &EquilibriumSearch,
    cancel: Option<&AtomicBool>,
) -> Result<Vec<Equilibrium>> {
    Ok(search(&Field::new(net, input)?, settings, &[], cancel)?.equilibria)
}
