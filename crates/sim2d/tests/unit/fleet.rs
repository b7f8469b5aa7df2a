use sim2d::{Fleet, FleetSpec, Pose, PursuerSpec, RingSpec, RobotSpec, SectorSpec, WorldSpec};
use streams::{Purpose, Stream};

/// Two pursuers, a noisy ring and the pursuer sensor: every part that draws or moves.
fn busy() -> FleetSpec {
    FleetSpec {
        sonar: RingSpec {
            noise_sd: 0.02,
            specular_max_incidence_deg: Some(60.0),
            ..RingSpec::default()
        },
        pursuers: PursuerSpec {
            count: 2,
            speed: 0.3,
            ..PursuerSpec::default()
        },
        sectors: SectorSpec {
            count: 4,
            ..SectorSpec::default()
        },
        ..FleetSpec::default()
    }
}

fn fleet(episodes: &[u64]) -> Fleet {
    let mut f = Fleet::new(&WorldSpec::landmark(2).unwrap(), &busy()).unwrap();
    f.reset(episodes, 11).unwrap();
    f
}

/// Wheel speeds for a row at a step, from the row's episode: any pattern that turns and
/// bumps into walls.
fn wheels(fleet: &Fleet, step: u64) -> Vec<f64> {
    fleet
        .rows()
        .iter()
        .flat_map(|r| {
            let mut s = Stream::new(r.episode(), step, Purpose::Evaluate, 0, 0);
            [s.range(-0.2, 1.0), s.range(-0.2, 1.0)]
        })
        .collect()
}

#[test]
fn a_row_does_not_depend_on_the_other_rows() {
    let mut many = fleet(&[4, 0, 1, 2, 3, 4]);
    let mut alone = fleet(&[4]);
    for t in 0..300 {
        many.step(&wheels(&many, t), None).unwrap();
        alone.step(&wheels(&alone, t), None).unwrap();
    }
    assert_eq!(many.rows()[0], alone.rows()[0]);
    assert_eq!(many.rows()[5], alone.rows()[0]);
    assert_ne!(many.rows()[1], alone.rows()[0]);
}

#[test]
fn any_number_of_threads_gives_the_same_bits() {
    let episodes: Vec<u64> = (0..37).collect();
    let mut serial = fleet(&episodes);
    let mut runs: Vec<(usize, Fleet)> = [1, 2, 3, 8].map(|t| (t, fleet(&episodes))).into();
    let (mut contacts, mut captures) = (0, 0);
    for t in 0..200 {
        let w = wheels(&serial, t);
        // Rows end at different steps, as episodes do.
        let active: Vec<bool> = (0..37).map(|r| t < 100 + 3 * r as u64).collect();
        serial.step(&w, Some(&active)).unwrap();
        contacts += serial.rows().iter().filter(|r| r.contact()).count();
        captures += serial.rows().iter().filter(|r| r.captured()).count();
        for (threads, f) in runs.iter_mut() {
            f.check_step(&w, Some(&active)).unwrap();
            let (arena, rows) = f.split_mut();
            let chunk = rows.len().div_ceil(*threads);
            std::thread::scope(|scope| {
                for (c, rows) in rows.chunks_mut(chunk).enumerate() {
                    let (w, active) = (&w, &active);
                    scope.spawn(move || {
                        for (i, row) in rows.iter_mut().enumerate() {
                            let r = c * chunk + i;
                            if active[r] {
                                arena.step_row(row, w[2 * r], w[2 * r + 1]).unwrap();
                            }
                        }
                    });
                }
            });
        }
    }
    for (threads, f) in &runs {
        assert_eq!(f.rows(), serial.rows(), "{threads} threads");
    }
    // The run did something: robots touched walls and were caught.
    assert!(
        contacts > 0 && captures > 0,
        "{contacts} contacts, {captures} captures"
    );
}

#[test]
fn an_inactive_row_is_left_alone_and_its_wheels_unread() {
    let mut f = fleet(&[0, 1]);
    let before = f.rows()[1].clone();
    let w = [0.5, 0.5, f64::NAN, f64::INFINITY];
    f.step(&w, Some(&[true, false])).unwrap();
    assert_eq!(f.rows()[1], before);
    assert_ne!(f.rows()[0].pose(), fleet(&[0]).rows()[0].pose());
}

