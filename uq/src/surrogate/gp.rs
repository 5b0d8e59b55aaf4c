//! Gaussian-process regression of one scalar on the unit cube.
//!
//! Kernel: squared exponential with one length scale per input and a
//! nugget g (relative to the signal variance s^2),
//!
//!   k(u, u') = s^2 [ exp(-1/2 sum_i (u_i - u'_i)^2 / l_i^2) + g delta(u, u') ],
//!
//! zero prior mean (the surrogate feeds it centred coefficients). With
//! R the correlation matrix (+ g I), s^2 is profiled out,
//! s^2 = y^T R^-1 y / n, and the length scales and nugget maximise the
//! profile log marginal likelihood
//!
//!   -n/2 ln(y^T R^-1 y / n) - 1/2 ln det R
//!
//! (Rasmussen & Williams 2006, *Gaussian Processes for Machine Learning*,
//! eqs. 2.30 and 5.8). The search is a log grid: the best isotropic length
//! first, then coordinate sweeps, each length over the grid with the others
//! held, then the nugget. A grid rather than a gradient optimiser (argmin)
//! because the profile likelihood of a few dozen smooth FE runs is flat along
//! long ridges where gradient steps wander; the grid is cheap (one n x n
//! Cholesky per point) and deterministic.
//!
//! Prediction is the posterior mean f(u) = k(u)^T R^-1 y: one kernel vector
//! and a dot product, O(n d).

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// A fitted scalar GP.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Gp {
    /// Training inputs in the unit cube.
    inputs: Vec<Vec<f64>>,
    /// Length scales (unit-cube units).
    pub length_scales: Vec<f64>,
    /// Nugget relative to the signal variance.
    pub nugget: f64,
    /// R^-1 y.
    weights: Vec<f64>,
}

const LENGTHS: usize = 25;
const NUGGETS: [f64; 5] = [1e-10, 1e-8, 1e-6, 1e-4, 1e-2];

fn correlation(a: &[f64], b: &[f64], l: &[f64]) -> f64 {
    let s: f64 = a
        .iter()
        .zip(b)
        .zip(l)
        .map(|((x, y), l)| (x - y) * (x - y) / (l * l))
        .sum();
    (-0.5 * s).exp()
}

fn matrix(u: &[Vec<f64>], l: &[f64], nugget: f64) -> DMatrix<f64> {
    let n = u.len();
    DMatrix::from_fn(n, n, |i, j| {
        correlation(&u[i], &u[j], l) + if i == j { nugget } else { 0.0 }
    })
}

/// Profile log marginal likelihood, `None` when R is not positive definite.
fn profile_lml(u: &[Vec<f64>], y: &DVector<f64>, l: &[f64], nugget: f64) -> Option<f64> {
    let n = u.len() as f64;
    let ch = matrix(u, l, nugget).cholesky()?;
    let alpha = ch.solve(y);
    let q = (y.dot(&alpha) / n).max(1e-300);
    let log_det: f64 = 2.0 * ch.l().diagonal().iter().map(|d| d.ln()).sum::<f64>();
    let v = -0.5 * n * q.ln() - 0.5 * log_det;
    v.is_finite().then_some(v)
}

impl Gp {
    /// Fits `y[i]` at unit-cube `inputs[i]`; `None` when no kernel on the
    /// grid gives a positive-definite matrix (e.g. repeated inputs with a
    /// tiny nugget never happen here: the largest nugget always works).
    pub fn fit(inputs: &[Vec<f64>], y: &[f64]) -> Option<Gp> {
        let d = inputs.first().map_or(0, Vec::len);
        let yv = DVector::from_column_slice(y);
        // 0.03 .. 10 in unit-cube units, log-spaced.
        let grid: Vec<f64> = (0..LENGTHS)
            .map(|k| 0.03 * (10.0f64 / 0.03).powf(k as f64 / (LENGTHS - 1) as f64))
            .collect();
        let mut nugget = NUGGETS[1];
        let mut best: Option<(f64, Vec<f64>)> = None;
        for &g in &grid {
            let l = vec![g; d];
            if let Some(v) = profile_lml(inputs, &yv, &l, nugget) {
                if best.as_ref().is_none_or(|(b, _)| v > *b) {
                    best = Some((v, l));
                }
            }
        }
        if best.is_none() {
            nugget = NUGGETS[NUGGETS.len() - 1];
            let l = vec![1.0; d];
            best = profile_lml(inputs, &yv, &l, nugget).map(|v| (v, l));
        }
        let (mut best_v, mut l) = best?;
        for _sweep in 0..3 {
            let before = best_v;
            for k in 0..d {
                for &g in &grid {
                    let mut t = l.clone();
                    t[k] = g;
                    if let Some(v) = profile_lml(inputs, &yv, &t, nugget) {
                        if v > best_v {
                            best_v = v;
                            l = t;
                        }
                    }
                }
            }
            for &g in &NUGGETS {
                if let Some(v) = profile_lml(inputs, &yv, &l, g) {
                    if v > best_v {
                        best_v = v;
                        nugget = g;
                    }
                }
            }
            if best_v <= before + 1e-9 {
                break;
            }
        }
        let ch = matrix(inputs, &l, nugget).cholesky()?;
        let weights = ch.solve(&yv).iter().copied().collect();
        Some(Gp {
            inputs: inputs.to_vec(),
            length_scales: l,
            nugget,
            weights,
        })
    }

    /// The posterior mean at unit-cube `u`.
    pub fn mean(&self, u: &[f64]) -> f64 {
        self.inputs
            .iter()
            .zip(&self.weights)
            .map(|(p, w)| w * correlation(u, p, &self.length_scales))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surrogate::halton_design;

    /// A smooth function of two inputs is reproduced between the design
    /// points, and the fitted lengths see that the second input matters less.
    #[test]
    fn reproduces_a_smooth_function_and_ranks_its_inputs() {
        let f = |u: &[f64]| (2.0 * u[0]).sin() + 0.1 * u[1] * u[1];
        let u = halton_design(&[0.0, 0.0], &[1.0, 1.0], 0, 40);
        let y: Vec<f64> = u.iter().map(|p| f(p)).collect();
        let gp = Gp::fit(&u, &y).unwrap();
        let test = halton_design(&[0.0, 0.0], &[1.0, 1.0], 40, 50);
        let max = test
            .iter()
            .map(|p| (gp.mean(p) - f(p)).abs())
            .fold(0.0, f64::max);
        assert!(max < 1e-4, "{max} {:?}", gp.length_scales);
        assert!(
            gp.length_scales[1] > gp.length_scales[0],
            "{:?}",
            gp.length_scales
        );
    }
}
