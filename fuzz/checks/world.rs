//! The fuzz check of the world file reader, `sim2d::WorldSpec::from_toml_str`. Shared by
//! `fuzz_targets/world.rs` (cargo-fuzz) and `crates/sim2d/tests/fuzz_corpus.rs` (the corpus
//! replayed by `cargo test`).

use sim2d::{World, WorldSpec};
use streams::{Purpose, Stream};

/// Reads `data` as a world file. Any input may be refused with an error; none may panic. A world
/// that is accepted must build, write back to itself, and answer ray casts and a start pose
/// (which may be refused when the start region has no room for the robot).
pub fn check(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(spec) = WorldSpec::from_toml_str(text) else {
        return;
    };
    let world = World::new(&spec).expect("an accepted world file builds its world");
    let toml = spec
        .to_toml_string()
        .expect("an accepted world writes TOML");
    let again =
        WorldSpec::from_toml_str(&toml).expect("an accepted world file writes a readable one");
    assert_eq!(again, spec, "a world changed on its way through TOML");
    let mut stream = Stream::new(0, 0, Purpose::Trial, 0, 0);
    let _ = world.random_pose(0.265, 0.05, &mut stream);
    let centre = [0.5 * spec.room[0], 0.5 * spec.room[1]];
    for k in 0..8 {
        let a = f64::from(k) * std::f64::consts::FRAC_PI_4;
        if let Some(hit) = world.cast_ray(centre, [a.cos(), a.sin()], 10.0) {
            assert!(
                hit.distance >= 0.0 && hit.distance <= 10.0,
                "a ray hit at {}",
                hit.distance
            );
        }
    }
}
