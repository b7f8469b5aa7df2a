use sim2d::{input, BoxSpec, Echo, Pose, Sonar, SonarSpec, StartRegion, World, WorldSpec};
use streams::{Purpose, Stream};

const TOL: f64 = 2e-5;

/// A 10 x 8 room with the given boxes.
fn world(boxes: Vec<BoxSpec>) -> World {
    World::new(&WorldSpec {
        room: [10.0, 8.0],
        boxes,
        start: StartRegion {
            min: [0.5, 0.5],
            max: [9.5, 7.5],
        },
    })
    .unwrap()
}

/// A forward-looking sonar on the robot's centre, with the given cone and rays.
fn forward(cone_deg: f64, rays: u32) -> SonarSpec {
    SonarSpec {
        mount_angle_deg: 0.0,
        mount_offset: 0.0,
        cone_deg,
        rays,
        max_range: 20.0,
        ..SonarSpec::default()
    }
}

fn stream() -> Stream {
    Stream::new(5, 0, Purpose::Trial, 0, 0)
}

#[test]
fn an_off_axis_ray_finds_the_nearer_box() {
    // Looking +x from (1, 4): the axis meets the right wall 9 m away. A small box with faces
    // x in [3.9, 4.1], y in [4.4, 4.6] lies off the axis. The 7 rays are 25 / 6 = 4.1667 deg
    // apart. At x = 3.9 (2.9 m ahead) the ray at +4.1667 deg is at y = 4 + 2.9 tan = 4.211
    // (below the box, and 4.226 at x = 4.1: a miss); the ray at +8.3333 deg is at y = 4.4248,
    // on the face, at distance 2.9 / cos(8.3333 deg) = 2.93094; the ray at +12.5 deg is at
    // y = 4.643 (above the box; it crossed y = 4.6 at x = 3.706, before the box).
    let w = world(vec![BoxSpec {
        center: [4.0, 4.5],
        size: [0.2, 0.2],
        angle_deg: 0.0,
    }]);
    let pose = Pose::new(1.0, 4.0, 0.0);
    let axis_only = Sonar::new(&forward(25.0, 1)).unwrap();
    let e = axis_only.read(&w, &pose, &mut stream());
    assert!((e.range - 9.0).abs() < TOL, "{e:?}");
    let cone = Sonar::new(&forward(25.0, 7)).unwrap();
    let e = cone.read(&w, &pose, &mut stream());
    let expected = 2.9 / (25.0f64 / 6.0 * 2.0).to_radians().cos();
    assert!((e.range - expected).abs() < TOL, "{e:?} vs {expected}");
    let [px, py] = e.point.unwrap();
    assert!((px - 3.9).abs() < TOL && (4.4..=4.6).contains(&py));
}

#[test]
fn nothing_in_range_gives_max_range_and_no_point() {
    let w = world(vec![]);
    let spec = SonarSpec {
        max_range: 5.0,
        ..forward(25.0, 7)
    };
    let e = Sonar::new(&spec)
        .unwrap()
        .read(&w, &Pose::new(1.0, 4.0, 0.0), &mut stream());
    assert_eq!(
        e,
        Echo {
            range: 5.0,
            point: None
        }
    );
}

#[test]
fn near_echoes_clamp_to_min_range() {
    let w = world(vec![]);
    let s = Sonar::new(&forward(10.0, 3)).unwrap();
    // 0.05 m from the right wall.
    let e = s.read(&w, &Pose::new(9.95, 4.0, 0.0), &mut stream());
    assert_eq!(e.range, 0.15);
    assert!(e.point.is_some());
}

#[test]
fn zero_noise_draws_nothing_and_noise_is_reproducible() {
    let w = world(vec![]);
    let pose = Pose::new(1.0, 4.0, 0.3);
    let quiet = Sonar::new(&forward(25.0, 7)).unwrap();
    let mut s = stream();
    let e = quiet.read(&w, &pose, &mut s);
    assert_eq!(s, stream(), "no draws with noise_sd = 0");
    let noisy = Sonar::new(&SonarSpec {
        noise_sd: 0.0,
        ..forward(25.0, 7)
    })
    .unwrap();
    assert_eq!(noisy.read(&w, &pose, &mut stream()), e);
    let noisy = Sonar::new(&SonarSpec {
        noise_sd: 0.05,
        ..forward(25.0, 7)
    })
    .unwrap();
    let run = |seed| {
        let mut s = Stream::new(seed, 0, Purpose::Trial, 0, 0);
        (0..50)
            .map(|k| noisy.read(&w, &Pose::new(1.0, 4.0, 0.01 * k as f64), &mut s))
            .collect::<Vec<_>>()
    };
    let a = run(11);
    assert_eq!(a, run(11));
    assert_ne!(a, run(12));
    let mean_err: f64 = a
        .iter()
        .zip(0..)
        .map(|(e, k)| {
            e.range
                - quiet
                    .read(&w, &Pose::new(1.0, 4.0, 0.01 * k as f64), &mut stream())
                    .range
        })
        .sum::<f64>()
        / 50.0;
    assert!(mean_err.abs() < 0.03, "{mean_err}");
    assert!(a.iter().any(|e| e.range != a[0].range));
}

