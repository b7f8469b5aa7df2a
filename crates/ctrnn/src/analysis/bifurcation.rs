//! A bifurcation sweep: one input varied from `from` to `to`, the equilibria (and, if asked, the
//! attracting limit cycles) followed, and the folds and Hopf points between them located.
//!
//! At each input value the equilibria are searched afresh, with the previous value's equilibria
//! as extra Newton starts (natural continuation). Consecutive values are linked by mutual
//! nearest neighbours. Between two values:
//!
//! - an equilibrium with no partner at the next value vanished there, and one with no partner at
//!   the previous value appeared: a **fold** (saddle-node), where a real eigenvalue passes
//!   through 0. Its input value is refined by bisection, following the equilibrium by Newton's
//!   method while it keeps the sign of `det(dG/dv)` (a fold's two equilibria have opposite signs).
//! - a linked pair whose count of complex eigenvalues with positive real part differs, with
//!   complex eigenvalues on both sides: a **Hopf point**, where a complex pair crosses the
//!   imaginary axis. Its input value is refined by bisection along the linked equilibrium.
//!
//! Linking is by continuation: Newton's method at the next value from each equilibrium, and back.
//! A value where the search finds an even number of equilibria is searched again with
//! [`EquilibriumSearch::retry_starts`] starts, by the same rule as a single search; the values
//! where that happened are listed in [`Bifurcation::retried`].
//! Each event is found to within `2^-40` of the step between input values, and reports the state
//! and the critical eigenvalue there (near 0 for a fold, near `±i omega` for a Hopf point). An
//! event whose critical eigenvalue is not within [`CRITICAL`] of the imaginary axis is dropped.
//!
//! With [`Sweep::cycles`], the attracting limit cycles are followed from value to value as
//! [`CycleBranch`]es, each with where it starts and ends (see the `branches` module).

use std::sync::atomic::{AtomicBool, Ordering};

use serde::Serialize;

use super::branches::{cycles_at, locate, CycleBranch};
use super::cycles::{Cycle, CycleSearch};
use super::equilibria::{max_abs, newton, search, Equilibrium, EquilibriumSearch};
use super::field::Field;
use super::stability::eigenvalues;
use crate::error::{Error, Result};
use crate::Network;

/// Bisection steps that locate an event between two input values.
const BISECTIONS: usize = 40;
/// Newton continuation steps from the last good input value to each bisection trial value.
const WALK: usize = 4;
/// An event is kept only if its critical eigenvalue's real part is within this of 0, relative to
/// the largest eigenvalue modulus (at least 1): a link between input values that was wrong, or a
/// search that missed an equilibrium at one value, then reports nothing instead of a false event.
pub const CRITICAL: f64 = 1e-3;

/// Settings of a bifurcation sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sweep {
    /// The index of the input varied. Default: 0.
    pub input: usize,
    /// The first input value. Default: 0.
    pub from: f64,
    /// The last input value. Default: 1.
    pub to: f64,
    /// Input values, evenly spaced from `from` to `to`. Default: 101.
    pub steps: usize,
    /// The equilibrium search at each value. Default: [`EquilibriumSearch::default`] with 128
    /// starts (the previous value's equilibria are also starts).
    pub search: EquilibriumSearch,
    /// The limit-cycle search at each value, if any; the previous value's cycles are followed
    /// from a point of each, as well. Default: None, since it costs about 100 times an
    /// equilibrium search.
    pub cycles: Option<CycleSearch>,
}

impl Default for Sweep {
    fn default() -> Self {
        Sweep {
            input: 0,
            from: 0.0,
            to: 1.0,
            steps: 101,
            search: EquilibriumSearch {
                starts: 128,
                ..EquilibriumSearch::default()
            },
            cycles: None,
        }
    }
}

