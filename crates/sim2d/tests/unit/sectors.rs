use sim2d::{Pose, SectorSpec};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

#[test]
fn sectors_are_centred_on_their_bearings() {
    let s = SectorSpec {
        count: 4,
        range: 5.0,
    };
    assert_eq!(s.sector(0.0), 0);
    assert_eq!(s.sector(FRAC_PI_2), 1);
    assert_eq!(s.sector(PI), 2);
    assert_eq!(s.sector(-PI + 1e-12), 2);
    assert_eq!(s.sector(-FRAC_PI_2), 3);
    // A border belongs to the counter-clockwise sector.
    assert_eq!(s.sector(FRAC_PI_4), 1);
    assert_eq!(s.sector(-FRAC_PI_4), 0);
    assert_eq!(s.sector(FRAC_PI_4 - 1e-12), 0);
    // Wrapped, and safe for nonsense.
    assert_eq!(s.sector(2.0 * PI), 0);
    assert_eq!(s.sector(f64::NAN), 0);
    let one = SectorSpec {
        count: 1,
        range: 5.0,
    };
    assert_eq!((one.sector(3.0), one.sector(-3.0)), (0, 0));
}

#[test]
fn each_sector_reads_its_nearest_pursuer() {
    let s = SectorSpec {
        count: 4,
        range: 5.0,
    };
    // Robot at (5, 5) facing +y: ahead is +y (sector 0), its left is -x (sector 1).
    let robot = Pose::new(5.0, 5.0, FRAC_PI_2);
    let pursuers = [
        Pose::new(5.0, 8.0, 0.0), // ahead, 3 m
        Pose::new(5.0, 7.0, 0.0), // ahead, 2 m: the nearer one counts
        Pose::new(3.0, 5.0, 0.0), // left, 2 m
        Pose::new(5.2, 5.0, 0.0), // right, overlapping: gap 0
    ];
    let mut out = [0.0; 4];
    s.read(&robot, 0.25, &pursuers, 0.2, &mut out);
    let want = [2.0 - 0.45, 2.0 - 0.45, 5.0, 0.0];
    for (g, w) in out.iter().zip(want) {
        assert!((g - w).abs() < 1e-12, "{out:?}");
    }
    // Beyond the range: the range.
    s.read(&robot, 0.25, &[Pose::new(5.0, 20.0, 0.0)], 0.2, &mut out);
    assert_eq!(out, [5.0; 4]);
    // Off: nothing is written.
    let mut none = [7.0; 2];
    SectorSpec::default().read(&robot, 0.25, &pursuers, 0.2, &mut none);
    assert_eq!(none, [7.0; 2]);
    assert!(SectorSpec {
        count: 2,
        range: 0.0
    }
    .validate()
    .unwrap_err()
    .to_string()
    .starts_with("sectors.range is 0"));
}