#[test]
fn a_row_moves_as_the_robot_does() {
    let spec = FleetSpec::default();
    let mut f = Fleet::new(&WorldSpec::landmark(1).unwrap(), &spec).unwrap();
    f.reset(&[0], 3).unwrap();
    let start = Pose::new(1.0, 1.0, 0.3);
    f.place(&[start], None).unwrap();
    let world = f.arena().world().clone();
    let mut pose = start;
    for _ in 0..10 {
        f.step(&[0.3, 0.4], None).unwrap();
        RobotSpec::default()
            .step(&mut pose, 0.3, 0.4, spec.dt, &world)
            .unwrap();
    }
    assert_eq!(f.rows()[0].pose(), pose);
}

#[test]
fn starts_follow_seed_and_episode() {
    let a = fleet(&[0, 1]);
    let b = fleet(&[1, 0]);
    assert_eq!(a.rows()[0], b.rows()[1]);
    assert_ne!(a.rows()[0].pose(), a.rows()[1].pose());
    let mut c = Fleet::new(&WorldSpec::landmark(2).unwrap(), &busy()).unwrap();
    c.reset(&[0], 12).unwrap();
    assert_ne!(c.rows()[0].pose(), a.rows()[0].pose());
    for row in a.rows() {
        assert_eq!(row.pursuers().len(), 2);
        assert_eq!((row.ranges().len(), row.sectors().len()), (8, 4));
        for p in row.pursuers() {
            assert!((p.x - row.pose().x).hypot(p.y - row.pose().y) >= 2.0);
        }
        assert!(!row.contact() && !row.captured());
    }
}

#[test]
fn bad_arguments_are_refused_and_change_nothing() {
    let mut f = fleet(&[0, 1]);
    let before = f.rows().to_vec();
    let e = |r: Result<(), sim2d::Error>| r.unwrap_err().to_string();
    assert_eq!(
        e(f.step(&[0.1; 3], None)),
        "wheels is 3 values; it must be two per row, 4"
    );
    assert_eq!(
        e(f.step(&[0.1; 4], Some(&[true]))),
        "active is 1 flags; it must be one per row, 2"
    );
    assert_eq!(
        e(f.step(&[0.1, 0.1, 0.1, f64::INFINITY], None)),
        "wheels[1, 1] is inf; it must be a finite number"
    );
    assert_eq!(
        e(f.place(&[Pose::new(1.0, 1.0, 0.0)], None)),
        "poses is 1 poses; it must be one per row, 2"
    );
    let into_wall = [Pose::new(0.1, 1.0, 0.0), Pose::new(1.0, 1.0, 0.0)];
    assert!(e(f.place(&into_wall, None)).starts_with("poses[0] is (0.1, 1) with clearance"));
    let nan = [Pose::new(1.0, 1.0, 0.0), Pose::new(1.0, f64::NAN, 0.0)];
    assert_eq!(
        e(f.place(&nan, None)),
        "poses[1].y is NaN; it must be a finite number"
    );
    let ok = [Pose::new(1.0, 1.0, 0.0), Pose::new(1.0, 1.0, 0.0)];
    let pursuers = [Pose::new(4.0, 4.0, 0.0); 3];
    assert_eq!(
        e(f.place(&ok, Some(&pursuers))),
        "pursuers is 3 poses; it must be K = 2 per row, 4"
    );
    assert_eq!(f.rows(), before);
    let spec = |s: FleetSpec| {
        Fleet::new(&WorldSpec::landmark(1).unwrap(), &s)
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        spec(FleetSpec {
            start_clearance: -1.0,
            ..FleetSpec::default()
        }),
        "start_clearance is -1; it must be a finite number >= 0"
    );
    let tiny = FleetSpec {
        robot: RobotSpec {
            radius: f64::NAN,
            ..RobotSpec::default()
        },
        ..FleetSpec::default()
    };
    assert_eq!(
        spec(tiny),
        "robot.radius is NaN; it must be a finite number > 0"
    );
}
