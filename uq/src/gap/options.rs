//! Options of the gap diagnosis.

use super::GapError;
use palpate_core::Effect;
use serde::{Deserialize, Serialize};

/// How the diagnosis decides. The defaults are statistical levels, not
/// values tuned to particular data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GapOptions {
    /// Family-wise significance level of every test (misfit, runs,
    /// autocorrelation, windows, likelihood ratio, held-out gain); each family
    /// is Bonferroni-corrected for its number of tests.
    pub alpha: f64,
    /// Number of contiguous blocks of the record for blocked cross-validation:
    /// each block is left out in turn, predicted by the model fitted to the
    /// rest; the last block is the later segment of the history.
    pub folds: usize,
    /// Running-window length in samples (default n / 15 within [8, 60]).
    pub window: Option<usize>,
    /// Candidate effects (default: every effect the base model offers).
    pub effects: Option<Vec<Effect>>,
    /// Level of the test that two effects' fits differ (below it they are
    /// reported as confounded).
    pub confound_alpha: f64,
}

impl Default for GapOptions {
    fn default() -> Self {
        GapOptions {
            alpha: 1e-3,
            folds: 8,
            window: None,
            effects: None,
            confound_alpha: 0.01,
        }
    }
}

impl GapOptions {
    /// Checks ranges.
    pub fn validate(&self) -> Result<(), GapError> {
        if !(self.alpha > 0.0 && self.alpha < 0.5) {
            return Err(GapError::InvalidOption {
                option: "alpha",
                reason: format!("{} must lie in (0, 0.5)", self.alpha),
            });
        }
        if !(self.confound_alpha > 0.0 && self.confound_alpha < 1.0) {
            return Err(GapError::InvalidOption {
                option: "confound_alpha",
                reason: format!("{} must lie in (0, 1)", self.confound_alpha),
            });
        }
        if !(2..=20).contains(&self.folds) {
            return Err(GapError::InvalidOption {
                option: "folds",
                reason: format!("{} must lie in [2, 20]", self.folds),
            });
        }
        if let Some(w) = self.window {
            if w < 3 {
                return Err(GapError::InvalidOption {
                    option: "window",
                    reason: format!("{w} samples is too short (at least 3)"),
                });
            }
        }
        Ok(())
    }
}
