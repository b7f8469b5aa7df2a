use sim2d::{BoxSpec, Error, StartRegion, Surface, World, WorldSpec};
use std::f64::consts::PI;
use streams::{Purpose, Stream};

const TOL: f64 = 2e-5; // f32 arithmetic in parry2d

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

fn square(center: [f64; 2], side: f64, angle_deg: f64) -> BoxSpec {
    BoxSpec {
        center,
        size: [side, side],
        angle_deg,
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < TOL
}

#[test]
fn ray_against_axis_aligned_box() {
    // A 2 x 1 box centred at (5, 4): faces at x = 4 and 6, y = 3.5 and 4.5.
    let w = world(vec![BoxSpec {
        center: [5.0, 4.0],
        size: [2.0, 1.0],
        angle_deg: 0.0,
    }]);
    // From (1, 4.2) along +x: the face x = 4 at distance 3.
    let h = w.cast_ray([1.0, 4.2], [1.0, 0.0], 100.0).unwrap();
    assert!(close(h.distance, 3.0), "{h:?}");
    assert!(close(h.point[0], 4.0) && close(h.point[1], 4.2));
    assert_eq!(h.normal, [-1.0, 0.0]);
    assert_eq!(h.surface, Surface::Box(0));
    // From (5.5, 0.5) along +y: the bottom face y = 3.5 at distance 3.
    let h = w.cast_ray([5.5, 0.5], [0.0, 2.0], 100.0).unwrap();
    assert!(close(h.distance, 3.0) && h.normal == [0.0, -1.0], "{h:?}");
    // From (1, 1) along (3, 2.6): the ray meets x = 4 at y = 3.6, on the left face just above
    // the corner (4, 3.5), at distance sqrt(9 + 6.76) = 3.96989.
    let h = w.cast_ray([1.0, 1.0], [3.0, 2.6], 100.0).unwrap();
    assert!(close(h.distance, (9.0f64 + 6.76).sqrt()), "{h:?}");
    assert!(close(h.point[0], 4.0) && close(h.point[1], 3.6));
    // Past the box along y = 4.6 (above its top face): the right wall x = 10 at distance 9.
    let h = w.cast_ray([1.0, 4.6], [1.0, 0.0], 100.0).unwrap();
    assert!(close(h.distance, 9.0) && h.surface == Surface::Wall);
    assert_eq!(h.normal, [-1.0, 0.0]);
    // A range shorter than the box: nothing.
    assert!(w.cast_ray([1.0, 4.2], [1.0, 0.0], 2.9).is_none());
    // A zero direction: nothing.
    assert!(w.cast_ray([1.0, 4.2], [0.0, 0.0], 9.0).is_none());
}

#[test]
fn ray_against_rotated_box() {
    // A unit-sided square at (5, 4) turned 45 degrees: a diamond whose corners are
    // 1/sqrt(2) = 0.70711 from the centre along the axes, and whose faces are 0.5 from it.
    let w = world(vec![square([5.0, 4.0], 1.0, 45.0)]);
    let half_diag = 0.5 * 2f64.sqrt();
    // Along +x from (1, 4): the left corner at x = 5 - 0.70711, distance 4 - 0.70711.
    let h = w.cast_ray([1.0, 4.0], [1.0, 0.0], 100.0).unwrap();
    assert!(close(h.distance, 4.0 - half_diag), "{h:?}");
    // Along the face normal (1, 1)/sqrt 2 from (3, 2), aimed at the centre: the lower-left face
    // is 0.5 before the centre, which is 2 sqrt 2 = 2.82843 away: distance 2.32843, and the
    // face's normal is (-1, -1)/sqrt 2, so incidence is 0.
    let h = w.cast_ray([3.0, 2.0], [1.0, 1.0], 100.0).unwrap();
    assert!(close(h.distance, 2.0 * 2f64.sqrt() - 0.5), "{h:?}");
    let n = -(0.5f64.sqrt());
    assert!(close(h.normal[0], n) && close(h.normal[1], n), "{h:?}");
    // A ray along y = 4.3 from the left meets the upper-left face, the line from the left corner
    // (4.29289, 4) to the top corner (5, 4.70711), i.e. x - y = 0.29289: x = 4.59289, at
    // distance 3.59289 from x = 1.
    let h = w.cast_ray([1.0, 4.3], [1.0, 0.0], 100.0).unwrap();
    assert!(close(h.distance, 4.3 - half_diag), "{h:?}");
}

#[test]
fn walls_bound_the_room_and_rays_from_inside_a_box_stop_at_once() {
    let w = world(vec![square([5.0, 4.0], 1.0, 0.0)]);
    let h = w.cast_ray([2.0, 1.0], [0.0, -1.0], 100.0).unwrap();
    assert!(close(h.distance, 1.0) && h.normal == [0.0, 1.0]);
    let h = w.cast_ray([2.0, 1.0], [-1.0, 0.0], 100.0).unwrap();
    assert!(close(h.distance, 2.0) && h.normal == [1.0, 0.0]);
    let h = w.cast_ray([2.0, 7.0], [0.0, 1.0], 100.0).unwrap();
    assert!(close(h.distance, 1.0) && h.normal == [0.0, -1.0]);
    let h = w.cast_ray([5.0, 4.0], [0.0, 1.0], 100.0).unwrap();
    assert_eq!(h.distance, 0.0);
}

#[test]
fn a_ray_from_a_non_finite_origin_hits_nothing_and_panics_not() {
    let w = world(vec![square([5.0, 4.0], 1.0, 30.0)]);
    for origin in [[f64::NAN, 1.0], [1.0, f64::INFINITY], [1e300, 1.0]] {
        assert!(w.cast_ray(origin, [1.0, 0.0], 10.0).is_none(), "{origin:?}");
    }
    assert!(w.cast_ray([1.0, 4.0], [1.0, 0.0], 10.0).is_some());
}

#[test]
fn clearance_is_signed() {
    let w = world(vec![square([5.0, 4.0], 1.0, 0.0)]);
    assert!(close(w.clearance([1.0, 4.0], 0.25), 0.75)); // left wall
    assert!(close(w.clearance([3.0, 4.0], 0.25), 1.25)); // box face x = 4.5
    assert!(close(w.clearance([4.0, 4.0], 0.25), 0.25));
    assert!(close(w.clearance([4.6, 4.0], 0.25), -0.35)); // 0.1 inside the box
    assert!(close(w.clearance([0.1, 4.0], 0.25), -0.15)); // into the left wall
    assert!(w.disc_overlaps([0.1, 4.0], 0.25));
    assert!(!w.disc_overlaps([1.0, 4.0], 0.25));
    // Towards the box's corner (4.5, 3.5) from (4, 3): sqrt(0.5) = 0.70711.
    assert!(close(w.clearance([4.0, 3.0], 0.0), 0.5f64.sqrt()));
}

#[test]
fn random_pose_is_clear_reproducible_and_fails_cleanly() {
    let w = World::new(&WorldSpec::landmark(1).unwrap()).unwrap();
    for t in 0..100 {
        let mut s = Stream::new(3, 0, Purpose::Trial, 0, t);
        let p = w.random_pose(0.265, 0.05, &mut s).unwrap();
        assert!(w.clearance(p.position(), 0.265) >= 0.05);
        assert!((-PI..PI).contains(&p.heading));
        let mut s2 = Stream::new(3, 0, Purpose::Trial, 0, t);
        assert_eq!(w.random_pose(0.265, 0.05, &mut s2).unwrap(), p);
    }
    let mut s = Stream::new(3, 0, Purpose::Trial, 0, 0);
    let e = w.random_pose(3.0, 0.0, &mut s).unwrap_err();
    assert!(matches!(e, Error::NoStartPose { .. }));
    assert!(w.random_pose(-1.0, 0.0, &mut s).is_err());
}

#[test]
fn the_free_share_of_the_start_region_matches_hand_computed_cases() {
    let spec = |boxes: Vec<BoxSpec>, min: [f64; 2], max: [f64; 2]| {
        World::new(&WorldSpec {
            room: [4.0, 2.0],
            boxes,
            start: StartRegion { min, max },
        })
        .unwrap()
    };
    // An empty room whose start region keeps 0.315 m from every wall: free everywhere.
    let open = spec(vec![], [0.4, 0.4], [3.6, 1.6]);
    assert_eq!(open.start_free_share(0.265, 0.05), 1.0);
    open.check_start(0.265, 0.05).unwrap();
    // A 2 m x 2 m box fills the room's right half. A robot of radius 0.265 with clearance 0.05
    // fits where 0.315 <= x <= 1.685 and 0.315 <= y <= 1.685: of the start region
    // [0.3, 3.7] x [0.3, 1.7], a share (1.37 / 3.4) (1.37 / 1.4) = 0.394, to within a grid cell.
    let half = spec(
        vec![BoxSpec {
            center: [3.0, 1.0],
            size: [2.0, 2.0],
            angle_deg: 0.0,
        }],
        [0.3, 0.3],
        [3.7, 1.7],
    );
    let share = half.start_free_share(0.265, 0.05);
    assert!((share - 0.394).abs() < 2.0 / 64.0, "{share}");
    half.check_start(0.265, 0.05).unwrap();
    // A robot of radius 0.99 fits only in a 0.02 m x 0.02 m square: too little.
    let e = half.check_start(0.99, 0.0).unwrap_err();
    assert!(matches!(e, Error::StartBlocked { .. }), "{e}");
    assert!(
        e.to_string().contains("enlarge start or move the boxes"),
        "{e}"
    );
    // A robot that fits nowhere, and bad arguments.
    assert_eq!(half.start_free_share(1.2, 0.0), 0.0);
    assert!(half.check_start(-1.0, 0.0).is_err());
    assert!(half.check_start(0.2, f64::NAN).is_err());
}
