//! The committed corpus of a fuzz target, `fuzz/corpus/NAME/`, replayed by the crates' own
//! tests (`crates/*/tests/fuzz_corpus.rs`): the reduced pass CI runs on stable Rust, where the
//! long run (`fuzz/run`) needs nightly.

use std::path::PathBuf;

/// Every file of `fuzz/corpus/NAME/` with its bytes, sorted by name; there is at least one.
pub fn files(name: &str) -> Vec<(PathBuf, Vec<u8>)> {
    // Each crate's manifest lies at crates/CRATE/, two folders below the repository's root.
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus")
        .join(name);
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|entry| entry.unwrap().path())
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "{} holds no seed", dir.display());
    paths
        .into_iter()
        .map(|p| {
            let data = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p, data)
        })
        .collect()
}

/// Runs `check` on every file of the corpus `name`, and `accept` on each seed (a file named
/// `seed-*`, which dnnevo wrote: a reader that refused one would test nothing beyond it). A
/// panic names the file that caused it.
pub fn replay(name: &str, check: fn(&[u8]), accept: fn(&[u8]) -> Result<(), String>) {
    for (path, data) in files(name) {
        if std::panic::catch_unwind(|| check(&data)).is_err() {
            panic!("{} made the {name} check panic", path.display());
        }
        let seed = path
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| n.starts_with("seed-"));
        if seed {
            if let Err(e) = accept(&data) {
                panic!("{}: the seed is refused: {e}", path.display());
            }
        }
    }
}
