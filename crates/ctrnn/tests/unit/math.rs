use ctrnn::math::*;
use ctrnn::testing::math::{EXP_MAX, EXP_MIN};

/// Distance in units in the last place between two positive finite floats.
fn ulps(a: f64, b: f64) -> u64 {
    a.to_bits().abs_diff(b.to_bits())
}

#[test]
fn exp_is_within_two_ulp_of_std() {
    let mut worst = 0;
    let n = 2_000_000;
    for i in 0..=n {
        let x = EXP_MIN + (EXP_MAX - EXP_MIN) * (i as f64) / (n as f64);
        worst = worst.max(ulps(exp(x), x.exp()));
    }
    // And densely where a network lives.
    for i in 0..=n {
        let x = -40.0 + 80.0 * (i as f64) / (n as f64);
        worst = worst.max(ulps(exp(x), x.exp()));
    }
    assert!(worst <= 2, "worst error {worst} ulp");
}

#[test]
fn exp_exact_points_and_edges() {
    assert_eq!(exp(0.0), 1.0);
    assert!(exp(f64::NAN).is_nan());
    assert!(exp(-1e6) > 0.0 && exp(-1e6) < 1e-300);
    assert!(exp(1e6).is_finite());
    assert_eq!(exp(f64::INFINITY), exp(EXP_MAX));
}

#[test]
fn sigmoid_is_within_a_few_ulp_and_saturates() {
    for i in 0..=100_000 {
        let x = -30.0 + 60.0 * (i as f64) / 100_000.0;
        let exact = 1.0 / (1.0 + (-x).exp());
        assert!(ulps(sigmoid(x), exact) <= 3, "x = {x}");
    }
    assert_eq!(sigmoid(1e9), 1.0);
    assert!(sigmoid(-1e9) < 1e-300);
    assert!((sigmoid(2.0) + sigmoid(-2.0) - 1.0).abs() <= f64::EPSILON);
}
