use sim2d::testing::wall_follow::choose_wall;
use sim2d::{
    wrap_angle, Pose, RobotSpec, Sim, SimSpec, Surface, WallFollower, WallFollowerSpec, World,
    WorldSpec,
};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use streams::{Purpose, Stream};

/// What one run did. A lap is one full counter-clockwise turn of the robot's position around
/// the room's centre, counted from the moment the follower reached a wall.
#[derive(Debug)]
struct LapRun {
    /// Simulated seconds until the follow phase began.
    reached_wall: Option<f64>,
    /// Simulated seconds from reaching the wall to the end of the first and second laps.
    laps: [Option<f64>; 2],
    /// The least and largest distance from the robot's centre to the nearest outer wall while
    /// following, after the first 10 s of following.
    wall_gap: (f64, f64),
    /// Of the steps after the first 10 s of following, the fraction whose right-side ray (from
    /// the centre, 90 degrees right) met an outer wall within 1 m.
    wall_on_right: f64,
    /// Steps cut short by a contact.
    contacts: u64,
}

/// Runs until two laps are done or `limit_s` has passed.
fn lap_run(world: &World, start: Option<Pose>, stream: &mut Stream, limit_s: f64) -> LapRun {
    lap_run_with(&SimSpec::default(), world, start, stream, limit_s)
}

/// [`lap_run`] with the follower and robot of `spec`.
fn lap_run_with(
    spec: &SimSpec,
    world: &World,
    start: Option<Pose>,
    stream: &mut Stream,
    limit_s: f64,
) -> LapRun {
    let spec = spec.clone();
    let mut sim = match start {
        Some(p) => Sim::new(world, &spec, p).unwrap(),
        None => Sim::random_start(world, &spec, stream).unwrap(),
    };
    let [w, h] = world.room();
    let centre_angle = |p: Pose| (p.y - 0.5 * h).atan2(p.x - 0.5 * w);
    let mut echo = [Default::default()];
    let mut run = LapRun {
        reached_wall: None,
        laps: [None; 2],
        wall_gap: (f64::INFINITY, 0.0),
        wall_on_right: 0.0,
        contacts: 0,
    };
    let (mut angle, mut settled, mut right) = (0.0, 0u32, 0u32);
    let mut last = centre_angle(sim.pose());
    while sim.time() < limit_s && run.laps[1].is_none() {
        sim.step(stream, &mut echo).unwrap();
        let p = sim.pose();
        let a = centre_angle(p);
        if let Some(t0) = run.reached_wall {
            angle += wrap_angle(a - last);
            for k in 0..2 {
                if angle >= TAU * (k + 1) as f64 && run.laps[k].is_none() {
                    run.laps[k] = Some(sim.time() - t0);
                }
            }
            if sim.time() - t0 > 10.0 {
                let gap = p.x.min(w - p.x).min(p.y).min(h - p.y);
                run.wall_gap = (run.wall_gap.0.min(gap), run.wall_gap.1.max(gap));
                settled += 1;
                let hit = world.cast_ray(p.position(), p.direction_at(-FRAC_PI_2), 1.0);
                right += u32::from(hit.is_some_and(|h| h.surface == Surface::Wall));
            }
        } else if sim.follower().is_following() {
            run.reached_wall = Some(sim.time());
        }
        last = a;
    }
    run.wall_on_right = f64::from(right) / f64::from(settled.max(1));
    run.contacts = sim.contacts();
    run
}

/// Two counter-clockwise laps, the first within 120 s of the start, steadily along the walls.
fn check(run: &LapRun, what: &str) {
    let t0 = run
        .reached_wall
        .unwrap_or_else(|| panic!("{what}: no wall: {run:?}"));
    let lap = run.laps[0].unwrap_or_else(|| panic!("{what}: no lap: {run:?}"));
    assert!(t0 + lap <= 120.0, "{what}: {run:?}");
    let second = run.laps[1].unwrap_or_else(|| panic!("{what}: one lap only: {run:?}"));
    // The perimeter at 0.55 m from the walls is 2 (4.9 + 3.9) = 17.6 m: 29 s at 0.6 m/s, plus
    // the corners; every lap takes about as long.
    assert!((25.0..40.0).contains(&lap), "{what}: {run:?}");
    assert!((second - 2.0 * lap).abs() < 2.0, "{what}: {run:?}");
    // The centre stays near wall_distance = 0.55 from the nearest wall (corners are rounded).
    assert!(
        run.wall_gap.0 > 0.4 && run.wall_gap.1 < 0.7,
        "{what}: {run:?}"
    );
    assert!(run.wall_on_right > 0.9, "{what}: {run:?}");
    assert_eq!(run.contacts, 0, "{what}: {run:?}");
}

#[test]
fn laps_the_room_counter_clockwise_from_random_starts() {
    for n in [1, 2] {
        let world = World::new(&WorldSpec::landmark(n).unwrap()).unwrap();
        for trial in 0..20 {
            let mut s = Stream::new(2024, 0, Purpose::Trial, u64::from(n), trial);
            check(
                &lap_run(&world, None, &mut s, 120.0),
                &format!("landmark {n}, trial {trial}"),
            );
        }
    }
}

#[test]
fn laps_jittered_rooms() {
    for trial in 0..6 {
        let mut s = Stream::new(7, 0, Purpose::Trial, 0, trial);
        let spec = WorldSpec::landmark(1 + (trial % 2) as u32)
            .unwrap()
            .jittered(&mut s, 0.15, 0.1)
            .unwrap();
        let world = World::new(&spec).unwrap();
        let run = lap_run(&world, None, &mut s, 120.0);
        assert!(
            run.laps[1].is_some() && run.contacts == 0,
            "jitter {trial}: {run:?}"
        );
        assert!(run.wall_on_right > 0.9, "jitter {trial}: {run:?}");
    }
}

