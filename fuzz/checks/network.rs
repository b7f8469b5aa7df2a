//! The fuzz check of the network file reader, `ctrnn::io::from_bytes` (what `Network.load` and
//! every `best.json` go through). Shared by `fuzz_targets/network.rs` (cargo-fuzz) and
//! `crates/ctrnn/tests/fuzz_corpus.rs` (the corpus replayed by `cargo test`).

/// Reads `data` as a network file. Any input may be refused with an error; none may panic, and a
/// file that is accepted must write back to a file that reads as the same network.
pub fn check(data: &[u8]) {
    let Ok(file) = ctrnn::io::from_bytes(data) else {
        return;
    };
    let text = ctrnn::io::to_json(&file);
    let again =
        ctrnn::io::from_json(&text).expect("an accepted network file writes a readable one");
    assert_eq!(
        again, file,
        "a network file changed on its way through to_json"
    );
}
