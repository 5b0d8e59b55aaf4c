//! The diagnosis report: the JSON contract of GAP.md plus the evidence and
//! the vectors a plot needs, and its markdown rendering.

use super::noise::NoiseEstimate;
use super::profile::ProfileInterval;
use super::score::ScoreTest;
use super::structure::{GapWindow, WhitenessTests};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write;

/// One candidate effect, refitted (GAP.md `ranking` entry).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RankedEffect {
    /// Canonical effect name.
    pub effect: String,
    /// The effect's own fitted parameters (physical units).
    pub params: BTreeMap<String, f64>,
    /// RMS residual of the base fit on the fitted samples (data unit).
    pub misfit_before: f64,
    /// RMS residual of the enriched fit on the fitted samples.
    pub misfit_after: f64,
    /// RMS residual of held-out predictions of the base model (blocked
    /// cross-validation: each block predicted by a fit to the other blocks).
    pub heldout_before: f64,
    /// Same for the enriched model.
    pub heldout_after: f64,
    /// The same restricted to the last block (the later segment of the
    /// history, predicted from the earlier part and what follows none).
    pub later_before: f64,
    pub later_after: f64,
    /// A sentence with the numbers behind the rank.
    pub evidence: String,
    /// Whether the enriched fit determines its parameters and is not
    /// confounded with another effect.
    pub identifiable: bool,
    /// Effects whose fits the data cannot tell apart from this one.
    pub confounded_with: Vec<String>,
    /// For every other candidate, the cosine of the smallest principal angle
    /// between the two effects' sensitivity directions at "off" (base
    /// directions removed): near 1, the two are locally indistinguishable.
    pub sensitivity_overlap: BTreeMap<String, f64>,
    /// Whether the effect earns its parameters (significant likelihood ratio
    /// and held-out gain).
    pub earns: bool,
    /// Enriched model name.
    pub model: String,
    /// Every parameter of the enriched fit.
    pub all_params: BTreeMap<String, f64>,
    /// Standard errors of the effect's parameters (absent where undefined).
    pub standard_errors: BTreeMap<String, Option<f64>>,
    /// Score (Lagrange-multiplier) test at the "off" point.
    pub score: ScoreTest,
    /// Likelihood ratio (SSE_base - SSE_enriched) / sigma^2 on the fitted samples.
    pub lr_statistic: f64,
    /// Its chi-square p-value on the effect's degrees of freedom.
    pub lr_p: f64,
    /// Held-out gain (SSE_base - SSE_enriched) / sigma^2 of the cross-validated predictions.
    pub heldout_gain: f64,
    /// Change of AIC and BIC (enriched - base) under an AR(1) error model.
    pub delta_aic_ar1: f64,
    pub delta_bic_ar1: f64,
    /// Whiteness of the enriched fit's residuals.
    pub after: WhitenessTests,
    /// Largest |correlation| between parameters of the enriched fit.
    pub max_correlation: f64,
    /// Why the fit is or is not identifiable (from the calibration report).
    pub identifiability: String,
    /// 95 % profile-likelihood intervals of the effect's own parameters
    /// (computed for the verdict's effect only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub profile: Vec<ProfileInterval>,
}

/// A candidate whose refit could not be made (reported, not hidden).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedCandidate {
    pub effect: String,
    pub error: String,
}

/// The base model's fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BaseSummary {
    pub model: String,
    pub params: BTreeMap<String, f64>,
    /// RMS residual on all samples (data unit).
    pub misfit: f64,
    /// RMS residual of the cross-validated (held-out) predictions.
    pub heldout: f64,
    pub tests: WhitenessTests,
    /// Whether the base misfit is significantly more than noise.
    pub gap_significant: bool,
    /// Which tests say so.
    pub reason: String,
}

/// Vectors for a plot of the diagnosis (all of the record's length).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GapPlot {
    /// Name and values of the horizontal axis (`time_s` or the drive column).
    pub axis: String,
    pub x: Vec<f64>,
    /// Drive column name and values.
    pub drive_name: String,
    pub drive: Vec<f64>,
    pub observed: Vec<f64>,
    pub base_fit: Vec<f64>,
    pub base_residual: Vec<f64>,
    /// Running mean of the base residuals and its +-2 sigma/sqrt(w) band.
    pub band_mean: Vec<f64>,
    pub band_lower: Vec<f64>,
    pub band_upper: Vec<f64>,
    /// The best-ranked enrichment's fit and residuals.
    pub enriched_effect: Option<String>,
    pub enriched_fit: Option<Vec<f64>>,
    pub enriched_residual: Option<Vec<f64>>,
    /// Cross-validation blocks [first, end) of sample indices.
    pub folds: Vec<(usize, usize)>,
    /// Held-out (cross-validated) predictions of the base model.
    pub base_cv: Vec<f64>,
}

