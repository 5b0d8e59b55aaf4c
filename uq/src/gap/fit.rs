//! Fitting a model to the whole record or to its first part, through
//! palpate-inverse (Levenberg-Marquardt in the unbounded parameter space),
//! from several starting points.

use super::GapError;
use palpate_core::{ForwardModel, Loading, ParamSpec};
use palpate_inverse::{fit, DataSet, FitOptions, FitReport, Objective, ResidualKind};
use std::sync::Arc;

/// A fitted model.
#[derive(Debug, Clone)]
pub(crate) struct Fitted {
    /// Physical parameters at the optimum.
    pub theta: Vec<f64>,
    /// Sum of squared residuals over the fitted samples.
    pub sse: f64,
    /// Predictions over the whole loading history (fitted and held-out samples).
    pub predicted: Vec<f64>,
    /// The inverse crate's report (standard errors, correlations, identifiability).
    pub report: FitReport,
}

/// The first `n` samples of a history.
pub(crate) fn prefix(loading: &Loading, n: usize) -> Loading {
    Loading {
        drive_kind: loading.drive_kind,
        drive: loading.drive[..n].to_vec(),
        time: loading.time.as_ref().map(|t| t[..n].to_vec()),
    }
}

/// `x` moved strictly inside the bounds of `spec` (the unbounded transforms
/// send a bound to infinity): a value on or beyond a bound moves a tenth of
/// the way towards the starting value, or by a small relative step.
pub(crate) fn interior(spec: &ParamSpec, x: f64) -> f64 {
    let mut v = if x.is_finite() { x } else { spec.initial };
    if spec.lower.is_finite() && v <= spec.lower {
        let gap = (spec.initial - spec.lower).abs();
        v = spec.lower
            + if gap > 0.0 {
                0.1 * gap
            } else {
                1e-6 * spec.lower.abs().max(1.0)
            };
    }
    if spec.upper.is_finite() && v >= spec.upper {
        let gap = (spec.upper - spec.initial).abs();
        v = spec.upper
            - if gap > 0.0 {
                0.1 * gap
            } else {
                1e-6 * spec.upper.abs().max(1.0)
            };
    }
    v
}

/// Fits `model` to the first `n_fit` samples from each start (moved inside
/// the bounds; parameters in `fixed` held at their values) and keeps the
/// lowest SSE. Starts whose fit fails are skipped;
/// the error of the first is returned when all fail.
pub(crate) fn fit_from_starts(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    n_fit: usize,
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
) -> Result<Fitted, GapError> {
    let fit_loading = prefix(loading, n_fit);
    let set = DataSet::new(
        "data",
        model.clone(),
        fit_loading,
        observed[..n_fit].to_vec(),
    );
    let objective = Objective::new(vec![set], ResidualKind::Absolute, fixed).map_err(|source| {
        GapError::Fit {
            model: model.name(),
            source,
        }
    })?;
    let mut best: Option<FitReport> = None;
    let mut first_error = None;
    for start in starts {
        let start: Vec<f64> = model
            .space()
            .params
            .iter()
            .zip(start)
            .map(
                |(p, &x)| match fixed.iter().find(|(name, _)| *name == p.name) {
                    Some((_, v)) => *v,
                    None => interior(p, x),
                },
            )
            .collect();
        let options = FitOptions {
            start: Some(start),
            ..FitOptions::default()
        };
        match fit(&objective, &options) {
            Ok(report) => {
                if report.sse.is_finite() && best.as_ref().is_none_or(|b| report.sse < b.sse) {
                    best = Some(report);
                }
            }
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    let report = match (best, first_error) {
        (Some(r), _) => r,
        (None, Some(source)) => {
            return Err(GapError::Fit {
                model: model.name(),
                source,
            })
        }
        (None, None) => {
            return Err(GapError::InvalidOption {
                option: "starts",
                reason: "no starting point".into(),
            })
        }
    };
    let theta = report.theta();
    let predicted = model.predict(&theta, loading)?;
    let sse = predicted[..n_fit]
        .iter()
        .zip(&observed[..n_fit])
        .map(|(p, y)| (y - p).powi(2))
        .sum();
    Ok(Fitted {
        theta,
        sse,
        predicted,
        report,
    })
}
