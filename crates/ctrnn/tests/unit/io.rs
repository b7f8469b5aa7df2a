use std::fs;

use serde_json::Map;

use ctrnn::integrate::Method;
use ctrnn::io::*;
use ctrnn::{Error, Integrator, Network};

fn sample() -> NetworkFile {
    let net = Network::new(
        vec![0.1 + 0.2, 7.0 / 3.0],
        vec![-1e-300, 16.0],
        vec![1.0 / 3.0, -2.5, 5e-324, std::f64::consts::PI],
        vec![0.1, 0.7],
        Some(vec![1.0 / 7.0, -0.0]),
    )
    .unwrap();
    let mut meta = Map::new();
    meta.insert("task".into(), "sequence-1bit".into());
    meta.insert("seed".into(), 3.into());
    NetworkFile {
        network: net,
        integrator: Some(Integrator {
            method: Method::Rk4,
            dt: 0.05,
            substeps: 10,
        }),
        meta,
    }
}

#[test]
fn round_trip_is_exact() {
    let f = sample();
    let back = from_json(&to_json(&f)).unwrap();
    assert_eq!(back, f);
    for (a, b) in back.network.weights().iter().zip(f.network.weights()) {
        assert_eq!(a.to_bits(), b.to_bits());
    }
    assert_eq!(to_json(&back), to_json(&f));
}

#[test]
fn file_round_trip_and_atomic_write() {
    let dir = std::env::temp_dir().join(format!("ctrnn-io-{}", std::process::id()));
    fs::create_dir_all(&dir).unwrap();
    let path = dir.join("net.json");
    save(&path, &sample()).unwrap();
    assert_eq!(load(&path).unwrap(), sample());
    let leftovers = fs::read_dir(&dir).unwrap().count();
    assert_eq!(leftovers, 1, "no temporary file is left behind");
    fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn atomic_write_never_follows_a_planted_symlink() {
    let dir = std::env::temp_dir().join(format!("ctrnn-io-link-{}", std::process::id()));
    fs::create_dir_all(&dir).unwrap();
    let target = dir.join("important");
    fs::write(&target, b"keep").unwrap();
    let path = dir.join("net.json");
    // Every name the old scheme used, and the final name itself, point at the target.
    std::os::unix::fs::symlink(
        &target,
        dir.join(format!(".net.json.tmp{}", std::process::id())),
    )
    .unwrap();
    std::os::unix::fs::symlink(&target, &path).unwrap();
    save(&path, &sample()).unwrap();
    assert_eq!(fs::read(&target).unwrap(), b"keep");
    assert!(!fs::symlink_metadata(&path)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(load(&path).unwrap(), sample());
    fs::remove_dir_all(&dir).unwrap();
}

fn err(text: &str) -> String {
    match from_json(text) {
        Err(Error::Format(m)) => m,
        other => panic!("expected a format error, got {other:?}"),
    }
}

#[test]
fn bad_documents_name_the_problem() {
    let good = to_json(&sample());
    let edit = |from: &str, to: &str| good.replacen(from, to, 1);
    assert!(err(&edit("dnnevo-network", "other")).contains("expected \"dnnevo-network\""));
    assert!(err(&edit("\"version\": 1", "\"version\": 2")).contains("version is 2"));
    assert!(err(&good[..good.len() / 2]).contains("not valid JSON"));
    assert!(err(&format!("\u{feff}{good}")).contains("starts with a byte-order mark"));
    for beer in ["biases", "gains"] {
        let e = err(&good.replacen("\"theta\"", &format!("\"{beer}\": [0], \"theta\""), 1));
        assert!(
            e.contains(&format!(
                "unknown field `{beer}`: this format has thresholds"
            )),
            "{e}"
        );
    }
    assert!(err("[1, 2]").contains("not a JSON object"));
    let no_tau = good.replacen("\"tau\"", "\"tua\"", 1);
    let e = err(&no_tau);
    assert!(e.contains("tua") || e.contains("tau"), "{e}");
    let e = err(&edit("\"theta\": [", "\"theta\": [\"x\", "));
    assert!(e.contains("theta[0]"), "{e}");
    let e = err(&edit("\"theta\": [", "\"theta\": [1e999, "));
    assert!(
        e.contains("theta") || e.contains("number out of range"),
        "{e}"
    );
    let e = err(&edit("\"tau\": [", "\"tau\": [-1.0, "));
    assert!(e.contains("weights has 2 rows; expected N = 3"), "{e}");
    let e = err(&edit("0.30000000000000004", "-0.5"));
    assert!(e.contains("tau[0]") && e.contains("> 0"), "{e}");
    let e = err(&edit("\"dt\": 0.05", "\"dt\": -1.0"));
    assert!(e.contains("integrator") && e.contains("dt"), "{e}");
    let minimal = r#"{"format": "dnnevo-network", "version": 1, "tau": [1],
        "theta": [0], "weights": [[0]], "sensor_weights": [[]]}"#;
    let f = from_json(minimal).unwrap();
    assert_eq!((f.network.size(), f.network.n_inputs()), (1, 0));
    assert_eq!(f.network.state(), &[0.0]);
    let missing = r#"{"format": "dnnevo-network", "version": 1, "tau": [1],
        "weights": [[0]], "sensor_weights": [[]]}"#;
    assert!(err(missing).contains("missing field `theta`"));
    let ragged = minimal.replace("[[0]]", "[[0, 1]]");
    assert!(err(&ragged).contains("weights[0] has 2 values; expected 1"));
}

