//! Checks against cases known in closed form, and against finite differences.

use nalgebra::DMatrix;

use super::stability::eigenvalues;
use super::*;
use crate::{Integrator, Method, Network};

fn logit(p: f64) -> f64 {
    (p / (1.0 - p)).ln()
}

/// For one neuron with self-weight w > 4, `h(x) = w f(x) - x` has a local minimum and maximum at
/// `f(x) (1 - f(x)) = 1 / w`; the neuron (input 0) is bistable exactly for theta between them.
fn bistable_interval(w: f64) -> Option<(f64, f64)> {
    if w <= 4.0 {
        return None;
    }
    let r = (1.0 - 4.0 / w).sqrt();
    let h = |p: f64| w * p - logit(p);
    Some((h((1.0 - r) / 2.0), h((1.0 + r) / 2.0)))
}

fn one(w: f64, theta: f64) -> Network {
    Network::new(vec![1.5], vec![theta], vec![w], vec![1.0], None).unwrap()
}

#[test]
fn one_neuron_is_bistable_exactly_in_the_closed_form_region() {
    let mut checked = (0, 0);
    for w in [1.0, 3.0, 3.99, 4.5, 6.0, 10.0, 16.0] {
        for k in 0..=40 {
            let theta = -2.0 + 0.5 * k as f64;
            let expect = match bistable_interval(w) {
                Some((lo, hi)) if (theta - lo).abs() < 1e-3 || (theta - hi).abs() < 1e-3 => {
                    continue
                }
                Some((lo, hi)) => lo < theta && theta < hi,
                None => false,
            };
            let eq = equilibria(&one(w, theta), &[0.0], &EquilibriumSearch::default()).unwrap();
            let stable = eq.iter().filter(|e| e.stability.is_stable()).count();
            assert_eq!(
                stable,
                if expect { 2 } else { 1 },
                "w {w} theta {theta}: {eq:?}"
            );
            assert_eq!(eq.len(), if expect { 3 } else { 1 }, "w {w} theta {theta}");
            if expect {
                assert_eq!(eq[1].stability, Stability::UnstableNode);
                checked.0 += 1;
            } else {
                checked.1 += 1;
            }
        }
    }
    assert!(checked.0 > 20 && checked.1 > 20, "{checked:?}");
}

#[test]
fn one_neuron_folds_where_the_closed_form_puts_them() {
    // With input I, v = w f(v - theta) + I: folds at I = theta - h(x+-).
    let (w, theta) = (8.0, 1.0);
    let (lo, hi) = bistable_interval(w).unwrap();
    let sweep = Sweep {
        from: -10.0,
        to: 6.0,
        steps: 33,
        ..Sweep::default()
    };
    let b = bifurcation(&one(w, theta), &[0.0], &sweep, None).unwrap();
    let folds: Vec<&Event> = b.events.iter().collect();
    assert_eq!(folds.len(), 2, "{folds:?}");
    assert!(folds.iter().all(|e| e.kind == EventKind::Fold));
    let want = [theta - hi, theta - lo];
    for (e, want) in folds.iter().zip(want) {
        assert!(
            (e.value - want).abs() < 1e-6,
            "fold at {} want {want}",
            e.value
        );
        assert!(e.eigenvalue[0].abs() < 1e-2, "{:?}", e.eigenvalue);
    }
    for (p, eq) in b.values.iter().zip(&b.equilibria) {
        let inside = want[0] < *p && *p < want[1];
        assert_eq!(eq.len(), if inside { 3 } else { 1 }, "input {p}");
    }
}

/// `[[a, b], [-b, a]]` with thresholds at the centre: equilibrium at v = theta with eigenvalues
/// `(-1 + a/4 ± i b/4) / tau`.
fn centre_pair(a: f64, b: f64, tau: f64) -> Network {
    let w = vec![a, b, -b, a];
    let theta = vec![(a + b) / 2.0, (a - b) / 2.0];
    Network::new(vec![tau; 2], theta, w, vec![1.0, 0.0], None).unwrap()
}

