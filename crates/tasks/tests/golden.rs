//! Stored bits of a population run and of a short evolution run. They must not change with the
//! CPU, the SIMD kernel, the number of threads or the build: every kernel this CPU has is checked
//! here, and `.ci/cross-cpu` runs the population run and the small evolution run on emulated CPUs
//! with and without AVX2 (the short evolution run took 7 minutes there, the small one a fraction).
//!
//! A deliberate change of the numbers (a new sigmoid, say) updates the constants below, and
//! CHANGELOG.md says so.

use ctrnn::genome::{self, Layout};
use ctrnn::simd::{self, Kernel};
use ctrnn::{Evolution, Fill, Inputs, Integrator, Method, Network, Population, Precision};
use tasks::RunConfig;

/// FNV-1a over the bits of `values`: any change of any bit changes it.
fn fingerprint(values: impl IntoIterator<Item = f64>) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    for v in values {
        for byte in v.to_bits().to_le_bytes() {
            hash = (hash ^ byte as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }
    hash
}

/// `f` on every kernel this CPU can run: the same fingerprint on each, and the stored one.
fn same_on_every_kernel(what: &str, stored: u64, f: impl Fn() -> u64) {
    let before = simd::kernel();
    let got: Vec<(Kernel, u64)> = simd::supported()
        .into_iter()
        .map(|k| {
            simd::set_kernel(k).unwrap();
            (k, f())
        })
        .collect();
    simd::set_kernel(before).unwrap();
    for (kernel, hash) in got {
        assert_eq!(
            hash, stored,
            "{what} on the {kernel} kernel: fingerprint {hash:#018x}, stored {stored:#018x}"
        );
    }
}

fn random_networks(layout: Layout, count: usize) -> Vec<Network> {
    tasks::testing::random_networks(layout, count, 17)
}

#[test]
fn a_population_run_keeps_its_stored_bits() {
    same_on_every_kernel("a population run", 0x26b4_c19b_421f_2efe, || {
        population_fingerprint(Precision::F64)
    });
}

/// The same run in single precision: its own fingerprint, the same on every kernel. (The
/// states come back widened to f64, exactly, so the fingerprint is of the f32 bits.)
#[test]
fn a_population_run_in_f32_keeps_its_stored_bits() {
    same_on_every_kernel("a population run in f32", 0x5913_88b2_8198_2425, || {
        population_fingerprint(Precision::F32)
    });
}

/// 37 networks (two full blocks of 16 and a ragged one, N = 7, not a multiple of 4) run for 120
/// steps with Euler and with RK4 in `precision`: every state of both runs.
fn population_fingerprint(precision: Precision) -> u64 {
    let nets = random_networks(
        Layout {
            size: 7,
            n_inputs: 2,
        },
        37,
    );
    let steps = 120;
    let inputs: Vec<f64> = (0..steps * 2)
        .map(|k| ((k * 7) % 11) as f64 / 5.0 - 1.0)
        .collect();
    let mut all = Vec::new();
    for (method, substeps) in [(Method::Euler, 1), (Method::Rk4, 3)] {
        let integ = Integrator {
            method,
            dt: 0.1,
            substeps,
        };
        let mut pop = Population::with_precision(&nets, precision).unwrap();
        let states = pop
            .run(Inputs::Shared(&inputs), steps, &integ, true, None)
            .unwrap();
        if precision == Precision::F32 {
            assert!(states.iter().all(|&v| v as f32 as f64 == v));
        }
        all.extend(states);
    }
    fingerprint(all)
}

#[test]
fn a_short_evolution_run_keeps_its_stored_bits() {
    let config = RunConfig {
        population: 48,
        generations: 3,
        ..RunConfig::default()
    };
    same_on_every_kernel(
        "a sequence-task evolution run",
        0x1d97_bd04_9c91_adbe,
        || evolution_fingerprint(&config),
    );
}

/// The short run's task with a fraction of its work (fewer, shorter trials, a smaller population),
/// so that an emulated CPU runs it in seconds; the same code paths, validation included.
#[test]
fn a_small_evolution_run_keeps_its_stored_bits() {
    let task_params = serde_json::json!({
        "triggers": 4,
        "trials_per_target": 1,
        "validation_trials": 2,
    });
    let config = RunConfig {
        population: 16,
        generations: 2,
        validation_candidates: 2,
        task_params: task_params.as_object().unwrap().clone(),
        ..RunConfig::default()
    };
    same_on_every_kernel(
        "a small sequence-task evolution run",
        0xb485_7858_b612_1855,
        || evolution_fingerprint(&config),
    );
}

/// The fitnesses, best and mean of every generation of `config`'s run from seed 5, then the
/// last population's genomes.
fn evolution_fingerprint(config: &RunConfig) -> u64 {
    let task = config.build_task().unwrap();
    let mut evo = Evolution::new(task.layout(), config.ga(), 5, &[], Fill::default()).unwrap();
    let mut all = Vec::new();
    for _ in 0..config.generations {
        let (stats, fitness) = evo.step(task.as_ref(), None).unwrap();
        all.extend(fitness);
        all.extend([stats.best, stats.mean]);
    }
    for net in evo.networks().unwrap() {
        all.extend(genome::encode(&net));
    }
    fingerprint(all)
}

/// Small evolution runs of each built-in task in single precision (`precision = "f32"`): their
/// own fingerprints, the same on every kernel.
#[test]
fn a_small_evolution_run_in_f32_keeps_its_stored_bits_for_every_task() {
    for (task, stored, params) in small_f32_runs() {
        let config = small_run(task, params, Precision::F32);
        same_on_every_kernel(
            &format!("a small {task} evolution run in f32"),
            stored,
            || evolution_fingerprint(&config),
        );
    }
}

/// The same small runs in f64 are other runs. (Apart from the kernels' test, which emulated CPUs
/// run, where these runs cost as much again.)
#[test]
fn small_f32_runs_are_not_the_f64_runs() {
    for (task, stored, params) in small_f32_runs() {
        let config = small_run(task, params, Precision::F64);
        let got = evolution_fingerprint(&config);
        assert_ne!(got, stored, "{task}: f64 gave the f32 run's bits");
    }
}

/// Each task's small f32 run: (task, its stored fingerprint, its task parameters).
fn small_f32_runs() -> [(&'static str, u64, serde_json::Value); 3] {
    [
        (
            "sequence",
            0xc827_0a93_fddd_5f9a,
            serde_json::json!({"triggers": 4, "trials_per_target": 1, "validation_trials": 2}),
        ),
        (
            "nav1d",
            0x00ed_7224_f35d_51e5,
            serde_json::json!({"objective": "classify", "max_steps": 60, "validation_chains": 2}),
        ),
        (
            "landmark",
            0x48b4_e6cc_3f85_5c52,
            serde_json::json!({"trials_per_landmark": 2, "validation_trials": 2, "trial_seconds": 8.0}),
        ),
    ]
}

fn small_run(task: &str, params: serde_json::Value, precision: Precision) -> RunConfig {
    let defaults = tasks::build(task, &serde_json::Value::Null)
        .unwrap()
        .layout();
    RunConfig {
        task: task.into(),
        population: 16,
        generations: 2,
        validation_candidates: 2,
        size: defaults.size,
        n_inputs: defaults.n_inputs,
        precision,
        task_params: params.as_object().unwrap().clone(),
        ..RunConfig::default()
    }
}

/// A small landmark run with `landmark-robust`'s varied training (every variation of its preset
/// on, validated on varied trials too): later variations draw from streams of their own, so this
/// run, and the preset's reference results, keep their bits.
#[test]
fn a_small_landmark_run_with_varied_training_keeps_its_stored_bits() {
    let task_params = serde_json::json!({
        "trials_per_landmark": 3, "validation_trials": 2, "trial_seconds": 8.0,
        "training": {
            "ideal_trials_per_landmark": 1, "landmark_shift": 0.15, "landmark_turn_deg": 5.0,
            "landmark_scale": 0.08, "follower_speed": 0.08, "follower_distance": 0.05,
            "cone_deg": 8.0, "trial_seconds": 3.0, "input_gain": 0.15, "input_offset": 0.025,
            "input_noise_sd": 0.015,
        },
    });
    let mut config = small_run("landmark", task_params, Precision::F64);
    config.generations = 3;
    same_on_every_kernel(
        "a small landmark run with varied training",
        0x8705_a4a0_cea0_66fd,
        || evolution_fingerprint(&config),
    );
}
