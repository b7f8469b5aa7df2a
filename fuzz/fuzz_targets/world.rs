//! cargo-fuzz target: see `checks/world.rs`.
#![no_main]

#[path = "../checks/world.rs"]
mod check;

libfuzzer_sys::fuzz_target!(|data: &[u8]| check::check(data));
