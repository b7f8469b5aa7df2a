//! The fuzz check of the run config reader, `tasks::RunConfig::from_json` (every config the
//! Python side reads, from `config.toml`, a checkpoint or a preset, crosses the binding as this
//! JSON). Shared by `fuzz_targets/run_config.rs` (cargo-fuzz) and
//! `crates/tasks/tests/fuzz_corpus.rs` (the corpus replayed by `cargo test`).

use tasks::RunConfig;

/// Reads `data` as a run config. Any input may be refused with an error; none may panic. A
/// config that is accepted must write back to itself, and building its task may fail only with
/// an error.
pub fn check(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(config) = RunConfig::from_json(text) else {
        return;
    };
    let json = serde_json::to_string(&config).expect("an accepted config serialises");
    let again = RunConfig::from_json(&json).expect("an accepted config writes a readable one");
    assert_eq!(
        again, config,
        "a run config changed on its way through JSON"
    );
    let _ = config.build_task();
}
