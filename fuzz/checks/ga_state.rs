//! The fuzz check of the GA state reader, `ctrnn::Evolution::from_json` (the `state.evolution`
//! text of `checkpoint.json`, which `dnnevo resume` continues). Shared by
//! `fuzz_targets/ga_state.rs` (cargo-fuzz) and `crates/ctrnn/tests/fuzz_corpus.rs` (the corpus
//! replayed by `cargo test`).

use ctrnn::Evolution;

/// Reads `data` as a GA state. Any input may be refused with an error; none may panic. A state
/// that is accepted must write back to itself, decode its population and champion, and breed
/// its next generation.
pub fn check(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(evo) = Evolution::from_json(text) else {
        return;
    };
    let again =
        Evolution::from_json(&evo.to_json()).expect("an accepted GA state writes a readable one");
    assert_eq!(again, evo, "a GA state changed on its way through to_json");
    evo.networks()
        .expect("an accepted GA state decodes its population");
    evo.champion_network()
        .expect("an accepted GA state decodes its champion");
    let mut next = evo.clone();
    let fitness: Vec<f64> = (0..evo.config.population).map(|i| i as f64).collect();
    next.tell(&fitness)
        .expect("an accepted GA state breeds its next generation");
}
