//! Folds and Hopf points: what they are, and how one is located between two input values of a
//! sweep. [`At`] looks at the system at one input value: it links the equilibria of two values,
//! and bisects between them to where an equilibrium vanishes (a fold) or a complex pair of
//! eigenvalues crosses the imaginary axis (a Hopf point). See the `bifurcation` module.

use serde::Serialize;

use super::equilibria::{max_abs, newton, Equilibrium, EquilibriumSearch};
use super::field::Field;
use super::stability::eigenvalues;
use crate::error::Result;
use crate::Network;

/// Bisection steps that locate an event between two input values.
const BISECTIONS: usize = 40;
/// Newton continuation steps from the last good input value to each bisection trial value,
/// and from one swept value to the next when linking their equilibria.
const WALK: usize = 4;
/// How often a linking step may be halved when its root is not a smooth continuation.
const HALVINGS: u32 = 6;
/// The most a linking step may move the state, relative to `1 + max |v|`.
const SMOOTH: f64 = 0.1;
/// An event is kept only if its critical eigenvalue's real part is within this of 0, relative to
/// the largest eigenvalue modulus (at least 1): a link between input values that was wrong, or a
/// search that missed an equilibrium at one value, then reports nothing instead of a false event.
pub const CRITICAL: f64 = 1e-3;

/// What happens at an event.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// Two equilibria meet and vanish (or appear): a real eigenvalue passes through 0.
    Fold,
    /// A complex pair of eigenvalues crosses the imaginary axis: a limit cycle is born or dies.
    Hopf,
}

/// A fold or Hopf point located in a sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Event {
    /// Fold or Hopf.
    pub kind: EventKind,
    /// The input value where it happens.
    pub value: f64,
    /// The equilibrium there. Two events at nearly the same input value are told apart by it:
    /// two folds at one value are two different pairs of equilibria meeting.
    pub state: Vec<f64>,
    /// The firing rates `f(v - theta)` there.
    pub outputs: Vec<f64>,
    /// The critical eigenvalue `[re, im]` there: the real one nearest 0 (fold), or the one with
    /// positive imaginary part nearest the imaginary axis (Hopf).
    pub eigenvalue: [f64; 2],
}
pub(super) fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// Index of the nearest state of `among` to `x`.
fn nearest(x: &[f64], among: &[Equilibrium]) -> Option<usize> {
    (0..among.len())
        .min_by(|&a, &b| distance(x, &among[a].state).total_cmp(&distance(x, &among[b].state)))
}

/// Half the distance from `e` to the nearest other of `others` (at least 1e-3): how far one
/// continuation step from `e` may move before it may have reached another equilibrium.
fn reach(e: &Equilibrium, others: &[Equilibrium]) -> f64 {
    let nearest = others
        .iter()
        .map(|o| distance(&o.state, &e.state))
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    (nearest / 2.0).max(1e-3)
}

/// Eigenvalues with positive real part, real or complex.
pub(super) fn unstable(e: &Equilibrium) -> usize {
    e.eigenvalues.iter().filter(|[re, _]| *re > 0.0).count()
}

/// Whether `det(J)`, the product of the eigenvalues, is positive: an even count of negative
/// real eigenvalues (a complex pair's product is positive). A real eigenvalue through 0 (a
/// fold) changes it; a complex pair through the imaginary axis (a Hopf point) does not.
pub(super) fn det_positive(e: &Equilibrium) -> bool {
    e.eigenvalues
        .iter()
        .filter(|[re, im]| *im == 0.0 && *re < 0.0)
        .count()
        % 2
        == 0
}

fn det_sign(field: &Field<'_>, v: &[f64]) -> f64 {
    field.residual_jacobian(v).lu().determinant().signum()
}

/// Everything needed to look at the system at one input value.
pub struct At<'a> {
    net: &'a Network,
    base: Vec<f64>,
    input: usize,
    pub(crate) search: EquilibriumSearch,
}

impl<'a> At<'a> {
    /// `net` with input `input` swept, the others held at `base`.
    pub fn new(net: &'a Network, base: &[f64], input: usize, search: EquilibriumSearch) -> Self {
        At {
            net,
            base: base.to_vec(),
            input,
            search,
        }
    }

