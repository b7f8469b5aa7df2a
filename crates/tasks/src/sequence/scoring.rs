//! How a trial is scored and judged: performance, warm-up and the success rule's constants.

/// The fraction of trials a network must get right, after the warm-up, to have learnt a target.
pub const SUCCESS_FRACTION: f64 = 0.9;

/// Trials per target when a run checks whether its champion has succeeded yet (`dnnevo sweep`'s
/// "first success" generation). `dnnevo evaluate` uses as many as asked.
pub const SUCCESS_TRIALS: usize = 20;

/// A trial's performance `max(0, (mean(rs) - base) / (1 - base))`; 0 when `base >= 1`.
///
/// # Example
/// ```
/// assert_eq!(tasks::performance(&[1.0, 0.5], 0.5), 0.5);
/// assert_eq!(tasks::performance(&[0.25], 0.5), 0.0);
/// ```
pub fn performance(rs: &[f64], base: f64) -> f64 {
    score(mean(rs), base)
}

/// `max(0, (mean_r - base) / (1 - base))`, 0 when `base >= 1`.
pub fn score(mean_r: f64, base: f64) -> f64 {
    unclamped_score(mean_r, base).max(0.0)
}

/// `(mean_r - base) / (1 - base)`, 0 when `base >= 1`.
pub(super) fn unclamped_score(mean_r: f64, base: f64) -> f64 {
    if base >= 1.0 {
        0.0
    } else {
        (mean_r - base) / (1.0 - base)
    }
}

/// The arithmetic mean, summed in order.
pub fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// The warm-up of the success rule: triggers before index `2 * len(target)` are not judged.
pub fn warmup(target: &str) -> usize {
    2 * target.len()
}

/// Whether a trigger whose window had mean output `mean_output` was right about bit `bit`.
pub fn correct(bit: u8, mean_output: f64) -> bool {
    if bit == 1 {
        mean_output > 0.5
    } else {
        mean_output < 0.5
    }
}

/// One judged trial: its performance, and whether every trigger after the warm-up was correct.
pub(super) type Judged = (f64, bool);
