//! Profile-likelihood intervals of an effect's parameters: the identifiability
//! check that does not rest on the local curvature at the optimum (which
//! says nothing when the response saturates, as friction does once the
//! contact sticks).

use super::fit::{fit_from_starts, interior, scale_moduli};
use super::structure::chi2_isf;
use palpate_core::{ForwardModel, Loading};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A 95 % profile-likelihood interval of one parameter: the values x at
/// which min over the other parameters of SSE(x) / sigma^2 stays within
/// the chi2(1) 95 % quantile (3.84) of its minimum (Venzon & Moolgavkar
/// 1988; Raue et al. 2009 for its use as an identifiability test). A side
/// that reaches the parameter's bound (or the end of the explored range)
/// without crossing the threshold is `None`: the data do not bound the
/// parameter on that side.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileInterval {
    pub param: String,
    pub estimate: f64,
    pub lower: Option<f64>,
    pub upper: Option<f64>,
    /// Explored points: (value, (SSE - SSE_min) / sigma^2).
    pub points: Vec<(f64, f64)>,
    /// Whether the other parameters were refitted by a full
    /// Levenberg-Marquardt fit (`false`: only the moduli rescaled by their
    /// least-squares factor, exact for laws linear in one modulus such as
    /// neo-Hookean under prescribed displacement, used for expensive models).
    pub full_refit: bool,
}

impl ProfileInterval {
    /// `[lower, upper]` with unbounded sides spelled out.
    pub fn describe(&self) -> String {
        let side = |v: Option<f64>, what: &str| match v {
            Some(x) => format!("{x:.4}"),
            None => format!("not bounded {what}"),
        };
        format!(
            "{} 95 % profile interval [{}, {}]",
            self.param,
            side(self.lower, "below"),
            side(self.upper, "above")
        )
    }

    /// Whether both sides are bounded.
    pub fn bounded(&self) -> bool {
        self.lower.is_some() && self.upper.is_some()
    }
}

/// One side of a profile walk: its points (value, delta chi2) and where it
/// crossed the threshold.
type Side = (Vec<(f64, f64)>, Option<f64>);

/// Minimum SSE with parameter `j` fixed at `x`.
#[allow(clippy::too_many_arguments)]
fn profile_sse(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    theta: &[f64],
    j: usize,
    x: f64,
    expensive: bool,
) -> Option<f64> {
    let specs = &model.space().params;
    let mut start = theta.to_vec();
    start[j] = x;
    if expensive {
        let f = model.predict(&start, loading).ok()?;
        // the moduli other than theta_j rescaled (theta_j itself is held)
        let others_scaled = specs
            .iter()
            .enumerate()
            .any(|(k, s)| k != j && s.is_modulus());
        let a = if others_scaled {
            scale_moduli(specs, &start, &f, observed).map_or(1.0, |(a, _)| a)
        } else {
            1.0
        };
        Some(
            f.iter()
                .zip(observed)
                .map(|(v, y)| (y - a * v).powi(2))
                .sum(),
        )
    } else {
        let fixed = vec![(specs[j].name.clone(), x)];
        let start: Vec<f64> = start
            .iter()
            .zip(specs)
            .enumerate()
            .map(|(k, (v, s))| if k == j { *v } else { interior(s, *v) })
            .collect();
        fit_from_starts(model, loading, observed, None, &[start], &fixed, false)
            .ok()
            .map(|f| f.sse)
    }
}

/// The 95 % profile interval of parameter `j` of `model` fitted at `theta`
/// (SSE `sse_min`, noise `sigma`). Walks away from the estimate in the
/// parameter's unbounded coordinate (log, logit or identity; ParamSpec) by
/// steps 0.125, 0.25, 0.5, ... until the profile crosses the threshold,
/// the bound is reached (for an expensive model: within 1 % of the range
/// from it) or 8 steps are made, and interpolates the crossing linearly in
/// sqrt(delta chi2) (exact for a quadratic profile). The two sides are
/// walked in parallel.
#[allow(clippy::too_many_arguments)]
pub(crate) fn profile_interval(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    theta: &[f64],
    sse_min: f64,
    sigma: f64,
    j: usize,
    expensive: bool,
) -> ProfileInterval {
    let spec = model.space().params[j].clone();
    let threshold = chi2_isf(0.05, 1.0);
    let x0 = theta[j];
    let z0 = spec.to_unbounded(x0);
    let unit = if spec.transform() == palpate_core::Transform::Identity {
        x0.abs().max(1e-3)
    } else {
        1.0
    };
    // The two sides are independent walks: run in parallel (for an expensive
    // model each point is a solve).
    let sides: Vec<Side> = [-1.0f64, 1.0]
        .par_iter()
        .map(|dir| {
            let mut points = Vec::new();
            let mut last = (x0, 0.0f64);
            let mut dz = 0.125 * unit;
            for _ in 0..8 {
                let x = spec.from_unbounded(z0 + dir * dz);
                if !x.is_finite() || x == last.0 || x <= spec.lower || x >= spec.upper {
                    break;
                }
                // an expensive model within 1 % of the range from a finite
                // bound: the bound is reached (the side is not bounded by
                // the data); further doublings only creep closer to it, a
                // solve each
                let range = spec.upper - spec.lower;
                let near_bound = expensive
                    && range.is_finite()
                    && ((x - spec.lower) < 0.01 * range || (spec.upper - x) < 0.01 * range);
                if near_bound && !points.is_empty() {
                    break;
                }
                let Some(sse) = profile_sse(model, loading, observed, theta, j, x, expensive)
                else {
                    break;
                };
                let d = ((sse - sse_min) / (sigma * sigma)).max(0.0);
                points.push((x, d));
                if d >= threshold {
                    let (s0, s1) = (last.1.sqrt(), d.sqrt());
                    let t = if s1 > s0 {
                        (threshold.sqrt() - s0) / (s1 - s0)
                    } else {
                        1.0
                    };
                    return (points, Some(last.0 + t * (x - last.0)));
                }
                last = (x, d);
                dz *= 2.0;
            }
            (points, None)
        })
        .collect();
    let ends = [sides[0].1, sides[1].1];
    let mut points: Vec<(f64, f64)> = sides.into_iter().flat_map(|(p, _)| p).collect();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    ProfileInterval {
        param: spec.name.clone(),
        estimate: x0,
        lower: ends[0],
        upper: ends[1],
        points,
        full_refit: !expensive,
    }
}