#[test]
fn starts_against_the_landmark_still_reach_the_perimeter() {
    // Poses touching the landmark (clearance 0.02 m) on each side, and in landmark 2's gap,
    // each facing four ways.
    let r = 0.265 + 0.02;
    let cases: [(u32, [f64; 2]); 7] = [
        (1, [2.4 - r, 2.5]),
        (1, [3.0, 2.2 - r]),
        (1, [3.6 + r, 2.8 + r]),
        (2, [3.0, 2.5]), // in the 0.6 m gap between the crates
        (2, [3.0, 2.8 + r]),
        (2, [2.1 - r, 2.2]),
        (2, [3.9 + r, 2.5]),
    ];
    for (n, [x, y]) in cases {
        let world = World::new(&WorldSpec::landmark(n).unwrap()).unwrap();
        for k in 0..4 {
            let start = Pose::new(x, y, 0.3 + k as f64 * FRAC_PI_2);
            let mut s = Stream::new(0, 0, Purpose::Trial, 0, 0);
            let run = lap_run(&world, Some(start), &mut s, 120.0);
            check(&run, &format!("landmark {n}, start {start:?}"));
        }
    }
}

#[test]
fn chooses_a_clear_corridor() {
    // Directly above landmark 1, the nearest wall is the top one; below it, the bottom one.
    // Just left of the landmark's centre line and 0.1 m below it, the nearest wall is the
    // bottom; but with the robot between the landmark and the left wall at (1.9, 2.5), both
    // left (1.9 m) and the clear corridor agree.
    let world = World::new(&WorldSpec::landmark(1).unwrap()).unwrap();
    let f = WallFollower::new(&WallFollowerSpec::default(), &RobotSpec::default()).unwrap();
    let t = choose_wall(&f, &world, &Pose::new(3.0, 3.2, 0.0));
    assert_eq!(t, FRAC_PI_2);
    let t = choose_wall(&f, &world, &Pose::new(1.9, 2.5, 0.0));
    assert_eq!(t, PI);
    // A world where a box blocks the way to the nearest (bottom) wall: it picks the next one.
    let mut spec = WorldSpec::landmark(1).unwrap();
    spec.boxes[0].center = [3.0, 0.5];
    let world = World::new(&spec).unwrap();
    let t = choose_wall(&f, &world, &Pose::new(3.0, 1.2, 0.0));
    assert_eq!(
        t, 0.0,
        "right wall (3 m) before left (3 m): ties keep bottom, right, top, left"
    );
}

#[test]
fn settings_are_validated() {
    let robot = RobotSpec::default();
    let bad = WallFollowerSpec {
        wall_distance: 0.3,
        ..WallFollowerSpec::default()
    };
    assert_eq!(
        bad.validate(&robot).unwrap_err().to_string(),
        "follower.wall_distance is 0.3; it must be a finite number > robot.radius + 0.1 = 0.365"
    );
    let bad = WallFollowerSpec {
        speed: -1.0,
        ..WallFollowerSpec::default()
    };
    assert!(WallFollower::new(&bad, &robot).is_err());
}

#[test]
fn a_weaving_follower_with_wide_corners_still_laps() {
    // A weakly damped law (angle gain 0.3: damping ratio about 0.1 at 0.6 m/s) that starts each
    // corner 0.9 m early: the held-out follower of the landmark transfer worlds.
    let mut spec = SimSpec::default();
    spec.follower.angle_gain = 0.3;
    spec.follower.corner_distance = 0.9;
    let (mut low, mut high) = (f64::INFINITY, 0.0f64);
    for n in [1, 2] {
        let world = World::new(&WorldSpec::landmark(n).unwrap()).unwrap();
        for trial in 0..6 {
            let mut s = Stream::new(2024, 0, Purpose::Trial, u64::from(n), trial);
            let run = lap_run_with(&spec, &world, None, &mut s, 150.0);
            assert!(run.laps[1].is_some() && run.contacts == 0, "{run:?}");
            assert!(run.wall_on_right > 0.8, "{run:?}");
            low = low.min(run.wall_gap.0);
            high = high.max(run.wall_gap.1);
        }
    }
    // It strays further from wall_distance = 0.55 than the default law's 0.4-0.7.
    assert!(low > 0.35 && high > 0.75, "{low} {high}");
    let bad = WallFollowerSpec {
        angle_gain: 0.0,
        ..WallFollowerSpec::default()
    };
    let e = bad.validate(&RobotSpec::default()).unwrap_err();
    assert!(e.to_string().starts_with("follower.angle_gain is 0"), "{e}");
    let bad = WallFollowerSpec {
        distance_gain: 101.0,
        ..WallFollowerSpec::default()
    };
    let e = bad.validate(&RobotSpec::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("follower.distance_gain is 101; it must be in (0, 100]"),
        "{e}"
    );
    // The front rays (2 m) must see where the corner turn starts: 0.55 + 1.45 is too far.
    let bad = WallFollowerSpec {
        corner_distance: 1.45,
        ..WallFollowerSpec::default()
    };
    let e = bad.validate(&RobotSpec::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("follower.corner_distance is 1.45; it must be less than"),
        "{e}"
    );
    // The robot's wheels would clamp a cruising speed above its top speed (1 m/s).
    let bad = WallFollowerSpec {
        speed: 1.5,
        ..WallFollowerSpec::default()
    };
    let e = bad.validate(&RobotSpec::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("follower.speed is 1.5; it must be in (0, 1]"),
        "{e}"
    );
}
