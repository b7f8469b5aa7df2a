use ctrnn::math::*;
use ctrnn::testing::math::{EXP_F32_MAX, EXP_F32_MIN, EXP_MAX, EXP_MIN};

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

/// The `f32` arguments of the tests below: a sweep of the whole clamped range, a dense one where
/// networks live, every `f32` near 0 and near the ends, and every eighth `f32` of [1, 2) and of
/// (-2, -1] (a binade each; .ci/cross-cpu runs these under emulation, with software FMA).
fn f32_arguments() -> impl Iterator<Item = f32> {
    let (lo, hi) = (EXP_F32_MIN, EXP_F32_MAX);
    let sweep = (0..=2_000_000).map(move |i| (lo + (hi - lo) * i as f64 / 2e6) as f32);
    let dense = (0..=1_000_000).map(|i| (-20.0 + 40.0 * i as f64 / 1e6) as f32);
    let binade = (1f32.to_bits()..2f32.to_bits())
        .step_by(8)
        .map(f32::from_bits);
    let near = |x: f32| {
        let b = x.to_bits();
        (b.saturating_sub(5000)..b + 5000).map(f32::from_bits)
    };
    sweep
        .chain(dense)
        .chain(binade.clone())
        .chain(binade.map(|x| -x))
        .chain(near(lo as f32))
        .chain(near(hi as f32))
        .chain(near(1e-30))
        .chain(near(-1e-30))
        .filter(move |x| (lo..=hi).contains(&(*x as f64)))
}

/// The bound stated in `exp_f32`'s documentation, against f64's `exp` (accurate to about 1e-16)
/// of the same argument.
#[test]
fn exp_f32_is_within_its_stated_bound_of_f64_exp() {
    let (mut worst, mut at) = (0.0f64, 0.0f32);
    for x in f32_arguments() {
        let want = (x as f64).exp();
        let rel = (exp_f32(x) as f64 - want).abs() / want;
        if rel > worst {
            (worst, at) = (rel, x);
        }
    }
    eprintln!("exp_f32: worst relative error {worst:.3e} at x = {at:e}");
    assert!(
        worst <= 1e-7,
        "worst relative error {worst:e} at x = {at:e}"
    );
}

#[test]
fn exp_f32_exact_points_and_edges() {
    assert_eq!(exp_f32(0.0), 1.0);
    assert!(exp_f32(f32::NAN).is_nan());
    assert_eq!(exp_f32(-1e6), exp_f32(EXP_F32_MIN as f32));
    assert!(exp_f32(-1e6) >= f32::MIN_POSITIVE);
    assert_eq!(exp_f32(f32::INFINITY), exp_f32(EXP_F32_MAX as f32));
    assert!(exp_f32(f32::INFINITY).is_finite());
}

/// `sigmoid_f32` against f64's sigmoid of the same argument, relative to the rate.
#[test]
fn sigmoid_f32_is_close_to_f64_and_saturates() {
    let mut worst = 0.0f64;
    for x in f32_arguments() {
        let want = 1.0 / (1.0 + (-(x as f64)).exp());
        worst = worst.max((sigmoid_f32(x) as f64 - want).abs() / want);
    }
    eprintln!("sigmoid_f32: worst relative error {worst:.3e}");
    assert!(worst <= 2e-7, "worst relative error {worst:e}");
    assert_eq!(sigmoid_f32(1e9), 1.0);
    // Never subnormal: the clamp keeps the rates of strongly inhibited neurons normal.
    assert!(sigmoid_f32(-1e9) >= f32::MIN_POSITIVE && sigmoid_f32(-1e9) < 1e-37);
    assert!((sigmoid_f32(2.0) + sigmoid_f32(-2.0) - 1.0).abs() <= f32::EPSILON);
}
