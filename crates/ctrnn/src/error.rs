//! The one error type of the `ctrnn` crate.
//!
//! Every message says what was wrong and what is allowed, so that it can be shown to a user as is.

/// Everything that can go wrong in `ctrnn`.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A network's parameters are inconsistent or out of their domain.
    #[error("invalid network: {0}")]
    InvalidNetwork(String),
    /// An integrator setting (dt, substeps, method) or an input array is unusable.
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// A network file is not a valid `dnnevo-network` document, or a checkpoint not a valid
    /// state of an evolution (the message says which).
    #[error("invalid file: {0}")]
    Format(String),
    /// An evolution setting is out of range.
    #[error("invalid config: {0}")]
    Config(String),
    /// A fitness function returned a value that cannot be selected on.
    #[error("invalid fitness: {0}")]
    Fitness(String),
    /// The computation was cancelled from outside (Ctrl-C).
    #[error("interrupted")]
    Interrupted,
    /// Reading or writing a file failed.
    #[error("{context}: {source}")]
    Io {
        /// What was being done, including the path.
        context: String,
        /// The operating system's error.
        source: std::io::Error,
    },
}

/// Shorthand for results in this crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Checks that every value of `values` is finite; the error names `field[index]`.
pub(crate) fn check_finite(field: &str, values: &[f64], cols: usize) -> Result<()> {
    if all_finite(values) {
        return Ok(());
    }
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => Err(Error::InvalidNetwork(format!(
            "{field}{} is {}; every value must be finite",
            index_label(k, cols),
            values[k]
        ))),
    }
}

/// Whether every value is finite, in a loop that vectorises (the search for the culprit does
/// not): `v * 0` is 0 for a finite `v` and NaN otherwise, and NaN survives every sum.
fn all_finite(values: &[f64]) -> bool {
    const WIDTH: usize = 8;
    let (chunks, rest) = values.as_chunks::<WIDTH>();
    let mut acc = [0.0; WIDTH];
    for chunk in chunks {
        for (a, v) in acc.iter_mut().zip(chunk) {
            *a += v * 0.0;
        }
    }
    acc.iter().chain(rest).all(|v| (v * 0.0) == 0.0)
}

/// `[i]` for a vector (`cols == 0`) or `[i][j]` for a row-major matrix with `cols` columns.
pub(crate) fn index_label(k: usize, cols: usize) -> String {
    match k.checked_div(cols) {
        None => format!("[{k}]"),
        Some(row) => format!("[{row}][{}]", k % cols),
    }
}

/// `n` and `noun`, the noun plural unless `n` is 1, for messages: `counted(1, "value")` is
/// "1 value", `counted(3, "value")` "3 values".
pub(crate) fn counted(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}