#[test]
fn centre_crossing_network_has_its_equilibrium_at_the_centre() {
    for (a, b, tau) in [(2.0, 1.0, 1.0), (3.0, 6.0, 2.0), (5.0, 3.0, 0.5)] {
        let net = centre_pair(a, b, tau);
        let eq = equilibria(&net, &[0.0], &EquilibriumSearch::default()).unwrap();
        let c = eq
            .iter()
            .find(|e| (e.state[0] - net.theta()[0]).abs() < 1e-9)
            .expect("an equilibrium at the centre");
        assert!((c.state[1] - net.theta()[1]).abs() < 1e-9);
        assert!(c.outputs.iter().all(|o| (o - 0.5).abs() < 1e-9));
        let re = (-1.0 + a / 4.0) / tau;
        let im = b / 4.0 / tau;
        assert!((c.eigenvalues[0][0] - re).abs() < 1e-9 && (c.eigenvalues[0][1] - im).abs() < 1e-9);
        assert!((c.eigenvalues[1][0] - re).abs() < 1e-9 && (c.eigenvalues[1][1] + im).abs() < 1e-9);
        let kind = if re < 0.0 {
            Stability::StableFocus
        } else {
            Stability::UnstableFocus
        };
        assert_eq!(c.stability, kind);
        assert!((c.time_scale.unwrap() - 1.0 / re.abs()).abs() < 1e-9);
    }
    // The general statement, for three neurons with an input: theta_i = sum_j w_ij / 2 + c_i.
    let w = vec![1.0, -2.0, 3.0, 0.5, 2.0, -1.0, -3.0, 1.5, 0.25];
    let s = vec![0.7, -0.2, 1.1];
    let theta: Vec<f64> = (0..3)
        .map(|i| w[3 * i..3 * i + 3].iter().sum::<f64>() / 2.0 + s[i] * 0.4)
        .collect();
    let net = Network::new(vec![1.0, 2.0, 3.0], theta.clone(), w, s, None).unwrap();
    let eq = equilibria(&net, &[0.4], &EquilibriumSearch::default()).unwrap();
    assert!(eq.iter().any(|e| e
        .state
        .iter()
        .zip(&theta)
        .all(|(v, t)| (v - t).abs() < 1e-9)));
}

/// The period of neuron 0's oscillation by plain RK4 integration (the network's own integrator),
/// from upward crossings of its threshold.
fn measured_period(net: &Network) -> f64 {
    let mut net = net.clone();
    let integ = Integrator {
        method: Method::Rk4,
        dt: 0.005,
        substeps: 1,
    };
    let steps = 40_000;
    let states = net.run(&vec![0.0; steps], steps, &integ).unwrap();
    let level = net.theta()[0];
    let ups: Vec<f64> = (steps / 2..steps)
        .filter(|&t| states[2 * (t - 1)] < level && states[2 * t] >= level)
        .map(|t| t as f64 * integ.dt)
        .collect();
    (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64
}

#[test]
fn two_neuron_oscillator_has_one_stable_cycle() {
    let net = centre_pair(5.5, 2.0, 1.0);
    let eq = equilibria(&net, &[0.0], &EquilibriumSearch::default()).unwrap();
    assert_eq!(eq.len(), 1);
    assert_eq!(eq[0].stability, Stability::UnstableFocus);
    let cycles = limit_cycles(&net, &[0.0], &CycleSearch::default(), None).unwrap();
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    let c = &cycles[0];
    assert!(c.stable && c.max_multiplier < 0.5, "{:?}", c.multipliers);
    let trivial = c
        .multipliers
        .iter()
        .map(|[re, im]| (re - 1.0).hypot(*im))
        .fold(1.0, f64::min);
    assert!(trivial < 1e-4, "{:?}", c.multipliers);
    let period = measured_period(&net);
    assert!(
        (c.period - period).abs() < 1e-3 * period,
        "{} vs {period}",
        c.period
    );
    assert!(c.amplitude.iter().all(|a| *a > 1.0));
    assert_eq!(c.orbit.len(), CycleSearch::default().orbit_points);
}

#[test]
fn cycle_near_hopf_has_the_linear_period() {
    // Just past the Hopf point (a = 4) the cycle is small and turns at the eigenvalues' rate b/4.
    let (a, b) = (4.05, 4.0);
    let net = centre_pair(a, b, 1.0);
    let settings = CycleSearch {
        transient: 2000.0,
        ..CycleSearch::default()
    };
    let cycles = limit_cycles(&net, &[0.0], &settings, None).unwrap();
    assert_eq!(cycles.len(), 1, "{cycles:?}");
    let linear = 2.0 * std::f64::consts::PI / (b / 4.0);
    assert!(
        (cycles[0].period - linear).abs() < 0.02 * linear,
        "{}",
        cycles[0].period
    );
    // Below the Hopf point: no cycle.
    let net = centre_pair(3.9, b, 1.0);
    assert!(limit_cycles(&net, &[0.0], &settings, None)
        .unwrap()
        .is_empty());
}

fn fd_jacobian(net: &Network, input: &[f64], v: &[f64]) -> DMatrix<f64> {
    let n = v.len();
    let h = 1e-6;
    DMatrix::from_fn(n, n, |i, j| {
        let (mut a, mut b) = (v.to_vec(), v.to_vec());
        a[j] += h;
        b[j] -= h;
        (vector_field(net, input, &a).unwrap()[i] - vector_field(net, input, &b).unwrap()[i])
            / (2.0 * h)
    })
}

#[test]
fn hopf_points_have_a_pair_on_the_imaginary_axis() {
    let net = centre_pair(4.5, 2.0, 1.0);
    let sweep = Sweep {
        from: -3.0,
        to: 3.0,
        steps: 31,
        ..Sweep::default()
    };
    let b = bifurcation(&net, &[0.0], &sweep, None).unwrap();
    let hopf: Vec<&Event> = b
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Hopf)
        .collect();
    assert_eq!(hopf.len(), 2, "{:?}", b.events);
    assert!(b.cycles.iter().all(|c| c.is_empty()));
    for e in hopf {
        // For two neurons the pair's real part is half the trace, here by finite differences.
        let j = fd_jacobian(&net, &[e.value], &e.state);
        assert!(j.trace().abs() < 1e-5, "trace {} at {}", j.trace(), e.value);
        assert!(j.determinant() > 0.0);
        assert!(e.eigenvalue[0].abs() < 1e-6 && e.eigenvalue[1] > 0.1);
    }
}

