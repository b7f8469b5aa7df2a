//! The fuzz corpus of the run config reader, replayed on stable Rust: every file of
//! `fuzz/corpus/run_config/` (the seeds and what the fuzzer found) goes through the same check
//! as the cargo-fuzz target, which may refuse it with an error but must not panic. The long run
//! is `fuzz/run` (see fuzz/README.md).

#[path = "../../../fuzz/checks/corpus.rs"]
mod corpus;
#[path = "../../../fuzz/checks/run_config.rs"]
mod run_config;

#[test]
fn run_configs_are_read_or_refused_without_a_panic() {
    corpus::replay("run_config", run_config::check, |data| {
        let text = std::str::from_utf8(data).map_err(|e| e.to_string())?;
        tasks::RunConfig::from_json(text)
            .map(drop)
            .map_err(|e| e.to_string())
    });
}
