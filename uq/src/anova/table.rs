//! The ANOVA table of a factorial model, from its regression formulation.
//!
//! The model is `y = b0 + sum_terms X_t b_t + e`, each factor coded with L - 1
//! sum-to-zero contrast columns and each interaction by the products of its
//! factors' columns ([`FactorColumn`]). Columns enter in hierarchical term
//! order (main effects, then two-factor interactions, ...). With the
//! sequential QR `X = Q R` (aliased columns dropped), the sequential
//! ("Type I") sum of squares of a term is the squared length of the part of
//! `y` its columns explain beyond all earlier columns:
//!
//! `SS_t = sum_{j in t} (q_j^T y)^2`,  `df_t` = number of its non-aliased columns,
//!
//! and `SS_E = |y - Q Q^T y|^2` with `df_E = n - rank(X)`. Then
//! `MS = SS/df`, `F_t = MS_t / MS_E` with p from F(df_t, df_E),
//! `eta^2_t = SS_t / SS_T` (`SS_T = sum (y - ybar)^2`),
//! `partial eta^2_t = SS_t / (SS_t + SS_E)`, `R^2 = 1 - SS_E/SS_T`,
//! `adj R^2 = 1 - (SS_E/df_E) / (SS_T/(n - 1))`
//! (Montgomery, *Design and Analysis of Experiments*, 8th ed., ch. 5 and
//! 10; Cohen 1973 for partial eta^2).
//!
//! Type I equals Type III when the design is balanced (equal replication in
//! every cell): the contrast columns of different terms are then orthogonal,
//! so a term's SS does not depend on which terms precede it. On unbalanced
//! data the table is still the sequential one (as statsmodels' `anova_lm(typ=1)`
//! and R's `anova`); [`AnovaTable::balanced`] says which case applies.

use super::coding::{cells, check_factors, term_columns};
use super::qr::SequentialQr;
use super::{hierarchical_terms, AnovaError, FactorColumn, Term};
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, FisherSnedecor};

/// One row of the table (a main effect or an interaction).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TermRow {
    /// Factor names joined by `:` (`material`, `material:space`).
    pub name: String,
    #[serde(skip)]
    pub term: Term,
    /// Degrees of freedom (non-aliased columns; 0 when fully aliased).
    pub df: usize,
    pub ss: f64,
    pub ms: Option<f64>,
    /// F ratio; `None` when there is no error degree of freedom.
    pub f: Option<f64>,
    pub p: Option<f64>,
    pub eta_sq: f64,
    pub partial_eta_sq: Option<f64>,
    /// Coefficient of each non-aliased column of the term (sum-to-zero coding).
    pub coefficients: Vec<f64>,
    /// Standard error of each coefficient (`None` without error df).
    pub coefficient_se: Vec<Option<f64>>,
}

/// The error (residual) row.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Residual {
    pub df: usize,
    pub ss: f64,
    pub ms: Option<f64>,
}

/// The corrected total row.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Total {
    pub df: usize,
    pub ss: f64,
}

/// A complete ANOVA table with the fit behind it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AnovaTable {
    pub response: String,
    pub factors: Vec<String>,
    pub terms: Vec<TermRow>,
    pub residual: Residual,
    pub total: Total,
    pub r2: f64,
    /// `None` without error degrees of freedom.
    pub adj_r2: Option<f64>,
    /// Intercept (the grand mean of cell means for balanced designs).
    pub intercept: f64,
    /// True when every combination of factor levels occurs equally often.
    pub balanced: bool,
    pub fitted: Vec<f64>,
    pub residuals: Vec<f64>,
}

impl AnovaTable {
    /// The row of a term by name.
    pub fn term(&self, name: &str) -> Option<&TermRow> {
        self.terms.iter().find(|t| t.name == name)
    }
}

/// ANOVA of `response` on `factors` with all interactions up to `max_order`
/// (use the number of factors for the full model).
pub fn anova(
    response_name: &str,
    factors: &[FactorColumn],
    y: &[f64],
    max_order: usize,
) -> Result<AnovaTable, AnovaError> {
    let n = y.len();
    check_factors(factors, n)?;
    if let Some(index) = y.iter().position(|v| !v.is_finite()) {
        return Err(AnovaError::NotFinite { index });
    }
    if n < 2 {
        return Err(AnovaError::TooFewRuns { needed: 2, got: n });
    }
    let mean = y.iter().sum::<f64>() / n as f64;
    let ss_total: f64 = y.iter().map(|v| (v - mean) * (v - mean)).sum();
    if ss_total <= 0.0 {
        return Err(AnovaError::ConstantResponse);
    }
    let terms = hierarchical_terms(factors.len(), max_order.max(1));
    let mut columns = vec![vec![1.0; n]];
    let mut owner = vec![usize::MAX];
    for (t, term) in terms.iter().enumerate() {
        for c in term_columns(factors, term) {
            columns.push(c);
            owner.push(t);
        }
    }
    let qr = SequentialQr::new(&columns, y);
    let rank = qr.kept.len();
    let df_e = n - rank;
    let ss_e: f64 = qr.residual.iter().map(|r| r * r).sum();
    let ms_e = (df_e > 0).then(|| ss_e / df_e as f64);
    let beta = qr.coefficients();
    let unscaled = qr.unscaled_variances();
    let fisher = |df: usize| FisherSnedecor::new(df as f64, df_e as f64).ok();
    let names: Vec<String> = factors.iter().map(|f| f.name.clone()).collect();
    let mut rows = Vec::with_capacity(terms.len());
    for (t, term) in terms.iter().enumerate() {
        let idx: Vec<usize> = (0..rank).filter(|&k| owner[qr.kept[k]] == t).collect();
        let df = idx.len();
        let ss: f64 = idx.iter().map(|&k| qr.qty[k] * qr.qty[k]).sum();
        let ms = (df > 0).then(|| ss / df as f64);
        let f = match (ms, ms_e) {
            (Some(ms), Some(me)) if me > 0.0 => Some(ms / me),
            _ => None,
        };
        let p = f.and_then(|f| fisher(df).map(|d| d.sf(f)));
        rows.push(TermRow {
            name: term.name(&names),
            term: term.clone(),
            df,
            ss,
            ms,
            f,
            p,
            eta_sq: ss / ss_total,
            partial_eta_sq: (df_e > 0 && ss + ss_e > 0.0).then(|| ss / (ss + ss_e)),
            coefficients: idx.iter().map(|&k| beta[k]).collect(),
            coefficient_se: idx
                .iter()
                .map(|&k| ms_e.map(|me| (me * unscaled[k]).sqrt()))
                .collect(),
        });
    }
    let groups = cells(factors);
    let full_cells: usize = factors.iter().map(|f| f.levels.len()).product();
    let balanced = groups.len() == full_cells && groups.iter().all(|g| g.len() == groups[0].len());
    let residuals = qr.residual.clone();
    let fitted: Vec<f64> = y.iter().zip(&residuals).map(|(y, r)| y - r).collect();
    Ok(AnovaTable {
        response: response_name.to_string(),
        factors: names,
        terms: rows,
        residual: Residual {
            df: df_e,
            ss: ss_e,
            ms: ms_e,
        },
        total: Total {
            df: n - 1,
            ss: ss_total,
        },
        r2: 1.0 - ss_e / ss_total,
        adj_r2: ms_e.map(|me| 1.0 - me / (ss_total / (n - 1) as f64)),
        intercept: if qr.kept.first() == Some(&0) {
            beta[0]
        } else {
            mean
        },
        balanced,
        fitted,
        residuals,
    })
}
