//! Small pieces every task shares: reading a config from JSON parameters, noticing Ctrl-C,
//! reporting a lane whose state stopped being finite, and remembering a value computed once.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use ctrnn::{Elem, Error, Integrator, Lanes, Method, Result};
use serde::de::DeserializeOwned;

/// Reads a task config from a JSON object of its fields (`null` means all defaults). Unknown or
/// mistyped fields are [`Error::Config`] errors prefixed with the task's `name`.
pub(crate) fn config_from_params<C: DeserializeOwned + Default>(
    name: &str,
    params: &serde_json::Value,
) -> Result<C> {
    match params {
        serde_json::Value::Null => Ok(C::default()),
        serde_json::Value::Object(_) => serde_path_to_error::deserialize(params).map_err(|e| {
            // Name the field (`training.cone_deg`) unless the error is about the whole object.
            let path = e.path().to_string();
            let inner = plain_types(&e.into_inner().to_string());
            if path == "." {
                Error::Config(format!("{name}: {inner}"))
            } else {
                Error::Config(format!("{name}: {path}: {inner}"))
            }
        }),
        other => Err(Error::Config(format!(
            "{name}: the parameters must be a JSON object of config fields; got {other}"
        ))),
    }
}

/// serde's message with Rust's type names (`expected usize`) in the words of the config, each
/// with its range (a name is replaced only where it ends: `expected u8` is not `expected u80`).
fn plain_types(message: &str) -> String {
    const WORDS: [(&str, &str); 10] = [
        ("expected usize", "expected an integer >= 0"),
        ("expected u64", "expected an integer >= 0"),
        ("expected u32", "expected an integer in [0, 4294967295]"),
        ("expected u16", "expected an integer in [0, 65535]"),
        ("expected u8", "expected an integer in [0, 255]"),
        ("expected i64", "expected an integer"),
        (
            "expected i32",
            "expected an integer in [-2147483648, 2147483647]",
        ),
        ("expected f64", "expected a number"),
        ("expected f32", "expected a number"),
        ("expected a boolean", "expected true or false"),
    ];
    let mut out = message.to_string();
    for (rust, plain) in WORDS {
        let mut from = 0;
        while let Some(at) = out[from..].find(rust).map(|i| i + from) {
            let end = at + rust.len();
            if out[end..].starts_with(|c: char| c.is_alphanumeric() || c == '_') {
                from = end;
                continue;
            }
            out.replace_range(at..end, plain);
            from = at + plain.len();
        }
    }
    out
}

/// `$body` with `$E` naming the element type of `$precision` (`f64` or `f32`): the one place a
/// task's run turns its [`ctrnn::Precision`] setting into the type its lanes compute in. `$body`
/// is compiled once for each type.
macro_rules! in_precision {
    ($precision:expr, $E:ident => $body:expr) => {
        match $precision {
            ::ctrnn::Precision::F64 => {
                type $E = f64;
                $body
            }
            ::ctrnn::Precision::F32 => {
                type $E = f32;
                $body
            }
        }
    };
}
pub(crate) use in_precision;

/// The state of a one-network block, widened to `f64` (exactly).
pub(crate) fn lane_state<E: Elem>(lanes: &Lanes<1, E>) -> Vec<f64> {
    let mut state = vec![E::default(); lanes.size()];
    lanes.lane_state(0, &mut state);
    state.into_iter().map(E::to_f64).collect()
}

/// Whether the caller asked to stop.
pub(crate) fn interrupted(cancel: Option<&AtomicBool>) -> bool {
    cancel.is_some_and(|c| c.load(Ordering::Relaxed))
}

/// A lane whose state stopped being finite.
pub struct Diverged {
    lane: usize,
    neuron: usize,
    value: f64,
    /// `dt / tau` there, and the method.
    step: (f64, Method),
}

impl Diverged {
    /// The first non-finite state of `lanes`, if any.
    pub fn find<const L: usize, E: Elem>(lanes: &Lanes<L, E>) -> std::result::Result<(), Diverged> {
        for neuron in 0..lanes.size() {
            let row = lanes.state(neuron);
            if let Some(lane) = (0..lanes.len()).find(|&l| !row[l].finite()) {
                return Err(Diverged {
                    lane,
                    neuron,
                    value: row[lane].to_f64(),
                    step: lanes.last_step(neuron, lane),
                });
            }
        }
        Ok(())
    }

