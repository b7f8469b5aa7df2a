//! `dnnevo._core.condition_seed`: a seed word from dnnevo's random streams, for conditions that
//! Python code draws (a user task's episodes), so that they follow a run's seed and generation as
//! the built-in tasks' conditions do.

use ctrnn::{Purpose, Stream};
use pyo3::prelude::*;
use pyo3::types::PyAny;

use crate::arrays::{arg_err, uint};

/// The first word of stream `(seed, generation, purpose, 0, 0)`, with `purpose` one of
/// "trial" (training conditions), "validate" or "evaluate" (fresh conditions).
#[pyfunction]
#[pyo3(signature = (seed, generation, purpose="trial"), text_signature = "(seed, generation, purpose='trial')")]
pub fn condition_seed(
    seed: &Bound<'_, PyAny>,
    generation: &Bound<'_, PyAny>,
    purpose: &str,
) -> PyResult<u64> {
    let seed: u64 = uint(seed, "seed", "[0, 2**64)")?;
    let generation: u64 = uint(generation, "generation", "[0, 2**64)")?;
    let purpose = match purpose {
        "trial" => Purpose::Trial,
        "validate" => Purpose::Validate,
        "evaluate" => Purpose::Evaluate,
        other => {
            return Err(arg_err(format!(
                "purpose is '{other}'; expected 'trial', 'validate' or 'evaluate'"
            )))
        }
    };
    Ok(Stream::new(seed, generation, purpose, 0, 0).next_u64())
}
