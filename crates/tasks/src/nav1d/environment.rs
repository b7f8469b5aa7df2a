//! The two environment types of §4: where the landmark is relative to the goal.

use serde::{Deserialize, Serialize};

/// Where the landmark is relative to the goal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Environment {
    /// The landmark is on the other side of the start from the goal.
    Far,
    /// The landmark is on the goal's side.
    Near,
}
