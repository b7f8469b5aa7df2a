use ctrnn::GaConfig;
use tasks::{RunConfig, TIME_STEP};

fn error(json: &str) -> String {
    RunConfig::from_json(json).err().unwrap().to_string()
}

#[test]
fn defaults_are_valid_and_match_the_ga_and_the_tasks() {
    let config = RunConfig::from_json("{}").unwrap();
    assert_eq!(config, RunConfig::default());
    assert_eq!(config.ga(), GaConfig::default());
    assert_eq!(config.integrator, TIME_STEP);
    let round = serde_json::to_string(&config).unwrap();
    assert_eq!(RunConfig::from_json(&round).unwrap(), config);
}

#[test]
fn every_bad_value_names_its_field() {
    for (json, fragment) in [
        (r#"{"population": 1}"#, "population is 1"),
        (
            r#"{"crossover_rate": 1.5}"#,
            "crossover_rate is 1.5; it must be in [0, 1]",
        ),
        (r#"{"mutation_rate": -0.1}"#, "mutation_rate is -0.1"),
        (
            r#"{"mutation_scale": 0}"#,
            "mutation_scale is 0; it must be in (0, 1]",
        ),
        (r#"{"elitism": 100}"#, "elitism is 100"),
        (r#"{"generations": 0}"#, "generations is 0"),
        (r#"{"size": 0}"#, "size is 0"),
        (r#"{"task": ""}"#, "task is empty"),
        (
            r#"{"selection": "tournament"}"#,
            "selection: unknown variant `tournament`",
        ),
        (
            r#"{"mutation": "gauss"}"#,
            "mutation: unknown variant `gauss`",
        ),
        (r#"{"fill": "zeros"}"#, "fill: unknown variant `zeros`"),
        (r#"{"integrator": {"dt": 0}}"#, "missing field `method`"),
        (
            r#"{"integrator": {"method": "euler", "dt": 0, "substeps": 1}}"#,
            "integrator.dt is 0",
        ),
        (
            r#"{"integrator": {"method": "rk2", "dt": 0.1, "substeps": 1}}"#,
            "integrator.method: unknown variant `rk2`",
        ),
        (r#"{"populaton": 3}"#, "unknown field `populaton`"),
        (
            r#"{"population": -1}"#,
            "population: invalid value: integer `-1`",
        ),
        (r#"{"task_params": {"size": 3}}"#, "task_params.size is set"),
        (
            r#"{"task_params": {"precision": "f32"}}"#,
            "task_params.precision is set",
        ),
        (
            r#"{"precision": "f16"}"#,
            "precision: unknown variant `f16`, expected `f64` or `f32`",
        ),
        ("[1]", "the parameters must be a JSON object"),
        ("{", "not valid JSON"),
    ] {
        let e = error(json);
        assert!(e.contains(fragment), "{json}: {e}");
    }
    let tau = r#"{"ranges": {"tau": [0, 1], "theta": [-1, 1], "weights": [-1, 1],
                  "sensor_weights": [-1, 1]}}"#;
    assert!(
        error(tau).contains("ranges.tau is (0, 1)"),
        "{}",
        error(tau)
    );
}

#[test]
fn the_task_gets_the_runs_size_integrator_and_precision() {
    let json = r#"{"size": 7, "task_params": {"targets": ["0", "1"]}}"#;
    let config = RunConfig::from_json(json).unwrap();
    assert_eq!(config.build_task().unwrap().layout().size, 7);
    let params = config.task_params();
    assert_eq!(params["integrator"]["substeps"], 10);
    assert_eq!(params["targets"][1], "1");
    assert_eq!(params["precision"], "f64");
    let single = RunConfig::from_json(r#"{"precision": "f32"}"#).unwrap();
    assert_eq!(single.task_params()["precision"], "f32");
    let own = RunConfig {
        task: "python:m.f".into(),
        ..RunConfig::default()
    };
    assert!(own.validate().is_ok());
    let e = own.build_task().err().unwrap().to_string();
    assert!(e.contains("unknown task \"python:m.f\""), "{e}");
}

#[test]
fn the_step_check_validates_again_with_the_task_built_ten_times_finer() {
    for (task, size, params) in [
        ("sequence", 5, r#"{"targets": ["0", "1"]}"#),
        ("nav1d", 4, "{}"),
    ] {
        let json = format!(
            r#"{{"task": "{task}", "size": {size}, "champion_step_check": true, "task_params": {params}}}"#
        );
        let config = RunConfig::from_json(&json).unwrap();
        let plain = RunConfig {
            champion_step_check: false,
            ..config.clone()
        };
        let finer = RunConfig {
            integrator: ctrnn::Integrator {
                dt: 0.01,
                substeps: 100,
                ..TIME_STEP
            },
            ..plain.clone()
        };
        let (checked, plain, finer) = (
            config.build_task().unwrap(),
            plain.build_task().unwrap(),
            finer.build_task().unwrap(),
        );
        let nets = tasks::testing::random_networks(checked.layout(), 3, 7);
        assert_eq!(
            checked.evaluate(&nets, 2, 5, None).unwrap(),
            plain.evaluate(&nets, 2, 5, None).unwrap()
        );
        assert_eq!(
            checked.validate(&nets, 5, None).unwrap(),
            plain.validate(&nets, 5, None).unwrap()
        );
        let at_finer = checked.validate_finer(&nets, 5, None).unwrap();
        assert_eq!(at_finer, finer.validate(&nets, 5, None).unwrap(), "{task}");
        assert!(at_finer.is_some() && plain.validate_finer(&nets, 5, None).unwrap().is_none());
        if task == "sequence" {
            // nav1d's validation counts goals reached, which these random networks reach or miss
            // at both steps alike; the sequence task's mean trial score moves with the step.
            assert_ne!(at_finer, plain.validate(&nets, 5, None).unwrap());
        }
    }
}

#[test]
fn the_step_check_needs_a_step_that_can_be_made_finer_and_candidates() {
    let huge = format!(
        r#"{{"champion_step_check": true, "integrator": {{"method": "euler", "dt": 0.1, "substeps": {}}}}}"#,
        usize::MAX / 2
    );
    assert!(
        error(&huge).contains("champion_step_check: integrator.substeps"),
        "{}",
        error(&huge)
    );
    let e = error(r#"{"champion_step_check": true, "validation_candidates": 0}"#);
    assert!(e.contains("needs validation_candidates >= 1"), "{e}");
}

#[test]
fn a_task_s_error_names_its_parameter_as_the_config_does() {
    let task_error = |json: &str| {
        let config = RunConfig::from_json(json).unwrap();
        config.build_task().err().unwrap().to_string()
    };
    for (json, message) in [
        (
            r#"{"task": "sequence", "task_params": {"triggers": 0}}"#,
            "task_params.triggers is 0; it must be >= 1",
        ),
        (
            r#"{"task": "sequence", "task_params": {"trials_per_target": -1}}"#,
            "sequence: task_params.trials_per_target: invalid value: integer `-1`, expected an \
             integer >= 0",
        ),
        (
            r#"{"task": "sequence", "task_params": {"perf_base": true}}"#,
            "sequence: task_params.perf_base: ",
        ),
        (
            r#"{"task": "landmark", "task_params": {"training": {"cone_deg": -1}}}"#,
            "task_params.training.cone_deg is -1",
        ),
        (
            r#"{"task": "nav1d", "task_params": {"max_stepz": 3}}"#,
            "nav1d: task_params.max_stepz: unknown field `max_stepz`",
        ),
        (
            r#"{"task": "landmark", "task_params": {"sim": {"sonars": [{"rays": 4294967296}]}}}"#,
            "landmark: task_params.sim.sonars[0].rays: invalid value: integer `4294967296`, \
             expected an integer in [0, 4294967295]",
        ),
    ] {
        let e = task_error(json);
        let e = e.strip_prefix("invalid config: ").unwrap_or(&e);
        assert!(e.starts_with(message), "{json}: {e}");
        assert!(!e.contains("usize"), "{json}: {e}");
    }
}
