//! Limit cycles by long integration and a Poincaré section, with Floquet multipliers.
//!
//! From each start the network is integrated (RK4) with its sensors held constant until the
//! transient has passed. If some neuron still moves, the section is the level halfway between
//! that neuron's extremes (the neuron that moves most), crossed upwards. A cycle is closed when
//! the state at a crossing returns, within [`CycleSearch::tolerance`], to the state one, two, three
//! or four crossings earlier; a closure after several crossings may be a cycle of fewer whose
//! crossings alternate about it as they converge (a negative multiplier), which is looked for by
//! waiting while it converges and by extrapolating its crossings, refined by Newton's method
//! (docs/analysis.md). One period from that crossing, integrated together with the
//! variational equation `dPhi/dt = J(v(t)) Phi`, gives the orbit, the amplitude of each neuron and
//! the monodromy matrix, whose eigenvalues are the Floquet multipliers. One multiplier is 1 (along
//! the orbit); the cycle is stable when every other one lies inside the unit circle. An orbit
//! with no multiplier within [`TRIVIAL_MULTIPLIER`] of 1 is not a cycle but a slowly decaying
//! spiral into a focus (near a Hopf point its crossings can come within the tolerance of each
//! other while it still shrinks), and is dropped.
//!
//! Forward integration finds attracting cycles only: an unstable cycle repels every start.

use std::sync::atomic::{AtomicBool, Ordering};

use nalgebra::DMatrix;
use serde::Serialize;

use super::equilibria::{max_abs, starting_states};
use super::field::Field;
use super::stability::eigenvalues;
use crate::error::{Error, Result};
use crate::Network;

/// A closed orbit is a cycle only if one of its Floquet multipliers lies within this of 1 (the
/// trivial one, along the orbit; integration and closing errors move it by about 1e-5).
pub const TRIVIAL_MULTIPLIER: f64 = 1e-3;

/// Settings of a limit-cycle search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CycleSearch {
    /// Starting states (drawn as for [`EquilibriumSearch`](super::EquilibriumSearch)). Default: 8.
    pub starts: usize,
    /// RK4 steps per smallest time constant. Default: 20.
    pub steps_per_tau: usize,
    /// Time discarded as transient, in units of the largest time constant. Default: 100.
    pub transient: f64,
    /// Time searched for a closed orbit after the transient, in largest time constants.
    /// Default: 100.
    pub window: f64,
    /// A neuron whose state varies by less than this after the transient is at rest. Default: 1e-6.
    pub at_rest: f64,
    /// A crossing closes the orbit when it is this close (max norm) to an earlier one.
    /// Default: 1e-5.
    pub tolerance: f64,
    /// Points kept along each orbit, for plots. Default: 200.
    pub orbit_points: usize,
    /// Seed of the starting points. Default: 1.
    pub seed: u64,
}

impl Default for CycleSearch {
    fn default() -> Self {
        CycleSearch {
            starts: 8,
            steps_per_tau: 20,
            transient: 100.0,
            window: 100.0,
            at_rest: 1e-6,
            tolerance: 1e-5,
            orbit_points: 200,
            seed: 1,
        }
    }
}

impl CycleSearch {
    /// Checks every setting: counts >= 1 (`orbit_points >= 2`), times finite and >= 0 (`window`
    /// > 0), tolerances finite and > 0.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &str, v: String, rule: &str| {
            Err(Error::InvalidArgument(format!(
                "{what} is {v}; it must be {rule}"
            )))
        };
        if self.starts == 0 {
            return bad("starts", "0".into(), ">= 1");
        }
        if self.steps_per_tau == 0 {
            return bad("steps_per_tau", "0".into(), ">= 1");
        }
        if self.orbit_points < 2 {
            return bad("orbit_points", self.orbit_points.to_string(), ">= 2");
        }
        if !(self.transient.is_finite() && self.transient >= 0.0) {
            return bad("transient", self.transient.to_string(), "finite and >= 0");
        }
        if !(self.window.is_finite() && self.window > 0.0) {
            return bad("window", self.window.to_string(), "finite and > 0");
        }
        for (what, v) in [("at_rest", self.at_rest), ("tolerance", self.tolerance)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(what, v.to_string(), "finite and > 0");
            }
        }
        Ok(())
    }
}

