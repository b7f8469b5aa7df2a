use sim2d::testing::error::{check_finite, check_range};

#[test]
fn messages_name_field_value_and_range() {
    let e = check_range("sonar.cone_deg", -3.0, 0.0, false, 180.0, false).unwrap_err();
    assert_eq!(
        e.to_string(),
        "sonar.cone_deg is -3; it must be in (0, 180)"
    );
    let e = check_range("robot.radius", 0.0, 0.0, false, f64::INFINITY, false).unwrap_err();
    assert_eq!(
        e.to_string(),
        "robot.radius is 0; it must be a finite number > 0"
    );
    let e = check_finite("x", f64::NAN).unwrap_err();
    assert_eq!(e.to_string(), "x is NaN; it must be a finite number");
    assert!(check_range("p", 1.0, 0.0, true, 1.0, true).is_ok());
}
