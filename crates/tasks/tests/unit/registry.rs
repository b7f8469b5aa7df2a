use ctrnn::Error;
use serde_json::json;
use tasks::registry::*;

#[test]
fn every_name_builds_with_defaults() {
    for name in names() {
        let task = build(name, &serde_json::Value::Null).unwrap();
        task.layout().validate().unwrap();
        build(name, &json!({})).unwrap();
    }
}

#[test]
fn sequence_params_are_read_and_checked() {
    let task = build("sequence", &json!({"size": 7, "targets": ["01", "10"]})).unwrap();
    assert_eq!(task.layout().size, 7);
    assert_eq!(task.layout().n_inputs, 2);
    let err = |p: serde_json::Value| build("sequence", &p).err().unwrap();
    let e = err(json!({"triggers": 10, "bogus": 1}));
    assert!(matches!(e, Error::Config(_)), "{e:?}");
    assert!(e.to_string().contains("bogus"), "{e}");
    let e = err(json!({"size": "five"})).to_string();
    assert!(e.contains("sequence"), "{e}");
    let e = err(json!({"targets": ["0", "2"]})).to_string();
    assert!(e.contains("targets[1]"), "{e}");
    let e = err(json!([1, 2])).to_string();
    assert!(e.contains("JSON object"), "{e}");
}

#[test]
fn unknown_name_lists_the_known_ones() {
    let e = build("x", &json!({})).err().unwrap();
    assert!(matches!(e, Error::Config(_)));
    assert_eq!(
        e.to_string(),
        "invalid config: unknown task \"x\"; known tasks: sequence, nav1d, landmark"
    );
}
