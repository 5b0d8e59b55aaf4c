//! The verdict: an effect, or none; and the decision that reaches it from
//! the ranking, the significance of the gap and the practical size of each
//! effect.

use super::report::RankedEffect;
use palpate_core::Effect;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// The diagnosis' answer: the effect that explains the gap, or none.
/// Serialised as GAP.md's `verdict` string: the effect's canonical name, or
/// `"none"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// No significant gap, no effect that earns its parameters, or only
    /// effects too small to matter (then listed in `GapReport::immaterial`).
    None,
    /// The effect that explains the gap.
    Effect(Effect),
}

impl Verdict {
    /// GAP.md's spelling.
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::None => "none",
            Verdict::Effect(e) => e.name(),
        }
    }

    /// The effect, if any.
    pub fn effect(&self) -> Option<Effect> {
        match self {
            Verdict::None => None,
            Verdict::Effect(e) => Some(*e),
        }
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.as_str())
    }
}

impl PartialEq<str> for Verdict {
    fn eq(&self, other: &str) -> bool {
        self.as_str() == other
    }
}

impl PartialEq<&str> for Verdict {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

impl Serialize for Verdict {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

impl<'de> Deserialize<'de> for Verdict {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        if s == "none" {
            return Ok(Verdict::None);
        }
        s.parse::<Effect>()
            .map(Verdict::Effect)
            .map_err(serde::de::Error::custom)
    }
}

/// The decision and its wording.
pub(crate) struct Decision {
    pub verdict: Verdict,
    /// Effects the data cannot tell apart from the verdict.
    pub confounded: Vec<Effect>,
    /// Effects that earn their parameters but remove too little misfit to matter.
    pub immaterial: Vec<Effect>,
    /// For a verdict that leaves a significant misfit: how much it explains.
    pub partly: Option<PartlyExplained>,
    pub explanation: String,
}

/// A verdict that leaves the misfit significantly above the noise: the gap
/// is only partly explained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PartlyExplained {
    /// Share of the excess mean-square misfit (above the noise variance) removed.
    pub excess_explained: f64,
    /// RMS misfit / noise SD before and after the effect.
    pub misfit_over_noise_before: f64,
    pub misfit_over_noise_after: f64,
    /// p-value of the misfit test after the effect (below alpha: still a gap).
    pub misfit_p_after: f64,
}

/// Decides from the ranked candidates (best first): `none` when the gap is
/// not significant; the first effect that earns its parameters and is
/// material; `none` with the earning effects listed as immaterial when none
/// is material; `none` when nothing earns. A verdict whose enriched fit
/// still fails the misfit test at `alpha` is reported as a partial
/// explanation with its share.
pub(crate) fn decide(
    ranking: &[RankedEffect],
    gap_significant: bool,
    reason: &str,
    sigma: f64,
    alpha: f64,
    materiality: f64,
) -> Decision {
    let earning: Vec<&RankedEffect> = ranking.iter().filter(|r| r.earns).collect();
    let material = earning.iter().find(|r| r.practical.material);
    let immaterial: Vec<Effect> = earning
        .iter()
        .filter(|r| !r.practical.material)
        .map(|r| r.effect)
        .collect();
    let none = |explanation: String, immaterial: Vec<Effect>| Decision {
        verdict: Verdict::None,
        confounded: Vec::new(),
        immaterial,
        partly: None,
        explanation,
    };
    if !gap_significant {
        return none(
            format!("No significant gap: the base misfit is {reason}."),
            immaterial,
        );
    }
    let Some(best) = material else {
        if earning.is_empty() {
            return none(
                format!(
                    "The base model misses the data ({reason}), but no candidate effect earns its parameters \
                     (significant likelihood ratio and cross-validated gain); the gap is left unexplained."
                ),
                immaterial,
            );
        }
        let sizes: Vec<String> = earning
            .iter()
            .map(|r| {
                format!(
                    "`{}` ({:.2} -> {:.2} x noise, a systematic component of {:.2} noise SD)",
                    r.effect,
                    r.practical.misfit_over_noise_before,
                    r.practical.misfit_over_noise_after,
                    r.practical.removed_over_noise
                )
            })
            .collect();
        return none(
            format!(
                "The gap is detectable but immaterial: the base model misses the data ({reason}), and {} \
                 earn their parameters, but none removes a systematic misfit of {materiality:.2} noise SD \
                 or more (the materiality threshold).",
                sizes.join(", ")
            ),
            immaterial,
        );
    };
    let mut text = format!(
        "The base model misses the data ({reason}). Adding `{}`{} brings the misfit from {:.3e} to {:.3e} \
         (noise {:.3e}; {:.2} -> {:.2} x noise) and the held-out misfit from {:.3e} to {:.3e}.",
        best.effect,
        best.form
            .as_ref()
            .map_or(String::new(), |f| format!(" (as {f})")),
        best.misfit_before,
        best.misfit_after,
        sigma,
        best.practical.misfit_over_noise_before,
        best.practical.misfit_over_noise_after,
        best.heldout_before,
        best.heldout_after
    );
    let partly = (best.after.misfit_p < alpha).then(|| PartlyExplained {
        excess_explained: best.practical.excess_explained.unwrap_or(0.0),
        misfit_over_noise_before: best.practical.misfit_over_noise_before,
        misfit_over_noise_after: best.practical.misfit_over_noise_after,
        misfit_p_after: best.after.misfit_p,
    });
    if let Some(p) = &partly {
        text.push_str(&format!(
            " The gap is only partly explained: the effect removes {:.0} % of the excess misfit and \
             leaves {:.2} x noise (p = {:.1e}); another effect, or several together, account for the rest.",
            100.0 * p.excess_explained,
            p.misfit_over_noise_after,
            p.misfit_p_after
        ));
    }
    if !best.confounded_with.is_empty() {
        let names: Vec<&str> = best.confounded_with.iter().map(|e| e.name()).collect();
        text.push_str(&format!(
            " It cannot be told apart from {} with these data.",
            names.join(", ")
        ));
    }
    if !immaterial.is_empty() {
        let names: Vec<&str> = immaterial.iter().map(|e| e.name()).collect();
        text.push_str(&format!(
            " Detectable but immaterial: {}.",
            names.join(", ")
        ));
    }
    Decision {
        verdict: Verdict::Effect(best.effect),
        confounded: best.confounded_with.clone(),
        immaterial,
        partly,
        explanation: text,
    }
}
