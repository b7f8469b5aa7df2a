//! How the scores of a task's groups of trials (a sequence task's targets, a navigation task's
//! environment types) make one fitness.

use serde::{Deserialize, Serialize};

/// How the scores of the groups make one fitness.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Aggregate {
    /// The mean over all scored trials: the paper's.
    #[default]
    Mean,
    /// The worst group's score (its mean over its trials): a network is only as good as the
    /// group it does least well.
    Min,
    /// The mean of `mean` and `min`: rewards every group, and the weakest twice.
    MeanMin,
}

impl Aggregate {
    /// The fitness from the mean over all trials and the worst group's score.
    ///
    /// # Example
    /// ```
    /// use tasks::Aggregate;
    /// assert_eq!(Aggregate::Mean.combine(0.75, 0.5), 0.75);
    /// assert_eq!(Aggregate::Min.combine(0.75, 0.5), 0.5);
    /// assert_eq!(Aggregate::MeanMin.combine(0.75, 0.5), 0.625);
    /// ```
    pub fn combine(self, overall: f64, worst: f64) -> f64 {
        match self {
            Aggregate::Mean => overall,
            Aggregate::Min => worst,
            Aggregate::MeanMin => 0.5 * (overall + worst),
        }
    }
}
