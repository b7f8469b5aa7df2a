use sim2d::{Disc, Pose, Ring, RingSpec, Scene, Sonar, SonarSpec, StartRegion, World, WorldSpec};
use streams::{Purpose, Stream};

fn room() -> WorldSpec {
    WorldSpec {
        room: [10.0, 8.0],
        boxes: vec![],
        start: StartRegion {
            min: [0.5, 0.5],
            max: [9.5, 7.5],
        },
    }
}

fn stream() -> Stream {
    Stream::new(3, 0, Purpose::Trial, 0, 1)
}

#[test]
fn the_default_ring_reads_the_walls_all_round() {
    let scene = Scene::new(&room());
    let ring = Ring::new(&RingSpec::default(), 0.25).unwrap();
    assert_eq!(ring.len(), 8);
    let mut ranges = [0.0; 8];
    // At (4, 3) facing +x: front 10 - 4 - 0.25, left 8 - 3 - 0.25, behind 4 - 0.25, right 3 -
    // 0.25. The three rays of a diagonal cone: the nearest is one of its edges.
    ring.read(
        &scene,
        &Pose::new(4.0, 3.0, 0.0),
        &[],
        &mut stream(),
        &mut ranges,
    );
    let want = [5.75, 4.75, 3.75, 2.75];
    for (got, want) in [ranges[0], ranges[2], ranges[4], ranges[6]]
        .iter()
        .zip(want)
    {
        assert!((got - want).abs() < 1e-12, "{ranges:?}");
    }
    // Facing +y, the front sonar reads the top wall.
    ring.read(
        &scene,
        &Pose::new(4.0, 3.0, std::f64::consts::FRAC_PI_2),
        &[],
        &mut stream(),
        &mut ranges,
    );
    assert!((ranges[0] - 4.75).abs() < 1e-12);
}

#[test]
fn a_pursuer_echoes_before_the_wall_behind_it_and_clamps_to_min_range() {
    let scene = Scene::new(&room());
    let spec = RingSpec {
        angles_deg: vec![0.0],
        rays: 1,
        ..RingSpec::default()
    };
    let ring = Ring::new(&spec, 0.25).unwrap();
    let mut r = [0.0];
    let pursuer = |x: f64| Disc {
        center: [x, 3.0],
        radius: 0.2,
    };
    ring.read(
        &scene,
        &Pose::new(4.0, 3.0, 0.0),
        &[pursuer(6.0)],
        &mut stream(),
        &mut r,
    );
    assert!((r[0] - (2.0 - 0.25 - 0.2)).abs() < 1e-12);
    // Nearer than min_range (0.15): min_range.
    ring.read(
        &scene,
        &Pose::new(4.0, 3.0, 0.0),
        &[pursuer(4.5)],
        &mut stream(),
        &mut r,
    );
    assert_eq!(r[0], 0.15);
    // Beyond max_range (6.5): max_range.
    let far = Pose::new(0.5, 3.0, 0.0);
    ring.read(&scene, &far, &[], &mut stream(), &mut r);
    assert_eq!(r[0], 6.5);
}

#[test]
fn noise_is_drawn_only_for_an_echo() {
    let scene = Scene::new(&room());
    let spec = RingSpec {
        angles_deg: vec![0.0, 180.0],
        noise_sd: 0.01,
        ..RingSpec::default()
    };
    let ring = Ring::new(&spec, 0.25).unwrap();
    let mut s = stream();
    let mut r = [0.0; 2];
    // Facing +x from x = 0.5: nothing within 6.5 ahead; the wall behind echoes.
    ring.read(&scene, &Pose::new(0.5, 4.0, 0.0), &[], &mut s, &mut r);
    assert_eq!(r[0], 6.5);
    let mut one = stream();
    one.normal();
    assert_eq!(s, one, "one draw, for the echo behind");
    assert!((r[1] - 0.25).abs() < 0.05 && r[1] != 0.25);
}

#[test]
fn a_ring_reads_as_the_landmark_sonar_does_to_f32_rounding() {
    // The landmark task's left sonar (parry2d, f32) and a ring of one sonar at 90 degrees on a
    // robot of its radius (f64).
    let spec = WorldSpec::landmark(2).unwrap();
    let world = World::new(&spec).unwrap();
    let scene = Scene::new(&spec);
    let sonar = Sonar::new(&SonarSpec::default()).unwrap();
    let ring = Ring::new(
        &RingSpec {
            angles_deg: vec![90.0],
            rays: 7,
            ..RingSpec::default()
        },
        0.265,
    )
    .unwrap();
    let mut s = Stream::new(5, 0, Purpose::Trial, 0, 0);
    for _ in 0..500 {
        let pose = world.random_pose(0.265, 0.01, &mut s).unwrap();
        let mut r = [0.0];
        ring.read(&scene, &pose, &[], &mut stream(), &mut r);
        let echo = sonar.read(&world, &pose, &mut stream());
        assert!((r[0] - echo.range).abs() < 1e-4, "{pose:?}: {r:?} {echo:?}");
    }
}

#[test]
fn bad_rings_are_refused_by_name() {
    let bad = |spec: RingSpec| Ring::new(&spec, 0.25).unwrap_err().to_string();
    assert_eq!(
        bad(RingSpec {
            angles_deg: vec![0.0, f64::NAN],
            ..RingSpec::default()
        }),
        "sonar.angles_deg[1] is NaN; it must be in [-360, 360]"
    );
    assert_eq!(
        bad(RingSpec {
            angles_deg: vec![1000.0],
            ..RingSpec::default()
        }),
        "sonar.angles_deg[0] is 1000; it must be in [-360, 360]"
    );
    assert_eq!(
        bad(RingSpec {
            cone_deg: 180.0,
            ..RingSpec::default()
        }),
        "sonar.cone_deg is 180; it must be in (0, 180)"
    );
    assert_eq!(
        bad(RingSpec {
            rays: 0,
            ..RingSpec::default()
        }),
        "sonar.rays is 0; it must be in [1, 4096]"
    );
    assert!(Ring::new(&RingSpec::default(), -1.0).is_err());
}
