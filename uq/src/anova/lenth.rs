//! Lenth's pseudo standard error for unreplicated two-level designs.
//!
//! From the m effect estimates `c_j` (Lenth 1989, *Quick and easy analysis of
//! unreplicated factorials*, Technometrics 31:469-473):
//!
//! ```text
//! s0  = 1.5 median |c_j|
//! PSE = 1.5 median { |c_j| : |c_j| < 2.5 s0 }
//! d   = m / 3                                  (degrees of freedom)
//! ME  = t_{1 - alpha/2; d} PSE                 (margin of error)
//! SME = t_{gamma; d} PSE, gamma = (1 + (1 - alpha)^{1/m}) / 2
//!                                              (simultaneous margin of error)
//! ```
//!
//! Quantiles of Student's t with fractional d come from `statrs`.

use super::AnovaError;
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Lenth's PSE and margins of error.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Lenth {
    /// Number of effects.
    pub m: usize,
    pub s0: f64,
    pub pse: f64,
    /// Degrees of freedom m/3.
    pub df: f64,
    pub alpha: f64,
    pub t_me: f64,
    pub me: f64,
    pub gamma: f64,
    pub t_sme: f64,
    pub sme: f64,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Lenth's method on `effects` at level `alpha` (usually 0.05). Needs at
/// least 3 effects (d = m/3 >= 1) and a non-zero PSE.
pub fn lenth(effects: &[f64], alpha: f64) -> Result<Lenth, AnovaError> {
    let m = effects.len();
    if m < 3 {
        return Err(AnovaError::TooFewEffects { needed: 3, got: m });
    }
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(AnovaError::BadAlpha { alpha });
    }
    if let Some(index) = effects.iter().position(|v| !v.is_finite()) {
        return Err(AnovaError::NotFinite { index });
    }
    let abs: Vec<f64> = effects.iter().map(|c| c.abs()).collect();
    let s0 = 1.5 * median(abs.clone());
    let small: Vec<f64> = abs.into_iter().filter(|&a| a < 2.5 * s0).collect();
    if small.is_empty() || s0 == 0.0 {
        return Err(AnovaError::ZeroPse);
    }
    let pse = 1.5 * median(small);
    if pse == 0.0 {
        return Err(AnovaError::ZeroPse);
    }
    let df = m as f64 / 3.0;
    let t = StudentsT::new(0.0, 1.0, df)
        .map_err(|_| AnovaError::TooFewEffects { needed: 3, got: m })?;
    let t_me = t.inverse_cdf(1.0 - alpha / 2.0);
    let gamma = 0.5 * (1.0 + (1.0 - alpha).powf(1.0 / m as f64));
    let t_sme = t.inverse_cdf(gamma);
    Ok(Lenth {
        m,
        s0,
        pse,
        df,
        alpha,
        t_me,
        me: t_me * pse,
        gamma,
        t_sme,
        sme: t_sme * pse,
    })
}