/// The diagnosis (GAP.md JSON contract: `verdict`, `noise_sd`, `where`,
/// `ranking`, plus supporting fields).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GapReport {
    /// An effect name, or `none`.
    pub verdict: String,
    /// Noise SD estimated from the data (data unit).
    pub noise_sd: f64,
    /// Windows of significant base misfit.
    #[serde(rename = "where")]
    pub where_: Vec<GapWindow>,
    /// Candidates, best first.
    pub ranking: Vec<RankedEffect>,
    /// Candidates that could not be assessed, with the reason.
    pub failed: Vec<FailedCandidate>,
    /// Effects the data cannot tell apart from the verdict (empty when the
    /// verdict is clear).
    pub confounded: Vec<String>,
    /// One paragraph saying why.
    pub explanation: String,
    pub base: BaseSummary,
    pub noise: NoiseEstimate,
    /// Samples, and blocks of the cross-validation.
    pub samples: usize,
    pub folds: usize,
    pub plot: GapPlot,
}

impl GapReport {
    /// The report as markdown (tables of windows and candidates).
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "# Sim-to-real gap diagnosis\n");
        let _ = writeln!(s, "**Verdict: `{}`**", self.verdict);
        if !self.confounded.is_empty() {
            let _ = writeln!(
                s,
                "\n**Cannot be told apart** from `{}` with these data.",
                self.confounded.join("`, `")
            );
        }
        let _ = writeln!(s, "\n{}\n", self.explanation);
        let _ = writeln!(s, "## Base model\n");
        let _ = writeln!(s, "- model: {}", self.base.model);
        let params: Vec<String> = self
            .base
            .params
            .iter()
            .map(|(k, v)| format!("{k} = {v:.6e}"))
            .collect();
        let _ = writeln!(s, "- parameters: {}", params.join(", "));
        let t = &self.base.tests;
        let _ = writeln!(
            s,
            "- noise SD (from second differences): {:.4e}; misfit RMS {:.4e} (RMS/noise {:.2}, z = {:.1}, p = {:.2e})",
            self.noise_sd, self.base.misfit, t.rms_over_noise, t.misfit_z, t.misfit_p
        );
        let _ = writeln!(
            s,
            "- residual structure: lag-1 autocorrelation {:.2} (p = {:.2e}); {} runs for {:.1} expected (z = {:.1}, p = {:.2e})",
            t.lag1_autocorrelation, t.lag1_p, t.runs, t.runs_expected, t.runs_z, t.runs_p
        );
        let _ = writeln!(
            s,
            "- significant gap: {} ({})\n- samples: {} (blocked cross-validation over {} blocks)\n",
            if self.base.gap_significant {
                "yes"
            } else {
                "no"
            },
            self.base.reason,
            self.samples,
            self.folds
        );
        let _ = writeln!(s, "## Where\n");
        if self.where_.is_empty() {
            let _ = writeln!(s, "No window of significant misfit.\n");
        } else {
            let _ = writeln!(
                s,
                "| axis | from | to | misfit RMS | mean residual | significance |"
            );
            let _ = writeln!(s, "|---|---|---|---|---|---|");
            for w in &self.where_ {
                let _ = writeln!(
                    s,
                    "| {} | {:.3} | {:.3} | {:.3e} | {:.3e} | {} |",
                    w.axis, w.from, w.to, w.misfit_rms, w.mean_residual, w.significance
                );
            }
            let _ = writeln!(s);
        }
        let _ = writeln!(s, "## Candidates (best first)\n");
        let _ = writeln!(
            s,
            "| effect | parameters | misfit before -> after | held-out before -> after | score (p) | LR (p) | dBIC AR(1) | earns | identifiable |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
        for r in &self.ranking {
            let params: Vec<String> = r
                .params
                .iter()
                .map(|(k, v)| match r.standard_errors.get(k).copied().flatten() {
                    Some(se) => format!("{k} = {v:.4e} +- {se:.1e}"),
                    None => format!("{k} = {v:.4e}"),
                })
                .collect();
            let _ = writeln!(
                s,
                "| {} | {} | {:.3e} -> {:.3e} | {:.3e} -> {:.3e} | {:.1} ({:.1e}) | {:.1} ({:.1e}) | {:.1} | {} | {}{} |",
                r.effect,
                params.join(", "),
                r.misfit_before,
                r.misfit_after,
                r.heldout_before,
                r.heldout_after,
                r.score.statistic,
                r.score.p_value,
                r.lr_statistic,
                r.lr_p,
                r.delta_bic_ar1,
                if r.earns { "yes" } else { "no" },
                if r.identifiable { "yes" } else { "no" },
                if r.confounded_with.is_empty() {
                    String::new()
                } else {
                    format!(" (confounded with {})", r.confounded_with.join(", "))
                }
            );
        }
        for f in &self.failed {
            let _ = writeln!(
                s,
                "| {} | could not be assessed: {} | | | | | | | |",
                f.effect, f.error
            );
        }
        let _ = writeln!(s, "\n### Evidence\n");
        for r in &self.ranking {
            let _ = writeln!(s, "- **{}**: {}", r.effect, r.evidence);
        }
        s
    }
}
