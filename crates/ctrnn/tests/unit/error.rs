use ctrnn::testing::error::check_finite;

#[test]
fn check_finite_finds_every_non_finite_value_wherever_it_is() {
    for len in [1, 7, 8, 9, 17, 30] {
        assert!(check_finite("w", &vec![1.5; len], 0).is_ok());
        for k in 0..len {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut values = vec![-2.0; len];
                values[k] = bad;
                let err = check_finite("w", &values, 0).unwrap_err().to_string();
                assert!(err.contains(&format!("w[{k}] is {bad}")), "{err}");
            }
        }
    }
    assert!(check_finite("w", &[f64::MAX, f64::MIN, 0.0, -0.0], 0).is_ok());
}
