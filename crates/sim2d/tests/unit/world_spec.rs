use sim2d::WorldSpec;
use streams::{Purpose, Stream};

#[test]
fn shipped_worlds_parse_and_match_the_paper_defaults() {
    let w1 = WorldSpec::landmark(1).unwrap();
    let w2 = WorldSpec::landmark(2).unwrap();
    assert_eq!(WorldSpec::default(), w1);
    for w in [&w1, &w2] {
        assert_eq!(w.room, [6.0, 5.0]);
    }
    // Landmark 1: one 1.2 x 0.6 rectangle (two crates pushed together) at the centre.
    assert_eq!(w1.boxes.len(), 1);
    assert_eq!(w1.boxes[0].size, [1.2, 0.6]);
    assert_eq!(w1.boxes[0].center, [3.0, 2.5]);
    // Landmark 2: two 0.6 crates with a 0.6 gap, symmetric about the centre.
    assert_eq!(w2.boxes.len(), 2);
    let gap = (w2.boxes[1].center[0] - 0.3) - (w2.boxes[0].center[0] + 0.3);
    assert!((gap - 0.6).abs() < 1e-12);
    assert!((w2.boxes[0].center[0] + w2.boxes[1].center[0] - 6.0).abs() < 1e-12);
}

#[test]
fn toml_round_trip() {
    for n in [1, 2] {
        let w = WorldSpec::landmark(n).unwrap();
        let text = w.to_toml_string().unwrap();
        assert_eq!(WorldSpec::from_toml_str(&text).unwrap(), w, "{text}");
    }
    let mut w = WorldSpec::landmark(1).unwrap();
    w.boxes[0].angle_deg = 33.25;
    w.boxes[0].center = [2.123456789012345, 2.5];
    let back = WorldSpec::from_toml_str(&w.to_toml_string().unwrap()).unwrap();
    assert_eq!(back, w);
}

fn err(text: &str) -> String {
    WorldSpec::from_toml_str(text).unwrap_err().to_string()
}

const START: &str = "start = { min = [0.4, 0.4], max = [1.0, 1.0] }\n";

#[test]
fn validation_errors_name_the_field() {
    let e = err(&format!("room = [6.0, -5.0]\n{START}"));
    assert_eq!(e, "room[1] is -5; it must be in (0, 1000]");
    let e = err(&format!(
        "room = [6.0, 5.0]\n{START}[[boxes]]\ncenter = [3, 2]\nsize = [-0.6, 0.6]\n"
    ));
    assert_eq!(
        e,
        "boxes[0].size[0] is -0.6; it must be a finite number > 0"
    );
    let e = err(&format!(
        "room = [6.0, 5.0]\n{START}[[boxes]]\ncenter = [3, 2]\nsize = [1, 1]\n\
         [[boxes]]\ncenter = [5.8, 2]\nsize = [0.6, 0.6]\n"
    ));
    assert!(e.starts_with("boxes[1] is centre [5.8, 2.0]"), "{e}");
    assert!(
        e.ends_with("must be wholly inside the room [0, 6] x [0, 5]"),
        "{e}"
    );
    // A 45-degree square of side 1 reaches 0.707 from its centre.
    let e = err(&format!(
        "room = [6.0, 5.0]\n{START}[[boxes]]\ncenter = [0.6, 2]\nsize = [1, 1]\nangle_deg = 45\n"
    ));
    assert!(e.starts_with("boxes[0] is"), "{e}");
    let e = err("room = [6.0, 5.0]\nstart = { min = [0.4, 0.4], max = [7, 1] }\n");
    assert_eq!(
        e,
        "start.max[0] is 7; it must be in [start.min[0], room[0]] = [0.4, 6]"
    );
}

