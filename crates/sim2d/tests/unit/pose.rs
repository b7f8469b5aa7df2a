use sim2d::wrap_angle;
use std::f64::consts::{PI, TAU};

#[test]
fn wrap_keeps_half_open_interval() {
    assert_eq!(wrap_angle(0.0), 0.0);
    assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
    assert!((wrap_angle(1.5 * PI) + 0.5 * PI).abs() < 1e-12);
    assert!((wrap_angle(-7.0) - (-7.0 + TAU)).abs() < 1e-12);
    assert!(wrap_angle(f64::NAN).is_nan());
}
