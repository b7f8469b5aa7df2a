//! The fuzz corpus of ctrnn's readers, replayed on stable Rust: every file of
//! `fuzz/corpus/network/` and `fuzz/corpus/ga_state/` (the seeds and what the fuzzers found)
//! goes through the same check as its cargo-fuzz target, which may refuse it with an error but
//! must not panic. The long run is `fuzz/run` (see fuzz/README.md).

#[path = "../../../fuzz/checks/corpus.rs"]
mod corpus;
#[path = "../../../fuzz/checks/ga_state.rs"]
mod ga_state;
#[path = "../../../fuzz/checks/network.rs"]
mod network;

#[test]
fn network_files_are_read_or_refused_without_a_panic() {
    corpus::replay("network", network::check, |data| {
        ctrnn::io::from_bytes(data)
            .map(drop)
            .map_err(|e| e.to_string())
    });
}

#[test]
fn ga_states_are_read_or_refused_without_a_panic() {
    corpus::replay("ga_state", ga_state::check, |data| {
        let text = std::str::from_utf8(data).map_err(|e| e.to_string())?;
        ctrnn::Evolution::from_json(text)
            .map(drop)
            .map_err(|e| e.to_string())
    });
}

/// The seed GA state, as JSON to edit.
fn seed_state() -> serde_json::Value {
    let (_, data) = corpus::files("ga_state")
        .into_iter()
        .find(|(p, _)| p.ends_with("seed-ga-state.json"))
        .expect("fuzz/corpus/ga_state/seed-ga-state.json");
    serde_json::from_slice(&data).unwrap()
}

/// The error `Evolution::from_json` gives for the seed state edited by `edit`.
fn refused(edit: impl FnOnce(&mut serde_json::Value)) -> String {
    let mut state = seed_state();
    edit(&mut state);
    match ctrnn::Evolution::from_json(&state.to_string()) {
        Ok(_) => panic!("the edited state was accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_ga_state_is_refused_unless_it_can_continue() {
    // Found by the ga_state target: a champion of 13 genes in a layout of 12 was read, and
    // failed only when decoded.
    let e = refused(|s| {
        s["champion"]["genes"]
            .as_array_mut()
            .unwrap()
            .push(1.0.into())
    });
    assert!(
        e.contains("checkpoint champion: genome has 13 genes"),
        "{e}"
    );
    let e = refused(|s| s["population"][0] = (-1.0).into());
    assert!(
        e.contains("checkpoint population[0]: gene 0 (neuron 0, tau[0]) is -1"),
        "{e}"
    );
    let e = refused(|s| s["champion"]["generation"] = 3.into());
    assert!(
        e.contains("champion was scored in generation 3; the state is at generation 3"),
        "{e}"
    );
    let e = refused(|s| s["champion"]["validation"]["rate"] = 1.5.into());
    assert!(e.contains("validation rate 1.5 and score"), "{e}");
    let e = refused(|s| s["generation"] = u64::MAX.into());
    assert!(e.contains("no generation can follow it"), "{e}");
}

#[test]
fn a_network_file_that_is_not_utf8_is_a_format_error_naming_it() {
    // Found by the Python network reader: Network.load raised OSError ("stream did not contain
    // valid UTF-8"), which the run folder's readers did not take for a damaged best.json.
    let path = std::env::temp_dir().join(format!("dnnevo-fuzz-corpus-{}.json", std::process::id()));
    std::fs::write(&path, b"{\"format\": \"dnnevo-net\xffwork\"}").unwrap();
    let e = ctrnn::io::load(&path).unwrap_err();
    std::fs::remove_file(&path).unwrap();
    assert!(matches!(e, ctrnn::Error::Format(_)), "{e:?}");
    assert!(
        e.to_string()
            .ends_with(&format!("{}: not UTF-8 text (byte 22)", path.display())),
        "{e}"
    );
}
