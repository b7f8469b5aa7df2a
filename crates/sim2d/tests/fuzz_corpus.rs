//! The fuzz corpus of the world file reader, replayed on stable Rust: every file of
//! `fuzz/corpus/world/` (the seeds and what the fuzzer found) goes through the same check as
//! the cargo-fuzz target, which may refuse it with an error but must not panic. The long run is
//! `fuzz/run` (see fuzz/README.md).

#[path = "../../../fuzz/checks/corpus.rs"]
mod corpus;
#[path = "../../../fuzz/checks/world.rs"]
mod world;

#[test]
fn world_files_are_read_or_refused_without_a_panic() {
    corpus::replay("world", world::check, |data| {
        let text = std::str::from_utf8(data).map_err(|e| e.to_string())?;
        sim2d::WorldSpec::from_toml_str(text)
            .map(drop)
            .map_err(|e| e.to_string())
    });
}
