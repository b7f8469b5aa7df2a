//! Cycle branches of a sweep: each attracting limit cycle followed from one input value to the
//! next, with where it appears and where it disappears.
//!
//! At each input value the cycle search integrates from a point of each cycle found at the
//! previous value (continuation) as well as from its own starts. A cycle reached from the
//! previous value's cycle `c` continues `c`'s branch when the two orbits are close: every point of
//! each lies within the larger of their sizes (largest amplitude over the neurons) of the other
//! ([`continues`]). When two branches continue into one cycle, the closer keeps it and the other
//! ends. A cycle that continues no branch starts a new one.
//!
//! A branch that is not present at the first (last) swept value starts (ends) between two
//! values, one with the cycle and one without. That end is located:
//!
//! - at a **Hopf point** of the sweep, if one lies between the two values (or within one more
//!   step on the side without the cycle, where a cycle too small or too slow to close was
//!   missed) and the equilibrium there, followed back to the value with the cycle, lies inside
//!   the cycle's range: the cycle shrinks onto that equilibrium;
//! - otherwise by bisection ([`CYCLE_BISECTIONS`] halvings): at each trial value the cycle is
//!   followed from the nearest value where it was found, and the end is the last value where it
//!   still continues. Such an end is **lost**: a fold of cycles (where it meets an unstable cycle),
//!   a homoclinic orbit (where its period grows without bound), or a change the search missed.

use std::sync::atomic::AtomicBool;

use serde::Serialize;

use super::cycles::{follow, same_cycle, Cycle, CycleSearch};
use super::equilibria::newton;
use super::events::{At, Event, EventKind};
use crate::error::Result;

/// Bisection steps that locate a lost cycle's end between two input values.
pub const CYCLE_BISECTIONS: usize = 12;

/// How a cycle branch starts or ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CycleEndKind {
    /// The cycle shrinks onto an equilibrium at a Hopf point of the sweep.
    Hopf,
    /// The cycle stops being found past this value: a fold of cycles, a homoclinic orbit, or a
    /// change the search missed.
    Lost,
}

/// Where a cycle branch starts or ends within a sweep.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CycleEnd {
    /// Hopf point or lost.
    pub kind: CycleEndKind,
    /// The input value of the end: the Hopf point's, or the last value (by bisection) where the
    /// cycle was still found.
    pub value: f64,
    /// The swept value next to the end where the cycle was found.
    pub with_cycle: f64,
    /// The swept value next to the end, on the other side, where it was not.
    pub without_cycle: f64,
    /// The cycle's period at the end: `2 pi / omega` of the Hopf point's eigenvalues `±i omega`
    /// (the limit of a vanishing cycle's period), or the last cycle found by the bisection. A
    /// lost cycle whose period grows towards its end is ending at a homoclinic orbit or a
    /// saddle-node on the cycle; one whose period stays finite, at a fold of cycles.
    pub period: f64,
}

/// One attracting cycle followed across consecutive swept values.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CycleBranch {
    /// Its number, in order of appearance in the sweep (`Bifurcation::cycle_branch` refers to it).
    pub id: usize,
    /// Index of the first swept value with the cycle.
    pub first: usize,
    /// Index of the last swept value with the cycle.
    pub last: usize,
    /// Where it appears, None if it is there at the sweep's first value.
    pub start: Option<CycleEnd>,
    /// Where it disappears, None if it is there at the sweep's last value.
    pub end: Option<CycleEnd>,
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
}