/// One attracting limit cycle.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Cycle {
    /// The period, in units of simulated time.
    pub period: f64,
    /// Upward crossings of the section per period (1 for a simple loop).
    pub crossings: usize,
    /// The neuron whose level defines the section.
    pub section_neuron: usize,
    /// Per neuron, the state's maximum minus its minimum over one period.
    pub amplitude: Vec<f64>,
    /// Per neuron, the mean firing rate over one period.
    pub mean_outputs: Vec<f64>,
    /// Per neuron, the lowest and highest firing rate over one period.
    pub output_range: Vec<[f64; 2]>,
    /// Floquet multipliers `[re, im]`, largest modulus first; one of them is 1.
    pub multipliers: Vec<[f64; 2]>,
    /// The largest multiplier modulus other than the trivial one (0 for N = 1).
    pub max_multiplier: f64,
    /// Whether every non-trivial multiplier lies inside the unit circle.
    pub stable: bool,
    /// `orbit_points` states along one period, each of length N, starting at the section.
    pub orbit: Vec<Vec<f64>>,
}

/// Work space of RK4 steps of `dv/dt` and, optionally, of the variational equation.
struct Rk4 {
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
    points: [Vec<f64>; 4],
}

impl Rk4 {
    fn new(n: usize) -> Self {
        Rk4 {
            k: std::array::from_fn(|_| vec![0.0; n]),
            tmp: vec![0.0; n],
            points: std::array::from_fn(|_| vec![0.0; n]),
        }
    }