    pub(crate) fn field(&self, value: f64) -> Result<Field<'_>> {
        let mut input = self.base.clone();
        input[self.input] = value;
        Field::new(self.net, &input)
    }

    /// For each of `from` (equilibria at input `start`), the one of `to` (the equilibria at
    /// input `value`) that [`At::walk`] reaches from it, if any. One Newton step from `start`
    /// to `value` lost equilibria that move fast (a half-centre's moved by 1 in state between
    /// two values of a 101-value sweep, where its Hopf point is); an unguarded walk in a few
    /// steps went past a fold onto the other branch of a hysteresis loop and hid both folds.
    pub(super) fn link(
        &self,
        start: f64,
        value: f64,
        from: &[Equilibrium],
        to: &[Equilibrium],
    ) -> Result<Vec<Option<usize>>> {
        let here = self.field(start)?;
        from.iter()
            .map(|e| {
                let sign = det_sign(&here, &e.state);
                let Some(r) = self.walk(start, value, &e.state, sign, reach(e, from))? else {
                    return Ok(None);
                };
                Ok(nearest(&r, to)
                    .and_then(|k| (distance(&r, &to[k].state) < self.search.distinct).then_some(k)))
            })
            .collect()
    }

    /// Follows the equilibrium `v` at input `start` to input `end` by Newton continuation in
    /// [`WALK`] steps, halving a step (at most [`HALVINGS`] times) whose root changes the sign of
    /// `det`, moves `reach` or more (towards another equilibrium), or moves more than [`SMOOTH`]
    /// relative to the state: a branch moves less the shorter the step, a jump to another
    /// branch past a fold does not. None when the walk cannot go on: the equilibrium vanished.
    fn walk(
        &self,
        start: f64,
        end: f64,
        v: &[f64],
        sign: f64,
        reach: f64,
    ) -> Result<Option<Vec<f64>>> {
        let mut state = v.to_vec();
        let (mut at, mut step) = (start, (end - start) / WALK as f64);
        let shortest = (end - start).abs() / (WALK as f64 * f64::from(1u32 << HALVINGS));
        while at != end {
            let p = if (end - at).abs() <= step.abs() * (1.0 + 1e-9) {
                end
            } else {
                at + step
            };
            let field = self.field(p)?;
            let root = newton(
                &field,
                state.clone(),
                self.search.tolerance,
                self.search.max_iterations,
            )
            .filter(|r| {
                let moved = distance(r, &state);
                det_sign(&field, r) == sign
                    && moved < reach
                    && moved <= SMOOTH * (1.0 + max_abs(&state))
            });
            match root {
                Some(r) => (state, at) = (r, p),
                None if step.abs() > shortest * (1.0 + 1e-9) => step /= 2.0,
                None => return Ok(None),
            }
        }
        Ok(Some(state))
    }

    /// Follows the equilibrium at `v` (input `a`) towards input `b` while `alive` holds;
    /// returns the last value where it did and the equilibrium there, or None if it never
    /// got past `a`. Each bisection trial walks from the last good value in [`WALK`] Newton
    /// continuation steps, and `alive(field, root, previous root)` judges every step.
    fn bisect(
        &self,
        a: f64,
        b: f64,
        v: &[f64],
        alive: impl Fn(&Field<'_>, &[f64], &[f64]) -> Result<bool>,
    ) -> Result<Option<(f64, Vec<f64>)>> {
        let (mut good, mut bad, mut state) = (a, b, v.to_vec());
        let mut advanced = false;
        'bisection: for _ in 0..BISECTIONS {
            let mid = 0.5 * (good + bad);
            let mut walked = state.clone();
            for k in 1..=WALK {
                let p = good + (mid - good) * k as f64 / WALK as f64;
                let field = self.field(p)?;
                let root = newton(
                    &field,
                    walked.clone(),
                    self.search.tolerance,
                    self.search.max_iterations,
                );
                match root {
                    Some(r) if alive(&field, &r, &walked)? => walked = r,
                    _ => {
                        bad = mid;
                        continue 'bisection;
                    }
                }
            }
            good = mid;
            state = walked;
            advanced = true;
        }
        Ok(advanced.then_some((good, state)))
    }

    /// The event at `value` and `state`, if its critical eigenvalue is where the kind puts it:
    /// a real part within [`CRITICAL`] (relative to the largest eigenvalue modulus, at least 1)
    /// of 0, and for a Hopf point an imaginary part beyond it.
    fn event(&self, kind: EventKind, value: f64, state: Vec<f64>) -> Result<Option<Event>> {
        let ev = eigenvalues(self.field(value)?.jacobian(&state))?;
        let pick = |a: &&[f64; 2], b: &&[f64; 2]| a[0].abs().total_cmp(&b[0].abs());
        let eigenvalue = match kind {
            EventKind::Fold => ev.iter().filter(|z| z[1] == 0.0).min_by(pick),
            EventKind::Hopf => ev.iter().filter(|z| z[1] > 0.0).min_by(pick),
        }
        .or_else(|| ev.iter().min_by(pick))
        .copied()
        .unwrap_or([f64::NAN, 0.0]);
        let scale = ev.iter().map(|z| z[0].hypot(z[1])).fold(1.0, f64::max);
        let critical = eigenvalue[0].abs() <= CRITICAL * scale
            && (kind == EventKind::Fold || eigenvalue[1] > CRITICAL * scale);
        let theta = self.net.theta();
        Ok(critical.then_some(Event {
            kind,
            value,
            outputs: state
                .iter()
                .zip(theta)
                .map(|(v, t)| crate::math::sigmoid(v - t))
                .collect(),
            state,
            eigenvalue,
        }))
    }

    /// The fold where `e` (at input `a`) vanishes on the way to input `b`.
    pub(super) fn fold(
        &self,
        a: f64,
        b: f64,
        e: &Equilibrium,
        others: &[Equilibrium],
    ) -> Result<Option<Event>> {
        let sign = det_sign(&self.field(a)?, &e.state);
        // Newton may not jump to a different equilibrium: each continuation step must move less
        // than half the distance from `e` to any other equilibrium at `a`, and keep the sign of
        // det (a fold's partner has the other sign).
        let reach = reach(e, others);
        let found = self.bisect(a, b, &e.state, |field, r, previous| {
            Ok(det_sign(field, r) == sign && distance(r, previous) < reach)
        })?;
        match found {
            Some((value, state)) => self.event(EventKind::Fold, value, state),
            None => Ok(None),
        }
    }

    /// The Hopf point between `e` (at input `a`) and its partner at input `b`: where its count
    /// of eigenvalues with positive real part changes (a real pair turning complex on the way
    /// keeps the count).
    pub(super) fn hopf(&self, a: f64, b: f64, e: &Equilibrium) -> Result<Option<Event>> {
        let count = unstable(e);
        let found = self.bisect(a, b, &e.state, |field, r, _| {
            let eq = Equilibrium::at(field, r.to_vec())?;
            Ok(unstable(&eq) == count)
        })?;
        match found {
            Some((value, state)) => self.event(EventKind::Hopf, value, state),
            None => Ok(None),
        }
    }
}
