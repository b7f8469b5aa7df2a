//! Small pieces every task shares: reading a config from JSON parameters, noticing Ctrl-C, and
//! reporting a lane whose state stopped being finite.

use std::sync::atomic::{AtomicBool, Ordering};

use ctrnn::{Error, Lanes, Result};
use serde::de::DeserializeOwned;

/// Reads a task config from a JSON object of its fields (`null` means all defaults). Unknown or
/// mistyped fields are [`Error::Config`] errors prefixed with the task's `name`.
pub(crate) fn config_from_params<C: DeserializeOwned + Default>(
    name: &str,
    params: &serde_json::Value,
) -> Result<C> {
    match params {
        serde_json::Value::Null => Ok(C::default()),
        serde_json::Value::Object(_) => {
            C::deserialize(params).map_err(|e| Error::Config(format!("{name}: {e}")))
        }
        other => Err(Error::Config(format!(
            "{name}: the parameters must be a JSON object of config fields; got {other}"
        ))),
    }
}

/// Whether the caller asked to stop.
pub(crate) fn interrupted(cancel: Option<&AtomicBool>) -> bool {
    cancel.is_some_and(|c| c.load(Ordering::Relaxed))
}

/// A lane whose state stopped being finite.
pub(crate) struct Diverged {
    lane: usize,
    neuron: usize,
    value: f64,
}

impl Diverged {
    /// The first non-finite state of `lanes`, if any.
    pub(crate) fn find<const L: usize>(lanes: &Lanes<L>) -> std::result::Result<(), Diverged> {
        for neuron in 0..lanes.size() {
            let row = lanes.state(neuron);
            if let Some(lane) = (0..lanes.len()).find(|&l| !row[l].is_finite()) {
                return Err(Diverged {
                    lane,
                    neuron,
                    value: row[lane],
                });
            }
        }
        Ok(())
    }

    /// The error, with the lane's network numbered from `first`.
    pub(crate) fn error(self, first: usize) -> Error {
        Error::InvalidArgument(format!(
            "integration diverged: state[{}] of network {} became {}; use a smaller dt \
             (Euler needs dt / tau well below 2)",
            self.neuron,
            first + self.lane,
            self.value
        ))
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