    /// One step of size `h`; with `phi`, the variational equation steps along.
    fn step(&mut self, field: &Field<'_>, v: &mut [f64], phi: Option<&mut DMatrix<f64>>, h: f64) {
        let n = v.len();
        self.points[0].copy_from_slice(v);
        field.rate(v, &mut self.k[0]);
        for s in 1..4 {
            let c = if s == 3 { h } else { h / 2.0 };
            for i in 0..n {
                self.tmp[i] = v[i] + c * self.k[s - 1][i];
            }
            field.rate(&self.tmp, &mut self.k[s]);
            self.points[s].copy_from_slice(&self.tmp);
        }
        if let Some(phi) = phi {
            let j: Vec<DMatrix<f64>> = self.points.iter().map(|p| field.jacobian(p)).collect();
            let k1 = &j[0] * &*phi;
            let k2 = &j[1] * (&*phi + &k1 * (h / 2.0));
            let k3 = &j[2] * (&*phi + &k2 * (h / 2.0));
            let k4 = &j[3] * (&*phi + &k3 * h);
            *phi += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        }
        let k = &self.k;
        for i in 0..n {
            v[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
        }
    }

    /// Where a step of at most `dt` from `from` brings `v_k` to `level` (`v_k` is below it at
    /// `from` and `at_dt` after the full step): the step `h` and the state there, by regula
    /// falsi (Illinois) on RK4 steps of size `h`, so the crossing is as exact as the integration.
    fn cross(
        &mut self,
        field: &Field<'_>,
        from: &[f64],
        dt: f64,
        k: usize,
        level: f64,
        at_dt: f64,
    ) -> (f64, Vec<f64>) {
        let (mut a, mut b) = (0.0, dt);
        let (mut ga, mut gb) = (from[k] - level, at_dt - level);
        let mut x = from.to_vec();
        let mut side = 0;
        let mut h = dt;
        for _ in 0..60 {
            h = if gb - ga > 0.0 {
                a - ga * (b - a) / (gb - ga)
            } else {
                0.5 * (a + b)
            };
            x.copy_from_slice(from);
            self.step(field, &mut x, None, h);
            let g = x[k] - level;
            if g.abs() < 1e-13 || b - a < 1e-15 * dt.max(1.0) {
                return (h, x);
            }
            if g < 0.0 {
                (a, ga) = (h, g);
                if side == -1 {
                    gb /= 2.0;
                }
                side = -1;
            } else {
                (b, gb) = (h, g);
                if side == 1 {
                    ga /= 2.0;
                }
                side = 1;
            }
        }
        (h, x)
    }
}

fn check_cancel(cancel: Option<&AtomicBool>) -> Result<()> {
    match cancel {
        Some(c) if c.load(Ordering::Relaxed) => Err(Error::Interrupted),
        _ => Ok(()),
    }
}

/// Integrates one period from `start` with the variational equation and describes the cycle;
/// None if no multiplier is within [`TRIVIAL_MULTIPLIER`] of 1 (a decaying spiral).
fn describe(
    field: &Field<'_>,
    start: &[f64],
    period: f64,
    crossings: usize,
    section_neuron: usize,
    dt: f64,
    settings: &CycleSearch,
) -> Result<Option<Cycle>> {
    let n = field.size();
    let steps = ((period / dt).ceil() as usize).max(settings.orbit_points);
    let h = period / steps as f64;
    let mut v = start.to_vec();
    let mut phi = DMatrix::<f64>::identity(n, n);
    let (mut lo, mut hi) = (v.clone(), v.clone());
    let theta = field.net.theta();
    let mut mean = vec![0.0; n];
    let mut orbit = Vec::with_capacity(settings.orbit_points);
    let mut rk = Rk4::new(n);
    let every = steps as f64 / settings.orbit_points as f64;
    for s in 0..steps {
        if orbit.len() < settings.orbit_points && s as f64 >= orbit.len() as f64 * every {
            orbit.push(v.clone());
        }
        rk.step(field, &mut v, Some(&mut phi), h);
        for i in 0..n {
            lo[i] = lo[i].min(v[i]);
            hi[i] = hi[i].max(v[i]);
            mean[i] += crate::math::sigmoid(v[i] - theta[i]) / steps as f64;
        }
    }
    let multipliers = eigenvalues(phi)?;
    let mut moduli: Vec<(f64, usize)> = multipliers
        .iter()
        .enumerate()
        .map(|(k, [re, im])| (re.hypot(*im), k))
        .collect();
    let from_one = |z: &[f64; 2]| (z[0] - 1.0).hypot(z[1]);
    let trivial = multipliers
        .iter()
        .enumerate()
        .min_by(|a, b| from_one(a.1).total_cmp(&from_one(b.1)))
        .map(|(k, _)| k);
    if trivial.is_none_or(|k| from_one(&multipliers[k]) > TRIVIAL_MULTIPLIER) {
        return Ok(None);
    }
    let max_multiplier = moduli
        .iter()
        .filter(|(_, k)| Some(*k) != trivial)
        .fold(0.0, |m: f64, (r, _)| m.max(*r));
    moduli.sort_by(|a, b| b.0.total_cmp(&a.0));
    Ok(Some(Cycle {
        period,
        crossings,
        section_neuron,
        amplitude: (0..n).map(|i| hi[i] - lo[i]).collect(),
        output_range: (0..n)
            .map(|i| {
                let f = |v: f64| crate::math::sigmoid(v - theta[i]);
                [f(lo[i]), f(hi[i])]
            })
            .collect(),
        mean_outputs: mean,
        multipliers: moduli.iter().map(|(_, k)| multipliers[*k]).collect(),
        max_multiplier,
        stable: max_multiplier < 1.0,
        orbit,
    }))
}

/// Follows one start; Some(cycle) when the orbit closes.
fn from_start(
    field: &Field<'_>,
    mut v: Vec<f64>,
    dt: f64,
    settings: &CycleSearch,
    tau_max: f64,
    cancel: Option<&AtomicBool>,
) -> Result<Option<Cycle>> {
    let n = field.size();
    let transient = (settings.transient * tau_max / dt).ceil() as usize;
    let mut rk = Rk4::new(n);
    for s in 0..transient {
        if s % 4096 == 0 {
            check_cancel(cancel)?;
        }
        rk.step(field, &mut v, None, dt);
    }
    // A first look over a tenth of the window: which neuron moves most, and between which levels.
    let probe = ((settings.window * tau_max / dt / 10.0).ceil() as usize).max(2);
    let (mut lo, mut hi) = (v.clone(), v.clone());
    for _ in 0..probe {
        rk.step(field, &mut v, None, dt);
        for i in 0..n {
            lo[i] = lo[i].min(v[i]);
            hi[i] = hi[i].max(v[i]);
        }
    }
    let (k, spread) = (0..n)
        .map(|i| (i, hi[i] - lo[i]))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .expect("a network has at least one neuron");
    if spread < settings.at_rest {
        return Ok(None);
    }
    let level = (lo[k] + hi[k]) / 2.0;
    let window = (settings.window * tau_max / dt).ceil() as usize;
    let mut sections: Vec<(f64, Vec<f64>)> = Vec::new();
    // The last closure after several crossings: how many, at which crossing.
    let mut closed: Option<(usize, usize)> = None;
    let mut prev = v.clone();
    for s in 0..window {
        if s % 4096 == 0 {
            check_cancel(cancel)?;
        }
        rk.step(field, &mut v, None, dt);
        if prev[k] < level && v[k] >= level {
            let (h, x) = rk.cross(field, &prev, dt, k, level, v[k]);
            let t = s as f64 * dt + h;
            sections.push((t, x));
            let last = sections.len() - 1;
            match closing(&sections, settings.tolerance) {
                Some(1) => return describe_closed(field, &sections, 1, last, k, dt, settings),
                // A closure after p > 1 crossings may be a cycle of q crossings (q dividing p)
                // whose crossings alternate about it as they converge ([`converging`]): with p
                // more crossings to tell, integration goes on while such a q still converges,
                // until q closes too or the window ends.
                Some(p) => {
                    closed = Some((p, last));
                    let waiting =
                        (1..p).any(|q| p.is_multiple_of(q) && converging(&sections, q, p));
                    if sections.len() > 2 * p && !waiting {
                        return settle(field, &sections, p, last, k, dt, settings);
                    }
                }
                None => {}
            }
        }
        prev.copy_from_slice(&v);
    }
    match closed {
        Some((p, at)) => settle(field, &sections, p, at, k, dt, settings),
        None => Ok(None),
    }
}

/// The cycle of an orbit that closed at crossing `at` after `p > 1` crossings: a stable cycle of
/// fewer crossings `q` (dividing `p`) when the last crossings `q` apart, extrapolated to their
/// limit ([`extrapolated`]) and refined ([`refined`]), give one (so slowly converging that `q`
/// never closed, as near a multiplier of -1), else the orbit that closed. Near a genuine cycle of
/// `p` crossings Newton's method finds no orbit of `q` crossings, or an unstable one, and it is
/// not taken.
fn settle(
    field: &Field<'_>,
    sections: &[(f64, Vec<f64>)],
    p: usize,
    at: usize,
    k: usize,
    dt: f64,
    settings: &CycleSearch,
) -> Result<Option<Cycle>> {
    for q in (1..p).filter(|&q| p.is_multiple_of(q)) {
        let guess = extrapolated(sections, q);
        if let Some((x, period)) =
            guess.and_then(|(x, t)| refined(field, &x, t, k, dt, settings.tolerance))
        {
            if let Some(cycle) = describe(field, &x, period, q, k, dt, settings)? {
                if cycle.stable {
                    return Ok(Some(cycle));
                }
            }
        }
    }
    describe_closed(field, sections, p, at, k, dt, settings)
}

/// Newton steps at most, in [`refined`].
const NEWTON_STEPS: usize = 8;

/// `start` and `period` of a periodic orbit refined by Newton's method: the state `x` on the
/// section (the section neuron `k` held at its value) and the period `T` with `v(T; x) = x`, each
/// step solving `(Phi - I) dx + f(v(T)) dT = x - v(T)` with `dx_k = 0`, `Phi` the monodromy from
/// the variational equation. Some when the orbit closes within `tolerance / 10` in at most
/// [`NEWTON_STEPS`] steps (Newton converges to a periodic orbit, stable or not, when it starts near
/// one), else None: no orbit of that many crossings there.
fn refined(
    field: &Field<'_>,
    start: &[f64],
    period: f64,
    k: usize,
    dt: f64,
    tolerance: f64,
) -> Option<(Vec<f64>, f64)> {
    let n = field.size();
    let (mut x, mut t) = (start.to_vec(), period);
    let mut rk = Rk4::new(n);
    for _ in 0..=NEWTON_STEPS {
        if !(t.is_finite() && t > 0.0) {
            return None;
        }
        let steps = (t / dt).ceil().max(1.0) as usize;
        let h = t / steps as f64;
        let mut v = x.clone();
        let mut phi = DMatrix::<f64>::identity(n, n);
        for _ in 0..steps {
            rk.step(field, &mut v, Some(&mut phi), h);
        }
        let residual: Vec<f64> = v.iter().zip(&x).map(|(a, b)| a - b).collect();
        if !residual.iter().all(|r| r.is_finite()) {
            return None;
        }
        if max_abs(&residual) < tolerance / 10.0 {
            return Some((x, t));
        }
        let mut rate = vec![0.0; n];
        field.rate(&v, &mut rate);
        let a = DMatrix::from_fn(n + 1, n + 1, |i, j| match (i < n, j < n) {
            (true, true) => phi[(i, j)] - if i == j { 1.0 } else { 0.0 },
            (true, false) => rate[i],
            (false, true) => f64::from(u8::from(j == k)),
            (false, false) => 0.0,
        });
        let b = nalgebra::DVector::from_fn(n + 1, |i, _| if i < n { -residual[i] } else { 0.0 });
        let step = a.lu().solve(&b)?;
        for i in 0..n {
            x[i] += step[i];
        }
        t += step[n];
    }
    None
}

/// [`describe`] of the orbit that closed at crossing `at` after `p` crossings.
fn describe_closed(
    field: &Field<'_>,
    sections: &[(f64, Vec<f64>)],
    p: usize,
    at: usize,
    k: usize,
    dt: f64,
    settings: &CycleSearch,
) -> Result<Option<Cycle>> {
    let (t, x) = &sections[at];
    describe(field, x, t - sections[at - p].0, p, k, dt, settings)
}

/// The limit of crossings `q` apart that alternate about a cycle's as they converge, and its
/// period: with `r` the ratio of the last two gaps `q` apart (the modulus of the cycle's
/// dominant multiplier), `x* = (x_k + r x_{k-q}) / (1 + r)`, and the same of the last two
/// periods. None without the crossings to tell or when the gaps do not shrink.
fn extrapolated(sections: &[(f64, Vec<f64>)], q: usize) -> Option<(Vec<f64>, f64)> {
    let k = sections.len().checked_sub(1)?;
    if k < 2 * q {
        return None;
    }
    let (a, b, c) = (&sections[k], &sections[k - q], &sections[k - 2 * q]);
    let r = gap(&a.1, &b.1) / gap(&b.1, &c.1);
    if !(r.is_finite() && r < 1.0) {
        return None;
    }
    let x =
        a.1.iter()
            .zip(&b.1)
            .map(|(p, q)| (p + r * q) / (1.0 + r))
            .collect();
    let period = ((a.0 - b.0) + r * (b.0 - c.0)) / (1.0 + r);
    Some((x, period))
}

/// The state at crossing `a` minus the one at crossing `b`, in the max norm; NaN when either has
/// a NaN coordinate (which `max_abs` would pass over), so that a NaN never closes a cycle.
fn gap(a: &[f64], b: &[f64]) -> f64 {
    if a.iter().chain(b).any(|x| x.is_nan()) {
        return f64::NAN;
    }
    max_abs(&a.iter().zip(b).map(|(x, y)| x - y).collect::<Vec<_>>())
}

/// The fewest crossings (1 to 4) after which the last crossing's state returns within
/// `tolerance` to an earlier one, if any.
fn closing(sections: &[(f64, Vec<f64>)], tolerance: f64) -> Option<usize> {
    let last = sections.len() - 1;
    (1..=4.min(last)).find(|&p| gap(&sections[last].1, &sections[last - p].1) < tolerance)
}

/// Whether the orbit that closed after `p` crossings is one of `q` crossings (`q` divides `p`)
/// still converging: the gap between crossings `q` apart shrank by more than
/// [`CONVERGING`] over the last `p` crossings. Near a cycle whose dominant Floquet multiplier is
/// negative, the crossings alternate about the cycle's, so those two apart close the tolerance
/// first; on a cycle of `p` crossings the gap `q` apart stays the distance between two of them.
fn converging(sections: &[(f64, Vec<f64>)], q: usize, p: usize) -> bool {
    let last = sections.len() - 1;
    if last < p + q {
        return false;
    }
    let lag = |at: usize| gap(&sections[at].1, &sections[at - q].1);
    lag(last) < CONVERGING * lag(last - p)
}

/// See [`converging`]: a gap that keeps more than this share of itself over `p` crossings is a
/// cycle's, not a convergence's (the crossings of a converged cycle of `p` crossings keep their
/// gaps to about the tolerance, which is far smaller than a gap between two of them).
const CONVERGING: f64 = 0.99;

/// The distinct attracting limit cycles reached from `extra` starts and the search's own.
pub(crate) fn search(
    field: &Field<'_>,
    settings: &CycleSearch,
    extra: &[Vec<f64>],
    cancel: Option<&AtomicBool>,
) -> Result<Vec<Cycle>> {
    settings.validate()?;
    let mut found: Vec<Cycle> = Vec::new();
    let starts = starting_states(field, settings.starts, settings.seed);
    for start in extra.iter().cloned().chain(starts) {
        let Some(cycle) = follow(field, settings, start, cancel)? else {
            continue;
        };
        if !found.iter().any(|c| same_cycle(c, &cycle)) {
            found.push(cycle);
        }
    }
    found.sort_by(|a, b| a.period.total_cmp(&b.period));
    Ok(found)
}

/// The attracting cycle reached from `start`, if the orbit closes: the integration of one start
/// of [`search`], at `tau_min / steps_per_tau` for `transient` then `window` largest time
/// constants.
pub(crate) fn follow(
    field: &Field<'_>,
    settings: &CycleSearch,
    start: Vec<f64>,
    cancel: Option<&AtomicBool>,
) -> Result<Option<Cycle>> {
    let tau = field.net.tau();
    let tau_max = tau.iter().fold(0.0, |m: f64, t| m.max(*t));
    let tau_min = tau.iter().fold(f64::INFINITY, |m: f64, t| m.min(*t));
    let dt = tau_min / settings.steps_per_tau as f64;
    from_start(field, start, dt, settings, tau_max, cancel)
}

/// Whether two cycles are one: close periods and the second's first point near the first's orbit.
pub(crate) fn same_cycle(a: &Cycle, b: &Cycle) -> bool {
    if (a.period - b.period).abs() > 1e-3 * a.period.max(b.period) {
        return false;
    }
    let dist =
        |x: &[f64], y: &[f64]| max_abs(&x.iter().zip(y).map(|(p, q)| p - q).collect::<Vec<_>>());
    let step = a
        .orbit
        .windows(2)
        .map(|w| dist(&w[0], &w[1]))
        .fold(0.0, f64::max);
    a.orbit.iter().any(|p| dist(p, &b.orbit[0]) <= step + 1e-6)
}

/// The attracting limit cycles of `net` with its sensors held at `input`, from the search's
/// starts, sorted by period.
///
/// # Example
/// ```
/// use ctrnn::analysis::{limit_cycles, CycleSearch};
/// use ctrnn::Network;
/// // Two self-exciting neurons coupled with opposite signs, thresholds at the centre: an
/// // oscillator (the equilibrium at v = theta is an unstable focus).
/// let net = Network::new(
///     vec![1.0, 1.0], vec![3.25, 2.25], vec![5.5, 1.0, -1.0, 5.5], vec![], None,
/// )?;
/// let cycles = limit_cycles(&net, &[], &CycleSearch::default(), None)?;
/// assert_eq!(cycles.len(), 1);
/// assert!(cycles[0].stable && cycles[0].period > 1.0);
/// # Ok::<(), ctrnn::Error>(())
/// ```
pub fn limit_cycles(
    net: &Network,
    input: &[f64],
    settings: &CycleSearch,
    cancel: Option<&AtomicBool>,
) -> Result<Vec<Cycle>> {
    search(&Field::new(net, input)?, settings, &[], cancel)
}