fn random_net(n: usize, seed: u64) -> Network {
    let mut d = super::equilibria::Draws::new(seed);
    let mut u = |lo: f64, hi: f64| lo + (hi - lo) * d.next();
    let tau = (0..n).map(|_| u(0.5, 5.0)).collect();
    let theta = (0..n).map(|_| u(-8.0, 8.0)).collect();
    let w = (0..n * n).map(|_| u(-16.0, 16.0)).collect();
    let s = (0..n).map(|_| u(-4.0, 4.0)).collect();
    Network::new(tau, theta, w, s, None).unwrap()
}

#[test]
fn equilibria_are_zeros_and_eigenvalues_match_finite_differences() {
    let mut total = 0;
    for seed in 0..12 {
        let n = 2 + seed as usize % 5;
        let net = random_net(n, seed);
        let input = [0.5];
        let eq = equilibria(&net, &input, &EquilibriumSearch::default()).unwrap();
        assert!(!eq.is_empty());
        for e in &eq {
            let rate = vector_field(&net, &input, &e.state).unwrap();
            let g: f64 = rate
                .iter()
                .zip(net.tau())
                .map(|(r, t)| (r * t).abs())
                .fold(0.0, f64::max);
            assert!(g <= 1e-10 && e.residual <= 1e-10, "{g}");
            let fd = fd_jacobian(&net, &input, &e.state);
            let exact = DMatrix::from_row_slice(n, n, &jacobian(&net, &input, &e.state).unwrap());
            assert!((&fd - &exact).amax() < 1e-6, "{fd} {exact}");
            let ev = eigenvalues(fd).unwrap();
            for (a, b) in ev.iter().zip(&e.eigenvalues) {
                assert!(
                    (a[0] - b[0]).abs() < 1e-5 && (a[1] - b[1]).abs() < 1e-5,
                    "{ev:?} {:?}",
                    e.eigenvalues
                );
            }
            total += 1;
        }
        for (i, a) in eq.iter().enumerate() {
            for b in &eq[i + 1..] {
                let d = a
                    .state
                    .iter()
                    .zip(&b.state)
                    .fold(0.0, |m: f64, (x, y)| m.max((x - y).abs()));
                assert!(d >= 1e-6);
            }
        }
    }
    assert!(total >= 12);
}

#[test]
fn a_search_is_deterministic_and_more_starts_find_no_fewer() {
    let net = random_net(6, 99);
    let few = EquilibriumSearch {
        starts: 64,
        ..EquilibriumSearch::default()
    };
    let a = equilibria(&net, &[0.0], &few).unwrap();
    assert_eq!(a, equilibria(&net, &[0.0], &few).unwrap());
    let many = EquilibriumSearch {
        starts: 2048,
        ..EquilibriumSearch::default()
    };
    assert!(equilibria(&net, &[0.0], &many).unwrap().len() >= a.len());
}