#[test]
fn unknown_and_missing_fields_are_named() {
    let e = err(&format!("room = [6.0, 5.0]\nrooms = 1\n{START}"));
    assert!(
        e.contains("line 2") && e.contains("unknown field `rooms`"),
        "{e}"
    );
    let e = err(&format!(
        "room = [6.0, 5.0]\n{START}[[boxes]]\ncenter = [3, 2]\nsize = [1, 1]\nangle = 4\n"
    ));
    assert!(
        e.contains("unknown field `angle`") && e.contains("line 6"),
        "{e}"
    );
    assert!(e.contains("boxes[0]"), "{e}");
    let e = err("room = [6.0, 5.0]\n");
    assert!(e.contains("missing field `start`"), "{e}");
    let e = err(&format!("room = \"big\"\n{START}"));
    assert!(e.contains("room") && e.contains("invalid type"), "{e}");
    assert!(!e.contains('\n'));
}

#[test]
fn every_pair_has_exactly_two_numbers() {
    // The TOML reader alone would read the first two numbers of a longer array and drop the rest.
    let good = "room = [6.0, 5.0]\n[start]\nmin = [0.4, 0.4]\nmax = [1.0, 1.0]\n\
                [[boxes]]\ncenter = [3, 2]\nsize = [1, 1]\n";
    assert!(WorldSpec::from_toml_str(good).is_ok());
    for (field, bad, line) in [
        ("room", "room = [6.0, 5.0, 4.0]", 1),
        ("room", "room = [6.0]", 1),
        ("start.min", "min = [0.4, 0.4, 9]", 3),
        ("start.max", "max = []", 4),
        ("boxes[0].center", "center = [3, 2, 7]", 6),
        ("boxes[0].size", "size = [1, 1, 1, 1]", 7),
    ] {
        let key = bad.split(" = ").next().unwrap();
        let text: String = good
            .lines()
            .map(|l| {
                if l.starts_with(&format!("{key} = ")) {
                    bad
                } else {
                    l
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        let e = err(&text);
        assert!(
            e.contains(&format!("{field}: invalid length"))
                && e.contains("an array of 2 numbers")
                && e.contains(&format!("line {line}")),
            "{bad}: {e}"
        );
    }
}

#[test]
fn jitter_stays_valid_and_is_deterministic() {
    let base = WorldSpec::landmark(2).unwrap();
    for t in 0..50 {
        let mut s = Stream::new(9, 0, Purpose::Trial, 0, t);
        let j = base.jittered(&mut s, 0.3, 0.2).unwrap();
        j.validate().unwrap();
        let mut s2 = Stream::new(9, 0, Purpose::Trial, 0, t);
        assert_eq!(base.jittered(&mut s2, 0.3, 0.2).unwrap(), j);
        for k in 0..2 {
            let f = j.room[k] / base.room[k];
            assert!((0.8..1.2).contains(&f));
        }
    }
    let mut s = Stream::new(9, 0, Purpose::Trial, 0, 0);
    assert_eq!(base.jittered(&mut s, 0.0, 0.0).unwrap(), base);
    let e = base.jittered(&mut s, -1.0, 0.1).unwrap_err().to_string();
    assert!(e.starts_with("box_shift_m is -1"), "{e}");
    let e = base.jittered(&mut s, 0.1, 0.5).unwrap_err().to_string();
    assert_eq!(e, "room_scale_frac is 0.5; it must be in [0, 0.5)");
}

#[test]
fn a_room_too_large_for_its_geometry_and_a_wild_angle_are_refused() {
    let e = err(&format!("room = [1e300, 5.0]\n{START}"));
    assert!(e.contains("room[0] is 1e300") && e.contains("1000"), "{e}");
    let e = err(&format!(
        "room = [6.0, 5.0]\n{START}[[boxes]]\ncenter = [3, 2]\nsize = [1, 1]\nangle_deg = 1e30\n"
    ));
    assert!(e.contains("boxes[0].angle_deg is 1e30"), "{e}");
    let ok = format!(
        "room = [1000.0, 5.0]\n{START}[[boxes]]\ncenter = [3, 2]\nsize = [1, 1]\nangle_deg = -360\n"
    );
    assert!(WorldSpec::from_toml_str(&ok).is_ok());
}