impl Sweep {
    /// Checks the settings against a network with `n_inputs` sensors: `input < n_inputs`,
    /// `from` and `to` finite and different, `steps >= 2`, and a valid search.
    pub fn validate(&self, n_inputs: usize) -> Result<()> {
        if self.input >= n_inputs {
            return Err(Error::InvalidArgument(format!(
                "input is {}; this network has {n_inputs} sensors, so it must be in 0..{n_inputs}",
                self.input
            )));
        }
        if !(self.from.is_finite() && self.to.is_finite() && self.from != self.to) {
            return Err(Error::InvalidArgument(format!(
                "the sweep runs from {} to {}; both must be finite and different",
                self.from, self.to
            )));
        }
        if self.steps < 2 {
            return Err(Error::InvalidArgument(format!(
                "steps is {}; a sweep needs at least 2 input values",
                self.steps
            )));
        }
        if let Some(c) = &self.cycles {
            c.validate()?;
        }
        self.search.validate()
    }

    fn value(&self, s: usize) -> f64 {
        self.from + (self.to - self.from) * s as f64 / (self.steps - 1) as f64
    }
}

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

/// The result of a sweep: the equilibria at each input value, and the events between them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bifurcation {
    /// The index of the input varied.
    pub input: usize,
    /// The input values, `steps` of them.
    pub values: Vec<f64>,
    /// The equilibria at each value, sorted by state.
    pub equilibria: Vec<Vec<Equilibrium>>,
    /// The attracting limit cycles at each value, sorted by period (empty lists unless the
    /// sweep searched for cycles).
    pub cycles: Vec<Vec<Cycle>>,
    /// The branch id of each cycle, parallel to `cycles`: an index into `branches`.
    pub cycle_branch: Vec<Vec<usize>>,
    /// The cycles followed across values, by id, each with where it starts and ends.
    pub branches: Vec<CycleBranch>,
    /// Folds and Hopf points, by input value.
    pub events: Vec<Event>,
    /// The input values where the first search found an even number of equilibria and the
    /// search was repeated with `retry_starts` starts. A count that is still even at one of them
    /// means that equilibria were missed there.
    pub retried: Vec<f64>,
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// Index of the nearest state of `among` to `x`.
fn nearest(x: &[f64], among: &[Equilibrium]) -> Option<usize> {
    (0..among.len())
        .min_by(|&a, &b| distance(x, &among[a].state).total_cmp(&distance(x, &among[b].state)))
}

fn unstable_complex(e: &Equilibrium) -> usize {
    e.eigenvalues
        .iter()
        .filter(|[re, im]| *re > 0.0 && *im != 0.0)
        .count()
}

fn has_complex(e: &Equilibrium) -> bool {
    e.eigenvalues.iter().any(|[_, im]| *im != 0.0)
}

fn det_sign(field: &Field<'_>, v: &[f64]) -> f64 {
    field.residual_jacobian(v).lu().determinant().signum()
}

/// Everything needed to look at the system at one input value.
pub(crate) struct At<'a> {
    net: &'a Network,
    base: Vec<f64>,
    input: usize,
    pub(crate) search: EquilibriumSearch,
}

