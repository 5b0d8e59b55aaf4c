//! The diagnosis report: the JSON contract of GAP.md plus the evidence and
//! the vectors a plot needs, and its markdown rendering.

use super::noise::NoiseEstimate;
use super::profile::ProfileInterval;
use super::score::ScoreTest;
use super::set::{Remainder, SetMember};
use super::structure::{GapWindow, WhitenessTests};
use super::undetectable::Undetectable;
use super::verdict::{PartlyExplained, Verdict};
use palpate_core::Effect;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write;

/// One candidate effect, refitted (GAP.md `ranking` entry).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RankedEffect {
    /// The effect (serialised by its canonical name).
    pub effect: Effect,
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
    pub confounded_with: Vec<Effect>,
    /// For every other candidate, the cosine of the smallest principal angle
    /// between the two effects' sensitivity directions at "off" (base
    /// directions removed): near 1, the two are locally indistinguishable.
    pub sensitivity_overlap: BTreeMap<Effect, f64>,
    /// Whether the effect earns its parameters (significant likelihood ratio
    /// and held-out gain).
    pub earns: bool,
    /// How much misfit it removes, beside the statistics of whether it removes any.
    pub practical: PracticalSize,
    /// Enriched model name.
    pub model: String,
    /// The form of the effect, when it has several (the richer law of
    /// `material_form`, e.g. `ogden:1`), chosen by held-out misfit with a
    /// charge per parameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub form: Option<String>,
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

/// The practical size of an effect, beside its statistical significance:
/// a misfit can be detectable (many samples, slightly correlated noise) and
/// still too small to matter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PracticalSize {
    /// RMS misfit / noise SD of the base fit and of the enriched fit.
    pub misfit_over_noise_before: f64,
    pub misfit_over_noise_after: f64,
    /// Share of the excess mean-square misfit (above the noise variance)
    /// the effect removes, (MS_before - MS_after) / (MS_before - sigma^2);
    /// absent when the base misfit is not above the noise.
    pub excess_explained: Option<f64>,
    /// RMS of the systematic component the effect removes,
    /// sqrt(MS_before - MS_after), in noise SDs.
    pub removed_over_noise: f64,
    /// Whether that reaches the materiality threshold (`GapOptions::materiality`).
    pub material: bool,
}

/// A candidate whose refit could not be made (reported, not hidden).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailedCandidate {
    pub effect: Effect,
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
    /// The fit of the whole explanation (when it has two effects or more).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set_fit: Option<Vec<f64>>,
    /// The best-ranked enrichment's fit and residuals.
    pub enriched_effect: Option<Effect>,
    pub enriched_fit: Option<Vec<f64>>,
    pub enriched_residual: Option<Vec<f64>>,
    /// Cross-validation chunks [first, end) of sample indices, in order;
    /// chunk k belongs to fold k mod `GapReport::folds`.
    pub folds: Vec<(usize, usize)>,
    /// Held-out (cross-validated) predictions of the base model.
    pub base_cv: Vec<f64>,
}

/// The diagnosis (GAP.md JSON contract: `verdict`, `noise_sd`, `where`,
/// `ranking`, plus supporting fields).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GapReport {
    /// An effect, or `none` (serialised as GAP.md's string).
    pub verdict: Verdict,
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
    pub confounded: Vec<Effect>,
    /// Effects that earn their parameters (significant likelihood ratio and
    /// cross-validated gain) but remove a systematic misfit below the
    /// materiality threshold: "detectable but immaterial". When every earning
    /// effect is immaterial the verdict is `none`.
    #[serde(default)]
    pub immaterial: Vec<Effect>,
    /// Set when the verdict's effect leaves the misfit significantly above
    /// the noise: the gap is only partly explained, by this much.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub partly_explained: Option<PartlyExplained>,
    /// Effects not detected, held at the ends of their plausible range: how
    /// far each would move the base parameters.
    #[serde(default)]
    pub undetectable: Vec<Undetectable>,
    /// One paragraph saying why (serialised as `summary`).
    #[serde(rename = "summary")]
    pub explanation: String,
    /// The explanation as a set of effects (serialised as `explanation`):
    /// the verdict first, then the effects that joined it by forward
    /// selection and survived the backward check, in the order of
    /// selection; empty when the verdict is `none`.
    #[serde(rename = "explanation", default)]
    pub explanation_set: Vec<SetMember>,
    /// Effects forward selection added that the backward check dropped
    /// (the others make them redundant).
    #[serde(default)]
    pub dropped: Vec<Effect>,
    /// What the explanation (or the base model, for `none`) leaves, and where.
    pub remainder: Remainder,
    pub base: BaseSummary,
    pub noise: NoiseEstimate,
    /// Samples, and blocks of the cross-validation.
    pub samples: usize,
    pub folds: usize,
    /// What limits the diagnosis on this record (a short record: the
    /// smallest misfit it can tell from the noise); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub caveat: Option<String>,
    pub plot: GapPlot,
}

