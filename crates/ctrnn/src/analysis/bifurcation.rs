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
//! - a linked pair whose count of eigenvalues with positive real part differs while the sign of
//!   `det(dG/dv)` stays (no real eigenvalue passed through 0): a **Hopf point**, where a complex
//!   pair crosses the imaginary axis, also when the pair is real on one side (a stable node at
//!   one value, an unstable focus at the next: it turned complex and crossed in between). Its
//!   input value is refined by bisection along the linked equilibrium, on that count. (A node
//!   that turns into a focus keeps its count and is no event.)
//!
//! Linking is by continuation: Newton's method in a few steps to the next value from each
//! equilibrium, and back, each step keeping the sign of `det` and moving less than half the
//! distance to any other equilibrium (as a fold's bisection does).
//! A value where the search finds an even number of equilibria is searched again with
//! [`EquilibriumSearch::retry_starts`] starts, by the same rule as a single search; the values
//! where that happened are listed in [`Bifurcation::retried`].
//! Each event is found to within `2^-40` of the step between input values, and reports the state
//! and the critical eigenvalue there (near 0 for a fold, near `±i omega` for a Hopf point). An
//! event whose critical eigenvalue is not within [`CRITICAL`](super::CRITICAL) of the imaginary axis is dropped.
//!
//! With [`Sweep::cycles`], the attracting limit cycles are followed from value to value as
//! [`CycleBranch`]es, each with where it starts and ends (see the `branches` module).

use std::sync::atomic::{AtomicBool, Ordering};

use serde::Serialize;

use super::branches::{cycles_at, locate, CycleBranch};
use super::cycles::{Cycle, CycleSearch};
use super::equilibria::{max_abs, search, Equilibrium, EquilibriumSearch};
use super::events::{det_positive, distance, unstable, At, Event};
use super::field::Field;
use crate::error::{Error, Result};
use crate::Network;

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
        let found = search(&at.field(p)?, &sweep.search, &extra, cancel)?;
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
        let forward = at.link(a, b, here, next)?;
        let backward = at.link(b, a, next, here)?;
        for (i, e) in here.iter().enumerate() {
            match forward[i] {
                Some(j) if backward[j] == Some(i) => {
                    let f = &next[j];
                    if unstable(e) != unstable(f) && det_positive(e) == det_positive(f) {
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