#[test]
fn nan_and_infinity_are_named_and_meta_s_conventional_keys_are_checked() {
    let minimal = r#"{"format": "dnnevo-network", "version": 1, "tau": [1],
        "theta": [0], "weights": [[0]], "sensor_weights": [[]]}"#;
    for word in ["NaN", "Infinity", "-Infinity"] {
        let e = err(&minimal.replace(r#""theta": [0]"#, &format!(r#""theta": [{word}]"#)));
        assert!(
            e.starts_with(&format!("not valid JSON: {word} at line 2 column")),
            "{e}"
        );
        assert!(e.ends_with("JSON has no NaN or Infinity"), "{e}");
    }
    let with_meta = |meta: &str| minimal.replace(r#""tau""#, &format!(r#""meta": {meta}, "tau""#));
    for (meta, message) in [
        (
            r#"{"seed": -1}"#,
            "meta.seed is -1; expected an integer >= 0",
        ),
        (
            r#"{"seed": 1.5}"#,
            "meta.seed is 1.5; expected an integer >= 0",
        ),
        (
            r#"{"generation": "3"}"#,
            "meta.generation is \"3\"; expected an integer >= 0",
        ),
        (r#"{"task": 3}"#, "meta.task is 3; expected a string"),
        (
            r#"{"fitness": "high"}"#,
            "meta.fitness is \"high\"; expected a number",
        ),
        (
            r#"{"input_labels": [1, 2]}"#,
            "meta.input_labels is [1,2]; expected a list of strings",
        ),
        (
            r#"{"output_labels": "x"}"#,
            "meta.output_labels is \"x\"; expected a list of strings",
        ),
        (
            r#"{"precision": "f16"}"#,
            "meta.precision is \"f16\"; expected \"f64\" or \"f32\"",
        ),
    ] {
        assert_eq!(err(&with_meta(meta)), message);
    }
    let twice = minimal.replace(r#""tau": [1]"#, r#""tau": [1], "tau": [2]"#);
    assert!(
        err(&twice).starts_with("not valid JSON: the key \"tau\" appears twice in one object"),
        "{}",
        err(&twice)
    );
    let nested = with_meta(r#"{"a": {"b": 1, "b": 2}}"#);
    assert!(err(&nested).contains("the key \"b\" appears twice"));
    let fine = r#"{"seed": 3, "generation": 0, "fitness": -0.5, "task": "x", "input_labels": ["a"],
        "precision": "f32", "anything": [1, {"b": null}]}"#;
    assert_eq!(from_json(&with_meta(fine)).unwrap().meta["seed"], 3);
    assert!(from_json(&with_meta(r#"{"seed": 3.0}"#)).is_ok()); // the schema's integer
    assert!(err(&with_meta(r#"{"seed": -2.0}"#)).starts_with("meta.seed is -2.0"));
    // What load would refuse, save does not write.
    let mut file = from_json(minimal).unwrap();
    file.meta.insert("seed".into(), (-1).into());
    let path = std::env::temp_dir().join(format!("dnnevo-meta-{}.json", std::process::id()));
    match save(&path, &file) {
        Err(Error::InvalidArgument(m)) => {
            assert_eq!(m, "meta.seed is -1; expected an integer >= 0")
        }
        other => panic!("{other:?}"),
    }
    assert!(!path.exists());
    // The whole class: any integrator block load refuses (NaN dt is written as null).
    for (dt, substeps) in [(f64::NAN, 1), (0.0, 1), (0.1, 0)] {
        let mut file = from_json(minimal).unwrap();
        file.integrator = Some(Integrator {
            method: Method::Euler,
            dt,
            substeps,
        });
        match save(&path, &file) {
            Err(Error::InvalidArgument(m)) => assert!(
                m.starts_with("not written, since it would not load: integrator"),
                "{m}"
            ),
            other => panic!("{dt} {substeps}: {other:?}"),
        }
        assert!(!path.exists());
    }
}
