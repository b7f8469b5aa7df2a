//! cargo-fuzz target: see `checks/run_config.rs`.
#![no_main]

#[path = "../checks/run_config.rs"]
mod check;

libfuzzer_sys::fuzz_target!(|data: &[u8]| check::check(data));
