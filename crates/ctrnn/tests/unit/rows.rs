use ctrnn::testing::rows::Rows;

#[test]
fn rows_are_aligned_packed_and_hold_their_values() {
    let mut rows = Rows::<3>::zeros(3);
    rows.copy_from_slice(&[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]]);
    assert_eq!(rows.len(), 3);
    assert_eq!(rows[1], [4.0, 5.0, 6.0]);
    assert!((rows.as_ptr() as usize).is_multiple_of(64));
    assert_eq!(
        rows.as_flattened(),
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    );
    let mut wide = Rows::<16>::zeros(5);
    wide[4][15] = 1.0;
    assert!(wide
        .iter()
        .all(|r| (r.as_ptr() as usize).is_multiple_of(64)));
    assert_eq!(wide.as_flattened().iter().sum::<f64>(), 1.0);
    assert!(Rows::<1>::zeros(0).is_empty());
}