impl<'a> At<'a> {
    /// `net` with input `input` swept, the others held at `base`.
    pub(crate) fn new(
        net: &'a Network,
        base: &[f64],
        input: usize,
        search: EquilibriumSearch,
    ) -> Self {
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

    /// For each of `from`, the one of `to` (the equilibria at input `value`) that Newton's method
    /// reaches from it, if any.
    fn link(
        &self,
        value: f64,
        from: &[Equilibrium],
        to: &[Equilibrium],
    ) -> Result<Vec<Option<usize>>> {
        let field = self.field(value)?;
        Ok(from
            .iter()
            .map(|e| {
                let r = newton(
                    &field,
                    e.state.clone(),
                    self.search.tolerance,
                    self.search.max_iterations,
                )?;
                let k = nearest(&r, to)?;
                (distance(&r, &to[k].state) < self.search.distinct).then_some(k)
            })
            .collect())
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
    fn fold(
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
        let reach = others
            .iter()
            .map(|o| distance(&o.state, &e.state))
            .filter(|d| *d > 0.0)
            .fold(f64::INFINITY, f64::min)
            / 2.0;
        let found = self.bisect(a, b, &e.state, |field, r, previous| {
            Ok(det_sign(field, r) == sign && distance(r, previous) < reach.max(1e-3))
        })?;
        match found {
            Some((value, state)) => self.event(EventKind::Fold, value, state),
            None => Ok(None),
        }
    }

    /// The Hopf point between `e` (at input `a`) and its partner at input `b`.
    fn hopf(&self, a: f64, b: f64, e: &Equilibrium) -> Result<Option<Event>> {
        let count = unstable_complex(e);
        let found = self.bisect(a, b, &e.state, |field, r, _| {
            let eq = Equilibrium::at(field, r.to_vec())?;
            Ok(unstable_complex(&eq) == count)
        })?;
        match found {
            Some((value, state)) => self.event(EventKind::Hopf, value, state),
            None => Ok(None),
        }
    }
}

/// Sweeps input `sweep.input` of `net` from `sweep.from` to `sweep.to`, the other inputs held at
/// `input`, following the equilibria and locating folds and Hopf points.
///
/// # Example
/// ```
/// use ctrnn::analysis::{bifurcation, EventKind, Sweep};
/// use ctrnn::Network;
/// // One self-exciting neuron (w = 8) driven by its sensor: bistable for inputs between two folds.
/// let net = Network::new(vec![1.0], vec![0.0], vec![8.0], vec![1.0], None)?;
/// let sweep = Sweep { from: -8.0, to: 0.0, steps: 41, ..Sweep::default() };
/// let b = bifurcation(&net, &[0.0], &sweep, None)?;
/// let folds: Vec<f64> = b.events.iter().filter(|e| e.kind == EventKind::Fold).map(|e| e.value).collect();
/// assert_eq!(folds.len(), 2);
/// assert!(b.equilibria[20].len() == 3); // at input -4, the centre: three equilibria
/// # Ok::<(), ctrnn::Error>(())
/// ```
pub fn bifurcation(
    net: &Network,
    input: &[f64],
    sweep: &Sweep,
    cancel: Option<&AtomicBool>,
) -> Result<Bifurcation> {
    Field::new(net, input)?;
    sweep.validate(net.n_inputs())?;
    let at = At::new(net, input, sweep.input, sweep.search);
    let values: Vec<f64> = (0..sweep.steps).map(|s| sweep.value(s)).collect();
    let mut equilibria: Vec<Vec<Equilibrium>> = Vec::with_capacity(sweep.steps);
    let mut retried = Vec::new();
    let mut cycles: Vec<Vec<Cycle>> = Vec::with_capacity(sweep.steps);
    let mut cycle_branch: Vec<Vec<usize>> = Vec::with_capacity(sweep.steps);
    let mut branches = 0;
    for &p in &values {
        if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
            return Err(Error::Interrupted);
        }
        let extra: Vec<Vec<f64>> = equilibria
            .last()
            .map(|prev| prev.iter().map(|e| e.state.clone()).collect())
            .unwrap_or_default();
        let found = search(&at.field(p)?, &sweep.search, &extra)?;
        if found.retried {
            retried.push(p);
        }
        equilibria.push(found.equilibria);
        let (here, ids) = match &sweep.cycles {
            None => (Vec::new(), Vec::new()),
            Some(settings) => {
                let previous: Vec<(Cycle, usize)> = match (cycles.last(), cycle_branch.last()) {
                    (Some(c), Some(b)) => c.iter().cloned().zip(b.iter().copied()).collect(),
                    _ => Vec::new(),
                };
                cycles_at(&at, p, settings, &previous, cancel)?
                    .into_iter()
                    .map(|(c, id)| {
                        let id = id.unwrap_or_else(|| {
                            branches += 1;
                            branches - 1
                        });
                        (c, id)
                    })
                    .unzip()
            }
        };
        cycles.push(here);
        cycle_branch.push(ids);
    }
    let mut events = Vec::new();
    for s in 0..sweep.steps - 1 {
        let (here, next) = (&equilibria[s], &equilibria[s + 1]);
        let (a, b) = (values[s], values[s + 1]);
        let forward = at.link(b, here, next)?;
        let backward = at.link(a, next, here)?;
        for (i, e) in here.iter().enumerate() {
            match forward[i] {
                Some(j) if backward[j] == Some(i) => {
                    let f = &next[j];
                    if unstable_complex(e) != unstable_complex(f)
                        && has_complex(e)
                        && has_complex(f)
                    {
                        events.extend(at.hopf(a, b, e)?);
                    }
                }
                _ => events.extend(at.fold(a, b, e, here)?),
            }
        }
        for (j, f) in next.iter().enumerate() {
            if !matches!(backward[j], Some(i) if forward[i] == Some(j)) {
                events.extend(at.fold(b, a, f, next)?);
            }
        }
    }
    events.sort_by(|x, y| x.value.total_cmp(&y.value));
    // A fold's two equilibria each report it: keep the report with the critical eigenvalue
    // nearer 0 (the other one's bisection may stop short where Newton's method, near the fold,
    // jumps to its partner). Events at nearly the same value but far apart in state are
    // different pairs, and both are kept.
    let spacing = (sweep.to - sweep.from).abs() / (sweep.steps - 1) as f64;
    let mut merged: Vec<Event> = Vec::with_capacity(events.len());
    for e in events {
        let dup = merged.iter_mut().find(|m| {
            m.kind == e.kind
                && (m.value - e.value).abs() <= spacing
                && distance(&m.state, &e.state) <= 0.1 * (1.0 + max_abs(&m.state))
        });
        match dup {
            Some(m) if e.eigenvalue[0].abs() < m.eigenvalue[0].abs() => *m = e,
            Some(_) => {}
            None => merged.push(e),
        }
    }
    let branches = match &sweep.cycles {
        Some(settings) => follow_branches(
            &at,
            settings,
            &values,
            &cycles,
            &cycle_branch,
            branches,
            &merged,
            cancel,
        )?,
        None => Vec::new(),
    };
    Ok(Bifurcation {
        input: sweep.input,
        values,
        equilibria,
        cycles,
        cycle_branch,
        branches,
        events: merged,
        retried,
    })
}

/// The `count` branches of `cycle_branch`, each with its start and end located.
#[allow(clippy::too_many_arguments)]
fn follow_branches(
    at: &At<'_>,
    settings: &CycleSearch,
    values: &[f64],
    cycles: &[Vec<Cycle>],
    cycle_branch: &[Vec<usize>],
    count: usize,
    events: &[Event],
    cancel: Option<&AtomicBool>,
) -> Result<Vec<CycleBranch>> {
    let cycle = |s: usize, id: usize| {
        cycle_branch[s]
            .iter()
            .position(|b| *b == id)
            .map(|k| &cycles[s][k])
    };
    let mut out = Vec::with_capacity(count);
    for id in 0..count {
        let present: Vec<usize> = (0..values.len())
            .filter(|&s| cycle(s, id).is_some())
            .collect();
        let (Some(&first), Some(&last)) = (present.first(), present.last()) else {
            continue;
        };
        let start = match (first > 0, cycle(first, id)) {
            (true, Some(c)) => Some(locate(
                at,
                settings,
                values[first],
                values[first - 1],
                c,
                events,
                cancel,
            )?),
            _ => None,
        };
        let end = match (last + 1 < values.len(), cycle(last, id)) {
            (true, Some(c)) => Some(locate(
                at,
                settings,
                values[last],
                values[last + 1],
                c,
                events,
                cancel,
            )?),
            _ => None,
        };
        out.push(CycleBranch {
            id,
            first,
            last,
            start,
            end,
        });
    }
    Ok(out)
}
