//! Residual checks for designed experiments: normality (Ryan-Joiner,
//! Anderson-Darling) and equality of variances across cells (Bartlett,
//! Levene / Brown-Forsythe).
//!
//! Distributions (normal, chi-square, F) come from `statrs`.

mod anderson_darling;
mod bartlett;
mod error;
mod levene;
mod normal_scores;
mod ryan_joiner;

pub use anderson_darling::{anderson_darling, AndersonDarling};
pub use bartlett::{bartlett, Bartlett};
pub use error::StatsError;
pub use levene::{levene, Levene, LeveneCenter};
pub use normal_scores::blom_scores;
pub use ryan_joiner::{ryan_joiner, ryan_joiner_critical, ryan_joiner_p, PBound, RyanJoiner};

/// Sample mean and sample variance (divisor n - 1), two-pass.
pub(crate) fn mean_var(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
    (m, v)
}

/// Checks that every value is finite; `what` names the input in the error.
pub(crate) fn check_finite(x: &[f64], what: &'static str) -> Result<(), StatsError> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(StatsError::NotFinite { what, index }),
        None => Ok(()),
    }
}
