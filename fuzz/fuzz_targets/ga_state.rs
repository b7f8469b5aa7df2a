//! cargo-fuzz target: see `checks/ga_state.rs`.
#![no_main]

#[path = "../checks/ga_state.rs"]
mod check;

libfuzzer_sys::fuzz_target!(|data: &[u8]| check::check(data));
