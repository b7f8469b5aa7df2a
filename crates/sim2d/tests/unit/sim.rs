use sim2d::{Echo, Pose, RobotSpec, Sim, SimSpec, SonarSpec, Trace, World, WorldSpec};
use streams::{Purpose, Stream};

fn noisy_spec() -> SimSpec {
    SimSpec {
        sonars: vec![
            SonarSpec {
                noise_sd: 0.05,
                specular_max_incidence_deg: Some(60.0),
                ..SonarSpec::default()
            },
            SonarSpec {
                mount_angle_deg: 0.0,
                ..SonarSpec::default()
            },
        ],
        ..SimSpec::default()
    }
}

fn trace(world: &World, spec: &SimSpec, seed: u64) -> Trace {
    let mut s = Stream::new(seed, 3, Purpose::Trial, 1, 2);
    let mut sim = Sim::random_start(world, spec, &mut s).unwrap();
    let mut t = Trace::with_capacity(450, 2);
    sim.run(450, &mut s, Some(&mut t)).unwrap();
    t
}

#[test]
fn same_seed_same_trial_to_the_bit() {
    let world = World::new(&WorldSpec::landmark(2).unwrap()).unwrap();
    let spec = noisy_spec();
    let a = trace(&world, &spec, 1);
    assert_eq!(a.poses.len(), 450);
    assert_eq!(a.echoes.len(), 900);
    let b = trace(&world, &spec, 1);
    let bits = |t: &Trace| -> Vec<u64> {
        t.echoes
            .iter()
            .map(|e| e.range.to_bits())
            .chain(t.poses.iter().map(|p| p.x.to_bits()))
            .collect()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_ne!(bits(&a), bits(&trace(&world, &spec, 2)));
}

#[test]
fn step_and_run_agree_and_run_without_trace() {
    let world = World::new(&WorldSpec::landmark(1).unwrap()).unwrap();
    let spec = noisy_spec();
    let t = trace(&world, &spec, 5);
    let mut s = Stream::new(5, 3, Purpose::Trial, 1, 2);
    let mut sim = Sim::random_start(&world, &spec, &mut s).unwrap();
    let mut echoes = [Echo::default(); 2];
    for k in 0..450 {
        assert_eq!(sim.pose(), t.poses[k]);
        sim.step(&mut s, &mut echoes).unwrap();
        assert_eq!(echoes[..], t.echoes[2 * k..2 * k + 2]);
    }
    let mut s = Stream::new(5, 3, Purpose::Trial, 1, 2);
    let mut quiet = Sim::random_start(&world, &spec, &mut s).unwrap();
    quiet.run(450, &mut s, None).unwrap();
    assert_eq!(quiet.pose(), sim.pose());
    assert_eq!(quiet.steps(), 450);
    assert!((quiet.time() - 45.0).abs() < 1e-9);
}

#[test]
fn the_left_sonar_sees_the_landmark_while_lapping() {
    for n in [1, 2] {
        let world = World::new(&WorldSpec::landmark(n).unwrap()).unwrap();
        let spec = SimSpec::default();
        let mut s = Stream::new(0, 0, Purpose::Trial, 0, u64::from(n));
        let mut sim = Sim::random_start(&world, &spec, &mut s).unwrap();
        let mut t = Trace::default();
        sim.run(450, &mut s, Some(&mut t)).unwrap();
        let on_box = t
            .echoes
            .iter()
            .filter(|e| {
                e.point.is_some_and(|p| {
                    // Within the landmark's bounding box (x in [2.1, 3.9], y in [2.2, 2.8]).
                    (2.09..=3.91).contains(&p[0]) && (2.19..=2.81).contains(&p[1])
                })
            })
            .count();
        // On the long sides the landmark fills the view for a good part of a lap.
        assert!(
            on_box > 45,
            "landmark {n}: {on_box} of 450 echoes from the landmark"
        );
        assert_eq!(sim.contacts(), 0);
    }
}

#[test]
fn spec_reads_from_partial_toml() {
    let spec: SimSpec =
        toml::from_str("dt = 0.2\n[robot]\nradius = 0.3\n[[sonars]]\ncone_deg = 30\n").unwrap();
    assert_eq!(spec.dt, 0.2);
    assert_eq!(spec.robot.radius, 0.3);
    assert_eq!(spec.robot.wheel_base, RobotSpec::default().wheel_base);
    assert_eq!(spec.sonars.len(), 1);
    assert_eq!(spec.sonars[0].cone_deg, 30.0);
    assert_eq!(spec.sonars[0].rays, 7);
    spec.validate().unwrap();
    assert!(toml::from_str::<SimSpec>("[robot]\nradiu = 0.3\n").is_err());
}

#[test]
fn bad_use_is_an_error() {
    let world = World::new(&WorldSpec::landmark(1).unwrap()).unwrap();
    let spec = SimSpec::default();
    let e = Sim::new(&world, &spec, Pose::new(3.0, 2.5, 0.0)).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("start is (3, 2.5) with clearance"),
        "{e}"
    );
    let [w, h] = world.room();
    for (x, y) in [(w + 1.0, 1.0), (1.0, -2.0), (-1.0, h + 1.0)] {
        let e = Sim::new(&world, &spec, Pose::new(x, y, 0.0)).unwrap_err();
        assert!(
            e.to_string()
                .contains("; it must be a position inside the room"),
            "{e}"
        );
    }
    let mut sim = Sim::new(&world, &spec, Pose::new(1.0, 1.0, 0.0)).unwrap();
    let mut s = Stream::new(0, 0, Purpose::Trial, 0, 0);
    let e = sim.step(&mut s, &mut []).unwrap_err();
    assert_eq!(
        e.to_string(),
        "echoes.len() is 0; it must be the number of sonars, 1"
    );
    let bad = SimSpec {
        sonars: vec![
            SonarSpec::default(),
            SonarSpec {
                cone_deg: 200.0,
                ..SonarSpec::default()
            },
        ],
        ..SimSpec::default()
    };
    let e = Sim::new(&world, &bad, Pose::new(1.0, 1.0, 0.0)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "sonars[1].cone_deg is 200; it must be in (0, 180)"
    );
    let bad = SimSpec {
        dt: 0.0,
        ..SimSpec::default()
    };
    assert!(Sim::new(&world, &bad, Pose::new(1.0, 1.0, 0.0)).is_err());
}