    /// The error, naming the network that `network(lane)` says ran on the lane.
    pub(crate) fn error(self, network: impl FnOnce(usize) -> usize) -> Error {
        let what = format!("network {}", network(self.lane));
        let (h, method) = self.step;
        ctrnn::integrate::diverged(&what, self.neuron, self.value, h, method)
    }
}

/// Checks that every network has the `m` sensors a task feeds, named in `what`.
pub(crate) fn check_inputs(networks: &[ctrnn::Network], m: usize, what: &str) -> Result<()> {
    for (p, net) in networks.iter().enumerate() {
        if net.n_inputs() != m {
            return Err(Error::InvalidArgument(format!(
                "network {p} has M = {} sensors; this task needs M = {m} ({what})",
                net.n_inputs()
            )));
        }
    }
    Ok(())
}

/// A value computed once for a key and kept, such as a run's validation set, which is the same
/// in every generation. Only a cache: a clone starts empty, and any two compare equal.
pub(crate) struct Memo<K, V>(Mutex<Option<(K, Arc<V>)>>);

impl<K: PartialEq + Clone, V> Memo<K, V> {
    /// The value for `key`: the kept one if it was computed for `key`, else `make(key)`, kept.
    pub(crate) fn get_or_try(&self, key: &K, make: impl FnOnce() -> Result<V>) -> Result<Arc<V>> {
        let mut slot = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((k, v)) = slot.as_ref() {
            if k == key {
                return Ok(v.clone());
            }
        }
        let v = Arc::new(make()?);
        *slot = Some((key.clone(), v.clone()));
        Ok(v)
    }
}

impl<K, V> Default for Memo<K, V> {
    fn default() -> Self {
        Memo(Mutex::new(None))
    }
}

impl<K, V> Clone for Memo<K, V> {
    fn clone(&self) -> Self {
        Memo::default()
    }
}

impl<K, V> PartialEq for Memo<K, V> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl<K, V> std::fmt::Debug for Memo<K, V> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Memo")
    }
}

/// The largest count (trials, triggers, steps, chains, neurons) a task setting may hold: 2^20.
/// The paper's counts are in the tens to thousands; a count past this is a typing error that
/// would otherwise make a task allocate terabytes and abort the process.
pub const MAX_COUNT: usize = 1 << 20;

/// One of the paper's time steps, every task's default integration: 10 forward-Euler steps of
/// 0.1 with the inputs held (`docs/paper.md`, "The network").
pub const TIME_STEP: Integrator = Integrator {
    method: Method::Euler,
    dt: 0.1,
    substeps: 10,
};

/// The most time steps one trial may last, whatever settings it is derived from: 2^24. The
/// paper's longest trial is about 1,000 time steps.
pub const MAX_TRIAL_STEPS: u128 = 1 << 24;

/// The most integration steps (time steps x substeps) one trial may take: 2^32, hours of one
/// core for one network.
pub const MAX_INTEGRATION_STEPS: u128 = 1 << 32;

/// Checks that a trial of at most `steps` time steps (`what` says how it is derived), each of
/// `substeps` integration steps, stays within [`MAX_TRIAL_STEPS`] and [`MAX_INTEGRATION_STEPS`]:
/// a product of settings each within its own limit can still ask for years of work or terabytes.
pub fn check_trial_steps(what: &str, steps: u128, substeps: usize) -> Result<()> {
    if steps > MAX_TRIAL_STEPS {
        return Err(Error::Config(format!(
            "a trial can last {steps} time steps ({what}); the limit is {MAX_TRIAL_STEPS} (2^24)"
        )));
    }
    let total = steps.saturating_mul(substeps as u128);
    if total > MAX_INTEGRATION_STEPS {
        return Err(Error::Config(format!(
            "a trial can take {total} integration steps ({what}, times {substeps} substeps); \
             the limit is {MAX_INTEGRATION_STEPS} (2^32)"
        )));
    }
    Ok(())
}

/// Checks a count setting is in `1..=MAX_COUNT`, naming it.
pub fn check_count(name: &str, value: usize) -> Result<()> {
    if value == 0 {
        return Err(Error::Config(format!("{name} is 0; it must be >= 1")));
    }
    if value > MAX_COUNT {
        return Err(Error::Config(format!(
            "{name} is {value}; the limit is {MAX_COUNT} (2^20), as larger counts would need more \
             memory or time than any run can use"
        )));
    }
    Ok(())
}
