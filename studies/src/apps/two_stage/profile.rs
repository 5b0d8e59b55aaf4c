//! The profile-likelihood intervals of a staged Q1 identification's polished
//! parameters ([`crate::apps::two_stage`]): each side refitted by LM with the
//! parameter held.

use crate::apps::two_stage::{lm_fit, StageResult, TwoStageOptions};
use palpate_inverse::{DataSet, Objective, ResidualKind};
use serde::Serialize;

/// The chi-square(1) 95 % quantile: the profile-likelihood threshold
/// (Venzon & Moolgavkar 1988), as `palpate_uq::gap`'s profiles.
pub const CHI2_1_95: f64 = 3.841_458_820_694_124;

/// A 95 % profile-likelihood interval: `min over the others SSE(x) / sigma^2`
/// within [`CHI2_1_95`] of its minimum. Each side is evaluated at
/// `estimate -/+ 2 SE` (the other parameters refitted by LM from the
/// optimum) and the crossing interpolated linearly in the signed root
/// `sqrt(delta chi2)` from the optimum (exact for a quadratic profile); a
/// side whose first point stays below the threshold is tried at 4 SE, and
/// is `None` (not bounded) if it still does, or if the point leaves the
/// parameter's bounds or fails.
#[derive(Debug, Clone, Serialize)]
pub struct Profile {
    pub param: String,
    pub estimate: f64,
    pub standard_error: Option<f64>,
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    /// (value, delta chi2) evaluated.
    pub points: Vec<(f64, f64)>,
    pub fe_runs: usize,
}

/// The profile of each free parameter of the polish ([`Profile`]).
pub(crate) fn profiles(
    set: &DataSet,
    polish: &StageResult,
    options: &TwoStageOptions,
) -> Vec<Profile> {
    let report = &polish.fit;
    let n = report.n_residuals as f64;
    let p = report.free.len() as f64;
    let sigma2 = report.sse / (n - p).max(1.0);
    let mut lm = options.lm;
    lm.max_iterations = 5;
    report
        .parameters
        .iter()
        .filter(|e| !e.fixed)
        .map(|e| {
            let mut prof = Profile {
                param: e.name.clone(),
                estimate: e.value,
                standard_error: e.standard_error,
                lower: None,
                upper: None,
                points: Vec::new(),
                fe_runs: 0,
            };
            let Some(se) = e.standard_error.filter(|s| *s > 0.0) else {
                return prof;
            };
            for side in [-1.0, 1.0] {
                let mut end = None;
                for m in [2.0, 4.0] {
                    let x = e.value + side * m * se;
                    if !(x > e.lower && x < e.upper) {
                        break;
                    }
                    let Ok(objective) = Objective::new(
                        vec![set.clone()],
                        ResidualKind::Absolute,
                        &[(e.name.clone(), x)],
                    ) else {
                        break;
                    };
                    let mut start = polish.theta.clone();
                    let k = report
                        .parameters
                        .iter()
                        .position(|q| q.name == e.name)
                        .expect("a parameter of the fit");
                    start[k] = x;
                    let Ok((r, _)) = lm_fit(&objective, start, options, lm) else {
                        break;
                    };
                    prof.fe_runs += r.evaluations;
                    let d = ((r.sse - report.sse) / sigma2).max(0.0);
                    prof.points.push((x, d));
                    if d >= CHI2_1_95 {
                        // linear in sqrt(delta chi2) from 0 at the estimate
                        end = Some(e.value + side * m * se * (CHI2_1_95 / d).sqrt());
                        break;
                    }
                }
                if side < 0.0 {
                    prof.lower = end;
                } else {
                    prof.upper = end;
                }
            }
            prof
        })
        .collect()
}
