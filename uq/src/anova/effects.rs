//! Standardised effects and the Pareto chart.
//!
//! With error degrees of freedom, the standardised effect of a one-degree-of-
//! freedom term is its t value `b / se(b)` (Minitab's "standardized effect";
//! for two-level factors twice the coefficient is the effect, and `t^2 = F`
//! on balanced designs). A term with more degrees of freedom has no single
//! effect; it is shown as the |t| with the same p-value,
//! `t_{df_E}^{-1}(1 - p/2)`, so every bar is compared with the same reference
//! line `t_{1 - alpha/2; df_E}`.
//!
//! Without error degrees of freedom (an unreplicated saturated two-level
//! design), the standardised effect is the effect divided by Lenth's PSE and
//! the reference line is `ME / PSE = t_{1 - alpha/2; m/3}` ([`lenth`]).

use super::{lenth, AnovaError, AnovaTable, Lenth};
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, StudentsT};

/// One term's standardised effect.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StandardisedEffect {
    pub term: String,
    /// Effect (twice the coefficient) for a one-df term of two-level factors.
    pub effect: Option<f64>,
    /// Coefficient for a one-df term.
    pub coefficient: Option<f64>,
    /// Signed t value (one df) or |t| with the same p (several df), or effect / PSE.
    pub standardised: f64,
}

/// Standardised effects sorted by decreasing magnitude, with the reference line.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Pareto {
    pub effects: Vec<StandardisedEffect>,
    /// Where the reference line is drawn (in standardised units).
    pub reference: f64,
    /// How the effects were standardised: `"t"` or `"lenth"`.
    pub method: String,
    pub alpha: f64,
    pub lenth: Option<Lenth>,
}

/// Standardised effects of every estimable term of `table` at level `alpha`.
pub fn standardised_effects(
    table: &AnovaTable,
    alpha: f64,
    two_level: &[bool],
) -> Result<Pareto, AnovaError> {
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(AnovaError::BadAlpha { alpha });
    }
    let df_e = table.residual.df;
    let rows: Vec<_> = table.terms.iter().filter(|t| t.df > 0).collect();
    let is_two_level = |r: &super::TermRow| {
        r.term
            .factors
            .iter()
            .all(|&f| two_level.get(f).copied().unwrap_or(false))
    };
    let mut effects = Vec::with_capacity(rows.len());
    let (reference, method, lenth_result) =
        if df_e > 0 && table.residual.ms.is_some_and(|m| m > 0.0) {
            let t = StudentsT::new(0.0, 1.0, df_e as f64)
                .map_err(|_| AnovaError::TooFewRuns { needed: 1, got: 0 })?;
            for r in rows {
                let (coefficient, effect, standardised) = if r.df == 1 {
                    let b = r.coefficients[0];
                    let se = r.coefficient_se[0].unwrap_or(f64::NAN);
                    (Some(b), is_two_level(r).then_some(2.0 * b), b / se)
                } else {
                    let p = r.p.unwrap_or(1.0);
                    (None, None, t.inverse_cdf(1.0 - p / 2.0))
                };
                effects.push(StandardisedEffect {
                    term: r.name.clone(),
                    effect,
                    coefficient,
                    standardised,
                });
            }
            (t.inverse_cdf(1.0 - alpha / 2.0), "t", None)
        } else {
            let c: Vec<f64> = rows
                .iter()
                .filter(|r| r.df == 1)
                .map(|r| 2.0 * r.coefficients[0])
                .collect();
            if c.len() != rows.len() {
                return Err(AnovaError::TooFewRuns {
                    needed: table.total.df + 2,
                    got: table.total.df + 1,
                });
            }
            let l = lenth(&c, alpha)?;
            for (r, &e) in rows.iter().zip(&c) {
                effects.push(StandardisedEffect {
                    term: r.name.clone(),
                    effect: Some(e),
                    coefficient: Some(r.coefficients[0]),
                    standardised: e / l.pse,
                });
            }
            (l.t_me, "lenth", Some(l))
        };
    effects.sort_by(|a, b| b.standardised.abs().total_cmp(&a.standardised.abs()));
    Ok(Pareto {
        effects,
        reference,
        method: method.into(),
        alpha,
        lenth: lenth_result,
    })
}
