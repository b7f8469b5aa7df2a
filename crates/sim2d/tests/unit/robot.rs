use proptest::prelude::*;
use sim2d::robot::CONTACT_MARGIN;
use sim2d::{Pose, RobotSpec, World, WorldSpec};
use std::f64::consts::{FRAC_PI_2, PI};
use streams::{Purpose, Stream};

fn landmark(n: u32) -> World {
    World::new(&WorldSpec::landmark(n).unwrap()).unwrap()
}

#[test]
fn straight_arc_and_spin_kinematics() {
    let w = landmark(1);
    let r = RobotSpec::default();
    // Turning on the spot: wheels +-0.45 * pi / 4 for 1 s turn pi/2 (omega = 0.9 pi/4 / 0.45).
    let mut p = Pose::new(1.0, 1.0, 0.0);
    let s = 0.45 * PI / 4.0;
    assert!(!r.step(&mut p, -s, s, 1.0, &w).unwrap());
    assert!((p.heading - FRAC_PI_2).abs() < 1e-12 && p.x == 1.0 && p.y == 1.0);
    // A quarter circle of radius 0.5 in 2 s: omega = pi / 4, v = 0.5 omega.
    let (vl, vr) = r.wheels(0.5 * PI / 4.0, PI / 4.0);
    let mut p = Pose::new(1.0, 1.0, 0.0);
    assert!(!r.step(&mut p, vl, vr, 2.0, &w).unwrap());
    assert!(
        (p.x - 1.5).abs() < 1e-12 && (p.y - 1.5).abs() < 1e-12,
        "{p:?}"
    );
    assert!((p.heading - FRAC_PI_2).abs() < 1e-12);
    // The same arc in ten steps lands on the same point.
    let mut q = Pose::new(1.0, 1.0, 0.0);
    for _ in 0..10 {
        r.step(&mut q, vl, vr, 0.2, &w).unwrap();
    }
    assert!((q.x - p.x).abs() < 1e-12 && (q.y - p.y).abs() < 1e-12);
    // Wheel speeds are clamped to max_speed.
    let mut p = Pose::new(1.0, 1.0, 0.0);
    r.step(&mut p, 5.0, 5.0, 1.0, &w).unwrap();
    assert!((p.x - 2.0).abs() < 1e-12);
}

#[test]
fn bad_commands_are_errors_and_leave_the_pose() {
    let w = landmark(1);
    let r = RobotSpec::default();
    let mut p = Pose::new(1.0, 1.0, 0.0);
    let e = r.step(&mut p, f64::NAN, 0.0, 0.1, &w).unwrap_err();
    assert_eq!(e.to_string(), "v_left is NaN; it must be a finite number");
    assert!(r.step(&mut p, 0.0, 0.0, -0.1, &w).is_err());
    assert_eq!(p, Pose::new(1.0, 1.0, 0.0));
    // A non-finite pose is not an error, but it does not panic either.
    let mut q = Pose::new(f64::NAN, 1.0, 0.0);
    r.step(&mut q, 0.5, 0.6, 0.1, &w).unwrap();
    let bad = RobotSpec {
        wheel_base: 0.0,
        ..RobotSpec::default()
    };
    assert_eq!(
        bad.validate().unwrap_err().to_string(),
        "robot.wheel_base is 0; it must be a finite number > 0"
    );
}

#[test]
fn stops_at_a_box_and_can_turn_away() {
    let w = landmark(1);
    let r = RobotSpec::default();
    // Heading +x at y = 2.5 towards the landmark's left face x = 2.4.
    let mut p = Pose::new(1.0, 2.5, 0.0);
    let mut contact = false;
    for _ in 0..40 {
        contact |= r.step(&mut p, 0.6, 0.6, 0.1, &w).unwrap();
    }
    assert!(contact);
    assert!((p.x - (2.4 - 0.265 - CONTACT_MARGIN)).abs() < 3e-5, "{p:?}");
    // Turn on the spot, then drive away.
    r.step(&mut p, -0.5, 0.5, PI * 0.45 / 1.0, &w).unwrap();
    assert!((p.heading.abs() - PI).abs() < 1e-9);
    assert!(!r.step(&mut p, 0.6, 0.6, 0.1, &w).unwrap());
    assert!(p.x < 2.4 - 0.265 - 0.05);
}

#[test]
fn random_driving_touches_things_but_never_enters_them() {
    let w = landmark(2);
    let r = RobotSpec::default();
    let mut s = Stream::new(1, 0, Purpose::Trial, 0, 0);
    let mut p = w.random_pose(r.radius, 0.0, &mut s).unwrap();
    let (mut contacts, mut moved) = (0, 0.0);
    let (mut vl, mut vr) = (0.0, 0.0);
    for k in 0..3000 {
        if k % 20 == 0 {
            vl = s.range(-0.3, 1.0);
            vr = s.range(-0.3, 1.0);
        }
        let before = p;
        contacts += u32::from(r.step(&mut p, vl, vr, 0.1, &w).unwrap());
        moved += (p.x - before.x).hypot(p.y - before.y);
        assert!(w.clearance(p.position(), r.radius) >= 0.5 * CONTACT_MARGIN);
    }
    assert!(contacts > 20, "{contacts} contacts");
    assert!(moved > 50.0, "moved {moved} m");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]
    /// From random starts, random wheel commands held for random spells never put the robot
    /// into a wall or a box.
    #[test]
    fn never_penetrates(seed in any::<u64>(), landmark_n in 1u32..=2, jitter in any::<bool>()) {
        let mut s = Stream::new(seed, 0, Purpose::Trial, 0, 0);
        let mut spec = WorldSpec::landmark(landmark_n).unwrap();
        if jitter {
            spec = spec.jittered(&mut s, 0.2, 0.15).unwrap();
        }
        let w = World::new(&spec).unwrap();
        let r = RobotSpec::default();
        let mut p = w.random_pose(r.radius, 0.0, &mut s).unwrap();
        let (mut vl, mut vr) = (0.0, 0.0);
        for k in 0..400 {
            if k % 10 == 0 {
                // Mostly forward, fast enough to hit things within a spell.
                vl = s.range(-0.6, 1.2);
                vr = s.range(-0.6, 1.2);
            }
            let dt = if k % 7 == 0 { 0.5 } else { 0.1 };
            r.step(&mut p, vl, vr, dt, &w).unwrap();
            let c = w.clearance(p.position(), r.radius);
            prop_assert!(c >= 0.5 * CONTACT_MARGIN, "step {}: clearance {} at {:?}", k, c, p);
            prop_assert!((-PI..=PI).contains(&p.heading));
        }
    }
}
