//! A factor of a designed experiment: a name and its level names.

use super::DoeError;
use serde::{Deserialize, Serialize};

/// A factor and its levels. For two-level designs the first level is the low
/// (-1) setting and the second the high (+1) setting.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Factor {
    pub name: String,
    pub levels: Vec<String>,
}

impl Factor {
    /// A factor from a name and level names.
    pub fn new<S: Into<String>>(
        name: impl Into<String>,
        levels: impl IntoIterator<Item = S>,
    ) -> Self {
        Factor {
            name: name.into(),
            levels: levels.into_iter().map(Into::into).collect(),
        }
    }

    /// Checks at least two levels and no repeated level name.
    pub fn validate(&self) -> Result<(), DoeError> {
        if self.levels.len() < 2 {
            return Err(DoeError::TooFewLevels {
                factor: self.name.clone(),
                got: self.levels.len(),
            });
        }
        for (k, l) in self.levels.iter().enumerate() {
            if self.levels[..k].contains(l) {
                return Err(DoeError::DuplicateLevel {
                    factor: self.name.clone(),
                    level: l.clone(),
                });
            }
        }
        Ok(())
    }
}
