use std::sync::atomic::AtomicBool;

use ctrnn::integrate::*;
use ctrnn::testing::integrate::{random_networks, weight_order};
use ctrnn::{Error, Method, Network};

fn sig(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

#[test]
fn euler_step_matches_hand_calculation() {
    // N = 2, M = 1, one step from v = (0.5, -1) with input 2.
    let mut net = Network::new(
        vec![1.0, 2.0],
        vec![0.25, -0.5],
        vec![1.0, -2.0, 0.5, 3.0],
        vec![0.3, -0.7],
        Some(vec![0.5, -1.0]),
    )
    .unwrap();
    let integ = Integrator::default();
    let s = net.run(&[2.0], 1, &integ).unwrap();
    let f0 = sig(0.5 - 0.25);
    let f1 = sig(-1.0 + 0.5);
    let d0 = -0.5 + (1.0 * f0 - 2.0 * f1) + 0.3 * 2.0;
    let d1 = 1.0 + (0.5 * f0 + 3.0 * f1) - 0.7 * 2.0;
    let want = [0.5 + 0.1 / 1.0 * d0, -1.0 + 0.1 / 2.0 * d1];
    for i in 0..2 {
        assert!((s[i] - want[i]).abs() < 1e-15, "{} vs {}", s[i], want[i]);
    }
    assert_eq!(net.state(), &s[..]);
}

/// With W = 0 and constant input, v(t) = c + (v0 - c) e^{-t / tau} with c = S I.
fn rk4_error(dt: f64) -> f64 {
    let tau = [0.7, 1.3, 4.0];
    let mut net = Network::new(
        tau.to_vec(),
        vec![0.0; 3],
        vec![0.0; 9],
        vec![1.0, -2.0, 0.5],
        Some(vec![2.0, 1.0, -3.0]),
    )
    .unwrap();
    let t_end = 2.0;
    let steps = (t_end / dt).round() as usize;
    let integ = Integrator {
        method: Method::Rk4,
        dt,
        substeps: steps,
    };
    let s = net.run(&[1.5], 1, &integ).unwrap();
    let c = [1.5, -3.0, 0.75];
    let v0 = [2.0, 1.0, -3.0];
    (0..3)
        .map(|i| (s[i] - (c[i] + (v0[i] - c[i]) * (-t_end / tau[i]).exp())).abs())
        .fold(0.0, f64::max)
}

#[test]
fn rk4_converges_with_order_four() {
    let (e1, e2) = (rk4_error(0.2), rk4_error(0.1));
    let order = (e1 / e2).log2();
    assert!(
        (3.8..4.2).contains(&order),
        "order {order}, errors {e1} {e2}"
    );
}

#[test]
fn euler_converges_with_order_one() {
    let err = |dt: f64| {
        let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
        let integ = Integrator {
            method: Method::Euler,
            dt,
            substeps: (1.0 / dt).round() as usize,
        };
        let s = net.run(&[1.0], 1, &integ).unwrap();
        (s[0] - (1.0 - (-1.0f64).exp())).abs()
    };
    let order = (err(0.01) / err(0.005)).log2();
    assert!((0.95..1.05).contains(&order), "order {order}");
}

#[test]
fn bad_arguments_are_errors() {
    let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    let bad_dt = Integrator {
        dt: -0.1,
        ..Integrator::default()
    };
    assert!(net
        .run(&[1.0], 1, &bad_dt)
        .unwrap_err()
        .to_string()
        .contains("dt"));
    let zero = Integrator {
        substeps: 0,
        ..Integrator::default()
    };
    assert!(net.run(&[1.0], 1, &zero).is_err());
    assert!(net.run(&[1.0, 2.0], 1, &Integrator::default()).is_err());
    assert!(net.run(&[f64::NAN], 1, &Integrator::default()).is_err());
    assert!("rk5".parse::<Method>().is_err());
}

#[test]
fn divergence_is_reported_not_returned() {
    let mut net =
        Network::new(vec![0.5], vec![0.0], vec![0.0], vec![1.0], Some(vec![1.0])).unwrap();
    let huge = Integrator {
        dt: 5.0,
        substeps: 1000,
        ..Integrator::default()
    };
    // A step too long for a time constant is refused before it is taken.
    let e = net.run(&[0.0], 1, &huge).unwrap_err().to_string();
    assert!(
        e.contains("dt / tau is 10 for tau[0] = 0.5 (dt 5); from 2 on, Euler steps make"),
        "{e}"
    );
    let rk4 = Integrator {
        method: Method::Rk4,
        dt: 1.3,
        ..Integrator::default()
    };
    assert!(net.run(&[0.0], 1, &rk4).is_ok()); // dt / tau = 2.6, within RK4's 2.785
    let rk4 = Integrator { dt: 1.4, ..rk4 };
    let e = net.run(&[0.0], 1, &rk4).unwrap_err().to_string();
    assert!(e.contains("from 2.785 on, RK4 steps make"), "{e}");
    // An overflow at a short step is not blamed on the step.
    let mut loud = Network::new(
        vec![1.0],
        vec![0.0],
        vec![0.0],
        vec![1e308],
        Some(vec![0.0]),
    )
    .unwrap();
    let e = loud
        .run(&[1e10], 1, &Integrator::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("diverged: state[0] of the network became")
            && e.contains("dt / tau is 0.1 here, so the step is not the cause"),
        "{e}"
    );
    // Within RK4's limit, though past Euler's, the step is not blamed either.
    let rk4 = Integrator {
        method: Method::Rk4,
        dt: 2.5,
        ..Integrator::default()
    };
    let e = loud.run(&[1e10], 1, &rk4).unwrap_err().to_string();
    assert!(
        e.contains("dt / tau is 2.5 here, so the step is not the cause"),
        "{e}"
    );
}

#[test]
fn weights_are_stored_by_row_groups() {
    // 6 x 6 with WEIGHT_GROUP = 4: rows 0-3 column by column, then rows 4 and 5 as they are.
    let order: Vec<usize> = weight_order(6).collect();
    assert_eq!(order[..8], [0, 6, 12, 18, 1, 7, 13, 19]);
    assert_eq!(order[20..24], [5, 11, 17, 23]);
    assert_eq!(order[24..], (24..36).collect::<Vec<_>>()[..]);
    // Fewer rows than a group: row-major.
    assert_eq!(
        weight_order(3).collect::<Vec<_>>(),
        (0..9).collect::<Vec<_>>()
    );
}

#[test]
fn holding_the_inputs_is_stepping_them_again() {
    let nets = random_networks(LANES, 5, 2, 4);
    let refs: Vec<&Network> = nets.iter().collect();
    for method in [Method::Euler, Method::Rk4] {
        let integ = Integrator {
            method,
            dt: 0.1,
            substeps: 2,
        };
        let mut again = Lanes::<LANES>::new(&refs).unwrap();
        let (mut held, mut together) = (again.clone(), again.clone());
        let same = |a: &Lanes<LANES>, b: &Lanes<LANES>| {
            (0..5).all(|i| {
                let (x, y) = (a.state(i), b.state(i));
                x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits())
            })
        };
        for t in 0..12 {
            let inputs = [[(t / 4) as f64; LANES], [0.5; LANES]];
            again.step_row(&inputs, &integ);
            if t % 4 == 0 {
                held.step_row(&inputs, &integ);
                // Four rows of the same inputs as one row of four times the steps.
                let four = Integrator {
                    substeps: 4 * integ.substeps,
                    ..integ
                };
                together.step_row(&inputs, &four);
            } else {
                held.step_held(&integ);
            }
            if t % 3 == 0 {
                let _ = held.outputs();
            }
            assert!(same(&again, &held), "{method:?}, row {t}");
            if t % 4 == 3 {
                assert!(same(&again, &together), "{method:?}, row {t}");
            }
        }
    }
}

#[test]
#[should_panic(expected = "step_held needs a step_row before it")]
fn holding_needs_a_row() {
    let net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![1.0], None).unwrap();
    Lanes::<1>::new(&[&net])
        .unwrap()
        .step_held(&Integrator::default());
}

#[test]
fn cancel_flag_interrupts() {
    let mut net = Network::new(vec![1.0], vec![0.0], vec![0.0], vec![], None).unwrap();
    let flag = AtomicBool::new(true);
    let r = net.run_cancellable(&[], 10, &Integrator::default(), Some(&flag));
    assert!(matches!(r, Err(Error::Interrupted)));
}