/// The largest distance (max norm) from a point of either orbit to the other orbit.
pub fn orbit_gap(a: &Cycle, b: &Cycle) -> f64 {
    let one_way = |p: &[Vec<f64>], q: &[Vec<f64>]| {
        p.iter()
            .map(|x| {
                q.iter()
                    .map(|y| distance(x, y))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0, f64::max)
    };
    one_way(&a.orbit, &b.orbit).max(one_way(&b.orbit, &a.orbit))
}

fn size(c: &Cycle) -> f64 {
    c.amplitude.iter().fold(0.0, |m: f64, a| m.max(*a))
}

/// Whether `new` (at the next input value) continues `old`: their orbits lie within the larger
/// of their sizes of each other.
pub fn continues(old: &Cycle, new: &Cycle) -> bool {
    orbit_gap(old, new) <= size(old).max(size(new))
}

/// The cycles at one value, each with its branch id (None: new) and its gap to the cycle it
/// continues.
pub struct Here {
    /// Each cycle, with its branch id and its gap to the cycle it continues.
    pub cycles: Vec<(Cycle, Option<usize>, f64)>,
}

impl Here {
    /// Adds `cycle`, reached by continuation of branch `id` at gap `gap`: merged with the same
    /// cycle if present, where the smaller gap keeps its branch.
    pub fn continued(&mut self, cycle: Cycle, id: usize, gap: f64) {
        match self.cycles.iter_mut().find(|h| same_cycle(&h.0, &cycle)) {
            Some(h) if gap < h.2 => *h = (cycle, Some(id), gap),
            Some(_) => {}
            None => self.cycles.push((cycle, Some(id), gap)),
        }
    }

    /// Adds a cycle the search found from its own starts, unless it is already here.
    pub fn fresh(&mut self, cycle: Cycle) {
        if !self.cycles.iter().any(|h| same_cycle(&h.0, &cycle)) {
            self.cycles.push((cycle, None, f64::INFINITY));
        }
    }
}

/// The cycles at input `value`: those continued from `previous` (with their branch ids) and those
/// found from the search's own starts (id None), sorted by period.
pub(crate) fn cycles_at(
    at: &At<'_>,
    value: f64,
    settings: &CycleSearch,
    previous: &[(Cycle, usize)],
    cancel: Option<&AtomicBool>,
) -> Result<Vec<(Cycle, Option<usize>)>> {
    let field = at.field(value)?;
    let mut here = Here { cycles: Vec::new() };
    for (c, id) in previous {
        if let Some(new) = follow(&field, settings, c.orbit[0].clone(), cancel)? {
            if continues(c, &new) {
                let gap = orbit_gap(c, &new);
                here.continued(new, *id, gap);
            }
        }
    }
    for c in super::cycles::search(&field, settings, &[], cancel)? {
        here.fresh(c);
    }
    let mut found: Vec<(Cycle, Option<usize>)> =
        here.cycles.into_iter().map(|(c, id, _)| (c, id)).collect();
    found.sort_by(|a, b| a.0.period.total_cmp(&b.0.period));
    Ok(found)
}

/// Locates the end of a branch between `with_cycle` (where it has `cycle`) and `without_cycle`.
/// `step` is the signed step from `with_cycle` to `without_cycle`.
pub fn locate(
    at: &At<'_>,
    settings: &CycleSearch,
    with_cycle: f64,
    without_cycle: f64,
    cycle: &Cycle,
    events: &[Event],
    cancel: Option<&AtomicBool>,
) -> Result<CycleEnd> {
    let step = without_cycle - with_cycle;
    let far = without_cycle + step;
    let between = |v: f64| (v - with_cycle) * (far - v) >= 0.0;
    let field = at.field(with_cycle)?;
    let n = cycle.amplitude.len();
    let (lo, hi): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|i| {
            let x = cycle.orbit.iter().map(|p| p[i]);
            let lo = x.clone().fold(f64::INFINITY, f64::min);
            let hi = x.fold(f64::NEG_INFINITY, f64::max);
            let margin = 0.1 * (hi - lo) + 1e-9;
            (lo - margin, hi + margin)
        })
        .unzip();
    let mut hopf: Vec<&Event> = events
        .iter()
        .filter(|e| e.kind == EventKind::Hopf && between(e.value))
        .collect();
    hopf.sort_by(|a, b| {
        (a.value - with_cycle)
            .abs()
            .total_cmp(&(b.value - with_cycle).abs())
    });
    for e in hopf {
        let back = newton(
            &field,
            e.state.clone(),
            at.search.tolerance,
            at.search.max_iterations,
        );
        let inside = back.is_some_and(|v| (0..n).all(|i| lo[i] <= v[i] && v[i] <= hi[i]));
        if inside {
            return Ok(CycleEnd {
                kind: CycleEndKind::Hopf,
                value: e.value,
                with_cycle,
                without_cycle,
                period: 2.0 * std::f64::consts::PI / e.eigenvalue[1],
            });
        }
    }
    let (mut good, mut bad, mut last) = (with_cycle, without_cycle, cycle.clone());
    for _ in 0..CYCLE_BISECTIONS {
        let mid = 0.5 * (good + bad);
        match follow(&at.field(mid)?, settings, last.orbit[0].clone(), cancel)? {
            Some(c) if continues(&last, &c) => {
                good = mid;
                last = c;
            }
            _ => bad = mid,
        }
    }
    Ok(CycleEnd {
        kind: CycleEndKind::Lost,
        value: good,
        with_cycle,
        without_cycle,
        period: last.period,
    })
}
