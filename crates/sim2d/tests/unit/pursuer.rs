use sim2d::{BoxSpec, Fleet, FleetSpec, Pose, PursuerSpec, StartRegion, World, WorldSpec};
use std::f64::consts::FRAC_PI_2;
use streams::{Purpose, Stream};

fn open_room() -> WorldSpec {
    WorldSpec {
        room: [10.0, 10.0],
        boxes: vec![],
        start: StartRegion {
            min: [0.5, 0.5],
            max: [9.5, 9.5],
        },
    }
}

fn one() -> PursuerSpec {
    PursuerSpec {
        count: 1,
        ..PursuerSpec::default()
    }
}

/// A fleet of one row with the robot and its pursuer placed by hand.
fn placed(spec: PursuerSpec, robot: Pose, pursuer: Pose) -> Fleet {
    let fleet_spec = FleetSpec {
        pursuers: spec,
        ..FleetSpec::default()
    };
    let mut fleet = Fleet::new(&open_room(), &fleet_spec).unwrap();
    fleet.reset(&[0], 0).unwrap();
    fleet.place(&[robot], Some(&[pursuer])).unwrap();
    fleet
}

#[test]
fn a_pursuer_straight_behind_a_still_robot_closes_in_and_captures_it() {
    // Robot at (5, 1), pursuer at (1, 1) facing it: 4 m apart, closing at 0.4 m/s, so 0.04 m per
    // step of 0.1 s; captured at 0.5 m, after 3.5 / 0.04 = 87.5 steps: at step 88.
    let mut fleet = placed(one(), Pose::new(5.0, 1.0, 0.0), Pose::new(1.0, 1.0, 0.0));
    let still = [0.0, 0.0];
    for step in 1..=88 {
        fleet.step(&still, None).unwrap();
        let row = &fleet.rows()[0];
        let p = row.pursuers()[0];
        assert!((p.x - (1.0 + 0.04 * step as f64)).abs() < 1e-12, "{p:?}");
        assert_eq!((p.y, p.heading), (1.0, 0.0));
        assert_eq!(row.captured(), step == 88, "step {step}");
        assert_eq!(row.pose(), Pose::new(5.0, 1.0, 0.0));
    }
}

#[test]
fn capture_is_at_exactly_the_radius() {
    let robot = Pose::new(2.0, 2.0, 0.0);
    // 0.5 m exactly (0.5 is exact in binary): captured; a hair further: not.
    let fleet = placed(one(), robot, Pose::new(2.5, 2.0, 0.0));
    assert!(fleet.rows()[0].captured());
    let fleet = placed(one(), robot, Pose::new(2.5 + 1e-12, 2.0, 0.0));
    assert!(!fleet.rows()[0].captured());
    let fleet = placed(one(), robot, Pose::new(2.0, 1.5, 0.0));
    assert!(fleet.rows()[0].captured());
}

#[test]
fn the_turning_limit_holds_and_a_near_turn_is_exact() {
    let world = World::new(&open_room()).unwrap();
    let spec = one();
    // The robot at 90 degrees: only 1.5 rad/s x 0.1 s = 0.15 rad of turn per step.
    let mut p = Pose::new(5.0, 5.0, 0.0);
    spec.step(&mut p, [5.0, 8.0], 0.1, &world).unwrap();
    assert!((p.heading - 0.15).abs() < 1e-15);
    // 0.1 rad off: turned exactly onto the bearing in one step.
    let mut p = Pose::new(5.0, 5.0, FRAC_PI_2 - 0.1);
    spec.step(&mut p, [5.0, 8.0], 0.1, &world).unwrap();
    assert!((p.heading - FRAC_PI_2).abs() < 1e-15);
    // No turning at all: a pursuer that cannot turn drives straight on.
    let stiff = PursuerSpec {
        max_turn_rate: 0.0,
        ..one()
    };
    let mut p = Pose::new(5.0, 5.0, 0.0);
    stiff.step(&mut p, [5.0, 8.0], 0.1, &world).unwrap();
    assert_eq!((p.y, p.heading), (5.0, 0.0));
}