impl GapPlot {
    /// The unit of the record's observable, from what drives it: a stretch
    /// or an amount of shear drives a homogeneous test whose observable is
    /// a nominal stress (`MPa`); a displacement or a position drives a tool
    /// whose observable is a force (`N`).
    pub fn data_unit(&self) -> &'static str {
        match self.drive_name.as_str() {
            "stretch" | "amount_of_shear" => "MPa",
            _ => "N",
        }
    }

    /// The unit of the horizontal axis (`s`, `mm` or `dimensionless`).
    pub fn axis_unit(&self) -> &'static str {
        match self.axis.as_str() {
            "time_s" => "s",
            "displacement_mm" | "position_mm" => "mm",
            _ => "dimensionless",
        }
    }
}

impl GapReport {
    /// The report as markdown (tables of windows and candidates), every
    /// quantity with its unit (the data's: MPa for a stress record, N for a
    /// force record).
    pub fn to_markdown(&self) -> String {
        let unit = self.plot.data_unit();
        let mut s = String::new();
        let _ = writeln!(s, "# Sim-to-real gap diagnosis\n");
        let _ = writeln!(s, "**Verdict: `{}`**", self.verdict);
        if !self.confounded.is_empty() {
            let _ = writeln!(
                s,
                "\n**Cannot be told apart** from `{}` with these data.",
                names(&self.confounded).join("`, `")
            );
        }
        if !self.immaterial.is_empty() {
            let _ = writeln!(
                s,
                "\n**Detectable but immaterial**: `{}`.",
                names(&self.immaterial).join("`, `")
            );
        }
        if let Some(p) = &self.partly_explained {
            let _ = writeln!(
                s,
                "\n**Only partly explained**: {:.0} % of the excess misfit removed, {:.2} -> {:.2} x noise.",
                100.0 * p.excess_explained,
                p.misfit_over_noise_before,
                p.misfit_over_noise_after
            );
        }
        let _ = writeln!(s, "\n{}\n", self.explanation);
        s.push_str(&self.explanation_markdown());
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
            "- noise SD (from second differences): {:.4e} {unit}; misfit RMS {:.4e} {unit} (RMS/noise {:.2}, z = {:.1}, p = {:.2e})",
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
                "| axis | from ({a}) | to ({a}) | misfit RMS ({unit}) | mean residual ({unit}) | significance |",
                a = self.plot.axis_unit()
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
            "| effect | parameters (physical units) | misfit RMS before -> after ({unit}) | held-out RMS before -> after ({unit}) | score statistic (p) | LR statistic (p) | dBIC AR(1) (dimensionless) | earns | identifiable |"
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
                    format!(" (confounded with {})", names(&r.confounded_with).join(", "))
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
        if !self.undetectable.is_empty() {
            let _ = writeln!(s, "\n## Effects the record cannot see\n");
            let _ = writeln!(
                s,
                "The base model refitted with each undetected effect held at the ends of its plausible \
                 range: the base parameters the record cannot be trusted for move this much.\n"
            );
            let _ = writeln!(
                s,
                "| effect | parameter | range (the parameter's unit) | base parameters at the ends (their units) | misfit RMS at the ends ({unit}) | p (LR vs base) |"
            );
            let _ = writeln!(s, "|---|---|---|---|---|---|");
            for u in &self.undetectable {
                let params: Vec<String> = u
                    .base_params
                    .iter()
                    .map(|(k, v)| {
                        format!(
                            "{k}: {:.4e} -> {:.4e} ({:+.1} %)",
                            v[0],
                            v[1],
                            100.0 * u.relative_shift[k]
                        )
                    })
                    .collect();
                let _ = writeln!(
                    s,
                    "| {} | {} | [{}, {}] | {} | {:.3e}, {:.3e} | {:.2}, {:.2} |",
                    u.effect,
                    u.param,
                    u.range[0],
                    u.range[1],
                    params.join("; "),
                    u.misfit[0],
                    u.misfit[1],
                    u.p_value[0],
                    u.p_value[1]
                );
            }
        }
        s
    }
}

impl GapReport {
    /// The explanation set and its remainder as a markdown section.
    fn explanation_markdown(&self) -> String {
        let unit = self.plot.data_unit();
        let mut s = String::new();
        let _ = writeln!(s, "## Explanation\n");
        if self.explanation_set.is_empty() {
            let _ = writeln!(s, "No effect explains the gap.\n");
        } else {
            let _ = writeln!(
                s,
                "| step | effect | parameters (physical units) | share of excess, marginal | share, dropped one out | misfit RMS after ({unit}) | held-out RMS after ({unit}) | confounded with |"
            );
            let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
            let pct = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.0} %", 100.0 * v));
            for (k, m) in self.explanation_set.iter().enumerate() {
                let _ = writeln!(
                    s,
                    "| {} | {} | {} | {} | {} | {:.3e} | {:.3e} | {} |",
                    k + 1,
                    m.effect,
                    m.params_text(),
                    pct(m.share_marginal),
                    pct(m.share_dropped),
                    m.misfit_after,
                    m.heldout_after,
                    names(&m.confounded_with).join(", ")
                );
            }
            let _ = writeln!(s);
        }
        if !self.dropped.is_empty() {
            let _ = writeln!(
                s,
                "Added and then dropped (the other members make it redundant): `{}`.\n",
                names(&self.dropped).join("`, `")
            );
        }
        let _ = writeln!(s, "**Remainder**: {}\n", self.remainder.note);
        s
    }
}

fn names(effects: &[Effect]) -> Vec<&'static str> {
    effects.iter().map(|e| e.name()).collect()
}