#[test]
fn bad_arguments_are_typed_errors() {
    let net = one(8.0, 4.0);
    let msg = |e: crate::Error| e.to_string();
    let e = msg(equilibria(&net, &[], &EquilibriumSearch::default()).unwrap_err());
    assert!(
        e.contains("input has 0 values") && e.contains("M = 1"),
        "{e}"
    );
    let e = msg(equilibria(&net, &[f64::NAN], &EquilibriumSearch::default()).unwrap_err());
    assert!(e.contains("input[0]") && e.contains("finite"), "{e}");
    let bad = EquilibriumSearch {
        starts: 0,
        ..EquilibriumSearch::default()
    };
    assert!(msg(equilibria(&net, &[0.0], &bad).unwrap_err()).contains("starts is 0"));
    let bad = EquilibriumSearch {
        distinct: 1e-12,
        ..EquilibriumSearch::default()
    };
    assert!(msg(equilibria(&net, &[0.0], &bad).unwrap_err()).contains("distinct"));
    let bad = CycleSearch {
        window: 0.0,
        ..CycleSearch::default()
    };
    assert!(msg(limit_cycles(&net, &[0.0], &bad, None).unwrap_err()).contains("window is 0"));
    let bad = Sweep {
        input: 1,
        ..Sweep::default()
    };
    let e = msg(bifurcation(&net, &[0.0], &bad, None).unwrap_err());
    assert!(e.contains("input is 1") && e.contains("0..1"), "{e}");
    let bad = Sweep {
        to: 0.0,
        ..Sweep::default()
    };
    assert!(msg(bifurcation(&net, &[0.0], &bad, None).unwrap_err()).contains("different"));
    let bad = Sweep {
        steps: 1,
        ..Sweep::default()
    };
    assert!(msg(bifurcation(&net, &[0.0], &bad, None).unwrap_err()).contains("at least 2"));
    let e = msg(vector_field(&net, &[0.0], &[0.0, 1.0]).unwrap_err());
    assert!(e.contains("state has 2 values"), "{e}");
    let cancel = std::sync::atomic::AtomicBool::new(true);
    let osc = centre_pair(5.5, 2.0, 1.0);
    assert!(matches!(
        limit_cycles(&osc, &[0.0], &CycleSearch::default(), Some(&cancel)),
        Err(crate::Error::Interrupted)
    ));
}

#[test]
fn every_change_in_the_equilibrium_count_has_its_fold() {
    let mut changes = 0;
    for seed in 0..30 {
        let net = random_net(2 + seed as usize % 2, 100 + seed);
        let sweep = Sweep {
            from: -2.0,
            to: 2.0,
            steps: 41,
            ..Sweep::default()
        };
        let b = bifurcation(&net, &[0.0], &sweep, None).unwrap();
        for s in 0..b.values.len() - 1 {
            let (here, next) = (b.equilibria[s].len(), b.equilibria[s + 1].len());
            if here == next {
                continue;
            }
            changes += 1;
            let folds = b
                .events
                .iter()
                .filter(|e| e.kind == EventKind::Fold)
                .filter(|e| b.values[s] <= e.value && e.value <= b.values[s + 1])
                .count();
            assert!(
                2 * folds >= here.abs_diff(next),
                "seed {seed}: {here} -> {next} equilibria between {} and {} with {folds} folds",
                b.values[s],
                b.values[s + 1]
            );
        }
    }
    assert!(changes >= 5, "only {changes} changes to check");
}

#[test]
fn a_sweep_with_cycles_finds_them_between_its_hopf_points() {
    let net = centre_pair(4.5, 4.0, 1.0);
    let sweep = Sweep {
        from: -4.0,
        to: 4.0,
        steps: 33,
        cycles: Some(CycleSearch {
            starts: 2,
            transient: 400.0,
            ..CycleSearch::default()
        }),
        ..Sweep::default()
    };
    let b = bifurcation(&net, &[0.0], &sweep, None).unwrap();
    let hopf: Vec<f64> = b
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Hopf)
        .map(|e| e.value)
        .collect();
    assert_eq!(hopf.len(), 2, "{:?}", b.events);
    let mut checked = 0;
    for (p, (found, eq)) in b.values.iter().zip(b.cycles.iter().zip(&b.equilibria)) {
        // Between the Hopf points the one equilibrium is unstable and a cycle surrounds it;
        // outside them the equilibrium is stable and no cycle exists. (Values within 0.3 of a
        // Hopf point are skipped: the cycle there is too small or too slow to close.)
        if hopf.iter().any(|h| (p - h).abs() < 0.3) {
            continue;
        }
        let inside = hopf[0] < *p && *p < hopf[1];
        assert_eq!(found.len(), usize::from(inside), "input {p}: {found:?}");
        assert_eq!(eq.len(), 1);
        assert_eq!(eq[0].stability.is_stable(), !inside, "input {p}");
        checked += usize::from(inside);
    }
    assert!(
        checked >= 2,
        "only {checked} values between the Hopf points"
    );
}