#[test]
fn a_pursuer_never_enters_a_wall() {
    let world = World::new(&open_room()).unwrap();
    let spec = PursuerSpec {
        speed: 2.0,
        ..one()
    };
    // Chasing a target beyond the right wall: it stops at the wall.
    let mut p = Pose::new(5.0, 5.0, 0.0);
    let mut touched = false;
    for _ in 0..100 {
        touched |= spec.step(&mut p, [20.0, 5.0], 0.1, &world).unwrap();
        assert!(world.clearance(p.position(), spec.radius) >= 0.0);
    }
    assert!(touched && p.x > 9.79 && p.x < 9.8, "{p:?}");
    assert!(spec.step(&mut p, [20.0, 5.0], f64::NAN, &world).is_err());
}

#[test]
fn random_starts_keep_their_distance_or_say_why_not() {
    let world = World::new(&open_room()).unwrap();
    let robot = Pose::new(5.0, 5.0, 0.0);
    let mut s = Stream::new(1, 0, Purpose::Trial, 0, 0);
    let mut out = [Pose::default(); 20];
    let spec = PursuerSpec {
        min_start_distance: 4.0,
        ..one()
    };
    spec.place(&world, &robot, 0.05, &mut s, &mut out).unwrap();
    for p in out {
        assert!((p.x - 5.0).hypot(p.y - 5.0) >= 4.0);
        assert!(world.clearance(p.position(), spec.radius) >= 0.05);
    }
    let far = PursuerSpec {
        min_start_distance: 20.0,
        ..one()
    };
    let e = far
        .place(&world, &robot, 0.05, &mut s, &mut out)
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("pursuers.min_start_distance is 20; it must be small enough"),
        "{e}"
    );
    let bad = PursuerSpec {
        speed: -1.0,
        ..one()
    };
    assert_eq!(
        bad.validate().unwrap_err().to_string(),
        "pursuers.speed is -1; it must be a finite number >= 0"
    );
}

#[test]
fn a_box_stops_pure_pursuit_and_a_detour_goes_round_it() {
    // A 1 m crate between a still robot at (5, 8) and a pursuer at (5, 2) facing it.
    let world = WorldSpec {
        boxes: vec![BoxSpec {
            center: [5.0, 5.0],
            size: [1.0, 1.0],
            angle_deg: 0.0,
        }],
        ..open_room()
    };
    let chase = |detour: bool| {
        let spec = FleetSpec {
            pursuers: PursuerSpec { detour, ..one() },
            ..FleetSpec::default()
        };
        let mut fleet = Fleet::new(&world, &spec).unwrap();
        fleet.reset(&[0], 0).unwrap();
        let start = Pose::new(5.0, 2.0, FRAC_PI_2);
        fleet
            .place(&[Pose::new(5.0, 8.0, 0.0)], Some(&[start]))
            .unwrap();
        let w = World::new(&world).unwrap();
        for step in 1..=600 {
            fleet.step(&[0.0, 0.0], None).unwrap();
            let row = &fleet.rows()[0];
            assert!(w.clearance(row.pursuers()[0].position(), 0.2) >= 0.0);
            if row.captured() {
                return Some(step);
            }
        }
        None
    };
    // Pure pursuit presses into the crate's face for the whole minute.
    assert_eq!(chase(false), None);
    // The detour turns left along the face, round the corner and on to the robot: 6 m straight
    // would take 14 s at 0.4 m/s; going round costs a few seconds more.
    let caught = chase(true).expect("the detour reaches the robot");
    assert!((140..300).contains(&caught), "caught at step {caught}");
}

#[test]
fn a_detour_changes_nothing_in_open_space() {
    let world = World::new(&open_room()).unwrap();
    let (plain, detour) = (
        one(),
        PursuerSpec {
            detour: true,
            ..one()
        },
    );
    let (mut a, mut b) = (Pose::new(2.0, 2.0, 0.0), Pose::new(2.0, 2.0, 0.0));
    for _ in 0..100 {
        assert!(!plain.step(&mut a, [7.0, 6.0], 0.1, &world).unwrap());
        assert!(!detour.step(&mut b, [7.0, 6.0], 0.1, &world).unwrap());
        assert_eq!(a, b);
    }
}
