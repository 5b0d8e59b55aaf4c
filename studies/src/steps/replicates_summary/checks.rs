//! The residual checks of an ANOVA: normality and equal variances.

use palpate_uq::anova::Analysis;
use palpate_uq::stats::PBound;
use serde::Serialize;

/// The residual checks of one scale at `alpha`: normality (Ryan-Joiner and
/// Anderson-Darling) and equal variances across the cells (Bartlett and
/// Levene); a check passes when its p-value is at least `alpha`, and one
/// that is undefined does not pass.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(super) struct ResidualChecks {
    pub(super) response: String,
    pub(super) ryan_joiner_p: Option<f64>,
    pub(super) anderson_darling_p: Option<f64>,
    pub(super) bartlett_p: Option<f64>,
    pub(super) levene_p: Option<f64>,
    pub(super) ryan_joiner_pass: bool,
    pub(super) anderson_darling_pass: bool,
    pub(super) bartlett_pass: bool,
    pub(super) levene_pass: bool,
    pub(super) normal: bool,
    pub(super) equal_variances: bool,
}

impl ResidualChecks {
    /// The checks that do not pass.
    pub(super) fn failed(&self) -> Vec<&'static str> {
        [
            ("Ryan-Joiner", self.ryan_joiner_pass),
            ("Anderson-Darling", self.anderson_darling_pass),
            ("Bartlett", self.bartlett_pass),
            ("Levene", self.levene_pass),
        ]
        .into_iter()
        .filter(|(_, pass)| !pass)
        .map(|(n, _)| n)
        .collect()
    }
}

pub(super) fn checks(a: &Analysis, alpha: f64) -> ResidualChecks {
    // Ryan-Joiner's p is a bound outside its table (< 0.01 or > 0.10)
    let rj = a.ryan_joiner.as_ref().map(|t| match t.p_bound {
        PBound::Below => t.p.min(alpha * (1.0 - 1e-12)),
        _ => t.p,
    });
    let ad = a.anderson_darling.as_ref().map(|t| t.p);
    let b = a.bartlett.as_ref().map(|t| t.p);
    let l = a.levene.as_ref().map(|t| t.p);
    let pass = |p: Option<f64>| p.is_some_and(|p| p >= alpha);
    ResidualChecks {
        response: a.table.response.clone(),
        ryan_joiner_p: a.ryan_joiner.as_ref().map(|t| t.p),
        anderson_darling_p: ad,
        bartlett_p: b,
        levene_p: l,
        ryan_joiner_pass: pass(rj),
        anderson_darling_pass: pass(ad),
        bartlett_pass: pass(b),
        levene_pass: pass(l),
        normal: pass(rj) && pass(ad),
        equal_variances: pass(b) && pass(l),
    }
}