#[test]
fn steep_incidence_loses_the_echo() {
    let w = world(vec![]);
    // One ray at 60 degrees of incidence to the right wall: from (9, 4) heading 60 deg from +x
    // the ray meets... the top wall y = 8 at incidence 30 deg (normal (0, -1)) after 4 / sin 60
    // = 4.6188 m, or the right wall x = 10 at incidence 60 deg after 1 / cos 60 = 2 m. It hits
    // the right wall first.
    let pose = Pose::new(9.0, 4.0, 60f64.to_radians());
    let spec = forward(25.0, 1);
    let e = Sonar::new(&spec).unwrap().read(&w, &pose, &mut stream());
    assert!((e.range - 2.0).abs() < TOL, "{e:?}");
    let lossy = SonarSpec {
        specular_max_incidence_deg: Some(45.0),
        ..spec.clone()
    };
    let e = Sonar::new(&lossy).unwrap().read(&w, &pose, &mut stream());
    assert_eq!(e.range, 20.0);
    assert_eq!(e.point, None);
    // Within the limit it echoes as before.
    let lenient = SonarSpec {
        specular_max_incidence_deg: Some(61.0),
        ..spec
    };
    let e = Sonar::new(&lenient).unwrap().read(&w, &pose, &mut stream());
    assert!((e.range - 2.0).abs() < TOL);
}

#[test]
fn mount_geometry_and_validation() {
    let s = Sonar::new(&SonarSpec::default()).unwrap();
    let p = s.mount_point(&Pose::new(1.0, 1.0, 0.0));
    assert!((p[0] - 1.0).abs() < 1e-12 && (p[1] - 1.265).abs() < 1e-12);
    let bad = SonarSpec {
        cone_deg: -3.0,
        ..SonarSpec::default()
    };
    assert_eq!(
        bad.validate().unwrap_err().to_string(),
        "sonar.cone_deg is -3; it must be in (0, 180)"
    );
    let bad = SonarSpec {
        rays: 0,
        ..SonarSpec::default()
    };
    assert_eq!(
        bad.validate().unwrap_err().to_string(),
        "sonar.rays is 0; it must be in [1, 4096]"
    );
    // A typing error in a count is named, not an allocation that takes the machine.
    let bad = SonarSpec {
        rays: 1_000_000_000,
        ..SonarSpec::default()
    };
    assert_eq!(
        bad.validate().unwrap_err().to_string(),
        "sonar.rays is 1000000000; it must be in [1, 4096]"
    );
    let bad = SonarSpec {
        max_range: 0.1,
        ..SonarSpec::default()
    };
    assert!(bad
        .validate()
        .unwrap_err()
        .to_string()
        .starts_with("sonar.max_range is 0.1"));
    assert_eq!(input(0.5, 0.5), 1.0);
    assert_eq!(input(0.0, 0.5), 1.0);
    assert_eq!(input(6.5, 0.5), 0.5 / 6.5);
}

#[test]
fn a_lobe_shortens_the_off_axis_rays() {
    // The scene of `an_off_axis_ray_finds_the_nearer_box`: only the ray 8.3333 deg off the axis
    // meets the box, 2.93094 m away; the axis meets the right wall 9 m away. With a 10 deg lobe
    // that ray reaches 20 exp(-(8.3333 / 10)^2) = 9.99 m and still echoes; with a 5 deg lobe it
    // reaches 20 exp(-(8.3333 / 5)^2) = 1.24 m and misses, and the axis (reaching 20 m) is left.
    let w = world(vec![BoxSpec {
        center: [4.0, 4.5],
        size: [0.2, 0.2],
        angle_deg: 0.0,
    }]);
    let pose = Pose::new(1.0, 4.0, 0.0);
    let lobed = |lobe: f64| SonarSpec {
        lobe_deg: Some(lobe),
        ..forward(25.0, 7)
    };
    let e = Sonar::new(&lobed(10.0))
        .unwrap()
        .read(&w, &pose, &mut stream());
    let expected = 2.9 / (25.0f64 / 6.0 * 2.0).to_radians().cos();
    assert!((e.range - expected).abs() < TOL, "{e:?} vs {expected}");
    let e = Sonar::new(&lobed(5.0))
        .unwrap()
        .read(&w, &pose, &mut stream());
    assert!((e.range - 9.0).abs() < TOL, "{e:?}");
    let e = SonarSpec {
        lobe_deg: Some(0.0),
        ..SonarSpec::default()
    }
    .validate()
    .unwrap_err();
    assert!(e.to_string().starts_with("sonar.lobe_deg is 0"), "{e}");
    let e = SonarSpec {
        lobe_deg: Some(5e-324),
        ..SonarSpec::default()
    }
    .validate()
    .unwrap_err();
    assert!(e.to_string().contains("also in radians"), "{e}");
}

#[test]
fn dropout_loses_that_fraction_of_readings_and_draws_only_when_on() {
    let w = world(vec![]);
    let pose = Pose::new(1.0, 4.0, 0.0);
    let lossy = Sonar::new(&SonarSpec {
        dropout: 0.25,
        ..forward(25.0, 1)
    })
    .unwrap();
    let mut s = stream();
    let lost = (0..4000)
        .filter(|_| {
            let e = lossy.read(&w, &pose, &mut s);
            assert!(e.range == 20.0 && e.point.is_none() || (e.range - 9.0).abs() < TOL);
            e.point.is_none()
        })
        .count();
    // Binomial(4000, 0.25): sd 27.4; 1000 +- 110 is four sds.
    assert!((890..=1110).contains(&lost), "{lost}");
    let (mut a, mut b) = (stream(), stream());
    Sonar::new(&forward(25.0, 7))
        .unwrap()
        .read(&w, &pose, &mut a);
    assert_eq!(a.next_u64(), b.next_u64(), "no dropout, no draw");
    let e = SonarSpec {
        dropout: 1.0,
        ..SonarSpec::default()
    }
    .validate()
    .unwrap_err();
    assert!(e.to_string().starts_with("sonar.dropout is 1"), "{e}");
}
