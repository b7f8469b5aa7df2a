//! What one call of the integrator may ask for: a bound on its work, and memory that is
//! reserved, not assumed. A request past either is an error that says how much it asked for;
//! without them a typing error (`substeps = 2**63`, `10**12` rows) runs for ever or aborts the
//! process when an allocation fails.

use crate::error::{Error, Result};

/// The most integration steps one call may take, over all its networks (networks x rows x
/// substeps): 2^36, a few minutes of both cores for networks of 5 neurons and a quarter of an
/// hour for 30. The tasks bound each trial by `tasks::MAX_INTEGRATION_STEPS` in the same spirit.
pub const MAX_CALL_STEPS: u128 = 1 << 36;

/// The most rows (networks x replicas) one [`Batch`](crate::Batch) may hold: 2^24.
pub const MAX_BATCH_ROWS: u128 = 1 << 24;

/// Checks that `networks` networks stepped through `rows` input rows of `substeps` steps each
/// stay within [`MAX_CALL_STEPS`].
pub fn check_work(networks: usize, rows: usize, substeps: usize) -> Result<()> {
    let total = (networks as u128)
        .saturating_mul(rows as u128)
        .saturating_mul(substeps as u128);
    if total > MAX_CALL_STEPS {
        return Err(Error::InvalidArgument(format!(
            "this call would take {total} integration steps ({networks} networks x {rows} rows x \
             {substeps} substeps); the limit is {MAX_CALL_STEPS} (2^36): split the work"
        )));
    }
    Ok(())
}

/// Checks that one step of a [`Batch`](crate::Batch) of `rows` rows, `substeps` steps each,
/// stays within [`MAX_CALL_STEPS`]: [`check_work`] in a batch's words, whose rows may be one
/// network's episodes.
///
/// # Example
/// ```
/// use ctrnn::limits::check_batch_step;
/// assert!(check_batch_step(200, 1000).is_ok());
/// let e = check_batch_step(200, 1_000_000_000).unwrap_err();
/// assert!(e.to_string().contains("(200 rows x 1000000000 substeps)"));
/// ```
pub fn check_batch_step(rows: usize, substeps: usize) -> Result<()> {
    let total = (rows as u128).saturating_mul(substeps as u128);
    if total > MAX_CALL_STEPS {
        return Err(Error::InvalidArgument(format!(
            "one step of this batch would take {total} integration steps ({rows} rows x {substeps} \
             substeps); the limit is {MAX_CALL_STEPS} (2^36): use fewer substeps (a longer dt) or \
             fewer rows"
        )));
    }
    Ok(())
}

/// `len` zeros, or an error naming `what` when the memory cannot be had (instead of the abort
/// of a failed allocation).
///
/// # Example
/// ```
/// assert_eq!(ctrnn::limits::zeros(3, "states").unwrap(), vec![0.0; 3]);
/// assert!(ctrnn::limits::zeros(usize::MAX / 8, "states").is_err());
/// ```
pub fn zeros(len: usize, what: &str) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    out.try_reserve_exact(len).map_err(|_| {
        Error::InvalidArgument(format!(
            "cannot allocate the {what}: {len} values ({:.1} GiB)",
            len as f64 * 8.0 / (1u64 << 30) as f64
        ))
    })?;
    out.resize(len, 0.0);
    Ok(out)
}

/// The product of `sizes`, or an error naming `what` when it does not fit in memory's address
/// range.
pub fn product(sizes: &[usize], what: &str) -> Result<usize> {
    sizes
        .iter()
        .try_fold(1usize, |acc, &x| acc.checked_mul(x))
        .ok_or_else(|| {
            Error::InvalidArgument(format!(
                "the {what} would hold {} values, more than memory can address",
                sizes
                    .iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join(" x ")
            ))
        })
}
