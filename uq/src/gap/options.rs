//! Options of the gap diagnosis.

use super::{GapError, NoisePaths};
use palpate_core::Effect;
use serde::{Deserialize, Serialize};

/// How the diagnosis decides. The defaults are statistical levels, not
/// values tuned to particular data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GapOptions {
    /// Significance level of the tests. The windows are tested at
    /// alpha / (2 x number of windows) and the likelihood ratios at
    /// alpha / number of candidates (Bonferroni); the three whole-record tests
    /// (misfit, runs, lag-1 autocorrelation) are each applied at alpha, so
    /// "gap significant" has a family-wise level of about 3 alpha plus the
    /// windows' alpha; the held-out gain must exceed the chi2(1) quantile at
    /// alpha.
    pub alpha: f64,
    /// Number of folds of the cross-validation: the record is cut into short
    /// chunks dealt to the folds in turn (every fold spans every loading
    /// phase); each fold is left out in turn, predicted by the model fitted
    /// to the rest. The last 1/folds of the record is also reported on its
    /// own as the later segment.
    pub folds: usize,
    /// Running-window length in samples (default n / 15 within [8, 60]).
    pub window: Option<usize>,
    /// Candidate effects (default: every effect the base model offers).
    pub effects: Option<Vec<Effect>>,
    /// Level of the test that two effects' fits differ (below it they are
    /// reported as confounded).
    pub confound_alpha: f64,
    /// How each left-out fold is refitted in the cross-validation.
    pub cross_validation: CrossValidation,
    /// How the record is cut into folds.
    pub fold_layout: FoldLayout,
    /// Materiality threshold: the smallest RMS of the systematic misfit an
    /// effect must remove, in noise SDs, for the verdict to name it
    /// (sqrt(MS_before - MS_after) / sigma). Below it an effect that earns
    /// its parameters is reported as "detectable but immaterial" and the
    /// verdict stays `none`. Default 0.4: a model error of 0.4 noise SD
    /// raises the RMS prediction error by under 8 % (sqrt(1 + 0.4^2) = 1.077).
    pub materiality: f64,
    /// Cache an expensive model's predictions for the whole diagnosis, and
    /// serve whole rays of moduli from one solve when the model is measured
    /// to be homogeneous in them (`gap::memo`). Default true; false only to
    /// measure what the cache saves.
    pub cache: bool,
    /// The record's loading paths, when it interleaves several (general
    /// biaxial data: one stress per direction, paths at a fixed stretch):
    /// the noise is then estimated within each path only. Default: one
    /// path, the record in order (by time when timed).
    pub paths: Option<NoisePaths>,
}

/// How the record is cut into the folds of the cross-validation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FoldLayout {
    /// Short contiguous chunks dealt to the folds in turn: every fold spans
    /// every loading phase, so no training set loses the samples that
    /// identify an effect (docs/gap-diagnosis.md).
    #[default]
    Stratified,
    /// `folds` contiguous blocks (the first version's layout, kept for
    /// comparison): leaving out the hold of a relaxation test leaves the time
    /// constants unidentified in the refit, and a true effect can be rejected.
    Contiguous,
}

/// Refit strategy of the blocked cross-validation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CrossValidation {
    /// `linearised` whenever the folds are stratified (for a model that
    /// declares itself expensive, `ForwardModel::expensive`, one step; for
    /// a cheap one refined to the refit by chord iterations), `refit` with
    /// contiguous blocks (leaving a whole phase out can move the parameters
    /// far from the full-record optimum, where one Jacobian does not reach).
    #[default]
    Auto,
    /// A Levenberg-Marquardt refit per left-out block (exact).
    Refit,
    /// From the full-record optimum with the sensitivities there: one
    /// Gauss-Newton step per left-out block for an expensive model (no
    /// model evaluation beyond the one Jacobian: approximate
    /// cross-validation; Beirami et al. 2017, Stephenson & Broderick 2020),
    /// refined by chord iterations (a few predictions per block) for a
    /// cheap one. Accurate when leaving a block out moves the parameters
    /// little compared with the curvature of the model.
    Linearised,
}

impl CrossValidation {
    /// Whether the linearised form applies to a model of this cost and
    /// folds of this layout.
    pub fn linearised(self, expensive: bool, layout: FoldLayout) -> bool {
        match self {
            CrossValidation::Auto => expensive || layout == FoldLayout::Stratified,
            CrossValidation::Refit => false,
            CrossValidation::Linearised => true,
        }
    }
}

impl Default for GapOptions {
    fn default() -> Self {
        GapOptions {
            alpha: 1e-3,
            folds: 8,
            window: None,
            effects: None,
            confound_alpha: 0.01,
            cross_validation: CrossValidation::Auto,
            fold_layout: FoldLayout::Stratified,
            materiality: 0.4,
            cache: true,
            paths: None,
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
        if !(self.materiality >= 0.0 && self.materiality.is_finite()) {
            return Err(GapError::InvalidOption {
                option: "materiality",
                reason: format!("{} must be a finite number >= 0", self.materiality),
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
