//! cargo-fuzz target: see `checks/network.rs`.
#![no_main]

#[path = "../checks/network.rs"]
mod check;

libfuzzer_sys::fuzz_target!(|data: &[u8]| check::check(data));
