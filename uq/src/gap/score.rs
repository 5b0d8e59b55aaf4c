//! Score (Lagrange-multiplier) test of an enrichment at its "off" point, and
//! finite-difference sensitivities that respect the bounds.

use nalgebra::DMatrix;
use palpate_core::fd::{fd_column, FdRule, FdStep};
use palpate_core::{ForwardError, ForwardModel, Loading};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Relative finite-difference step of the sensitivities. Larger than the
/// optimum for exact arithmetic (`eps^(1/3)`) because a finite-element
/// prediction is only accurate to its Newton tolerance.
pub const RELATIVE_STEP: f64 = 1e-4;

/// Finite-difference sensitivities d prediction / d theta_j at `theta`
/// (physical parameters), one column per parameter: central where both
/// neighbours are inside the bounds, one-sided into the interior otherwise
/// (e.g. at g = 0 or c = 0), and one-sided through `theta` when a step
/// fails. The rule is palpate-core's `fd` with [`RELATIVE_STEP`]: 1e-4 of a
/// scale that does not vanish at an "off" point,
/// max(|theta_j|, |initial_j|, 1e-3 x finite range, 1e-8).
pub fn sensitivities(
    model: &dyn ForwardModel,
    theta: &[f64],
    loading: &Loading,
) -> Result<DMatrix<f64>, ForwardError> {
    sensitivities_of(model, theta, loading, &vec![true; theta.len()])
}

/// [`sensitivities`] of the parameters flagged in `wanted` only (the other
/// columns are zero), computed in parallel over columns, each column by its
/// own evaluator with the same arithmetic whatever the thread (bit-identical
/// to the serial result). For a finite-element model each column is one or
/// two nonlinear solves, so the parallel columns matter.
pub(crate) fn sensitivities_of(
    model: &dyn ForwardModel,
    theta: &[f64],
    loading: &Loading,
    wanted: &[bool],
) -> Result<DMatrix<f64>, ForwardError> {
    sensitivities_at(model, theta, loading, wanted, None, false)
}

/// [`sensitivities_of`] reusing the prediction `centre` at `theta` when the
/// caller has it (a fit's predictions at its optimum), and with forward
/// differences through it when `forward` (one model evaluation per column
/// instead of two: what an expensive model's linearised cross-validation
/// uses; the truncation error O(h) at h = 1e-4 of the parameter's scale is
/// far below what a held-out prediction resolves).
pub(crate) fn sensitivities_at(
    model: &dyn ForwardModel,
    theta: &[f64],
    loading: &Loading,
    wanted: &[bool],
    centre: Option<&[f64]>,
    forward: bool,
) -> Result<DMatrix<f64>, ForwardError> {
    let n = loading.len();
    let rule = if forward {
        FdRule {
            relative_step: RELATIVE_STEP,
            scheme: palpate_core::fd::FdScheme::Forward,
        }
    } else {
        FdRule::central(RELATIVE_STEP)
    };
    let steps: Vec<Option<FdStep>> = model
        .space()
        .params
        .iter()
        .enumerate()
        .map(|(j, spec)| wanted[j].then(|| rule.param_step(spec, theta[j])))
        .collect();
    // The prediction at `theta` is shared by every column that is one-sided
    // at a bound (e.g. at g = 0 or c = 0).
    let one_sided = forward
        || steps
            .iter()
            .enumerate()
            .any(|(j, s)| s.is_some_and(|s| theta[j] + s.h > s.upper || theta[j] - s.h < s.lower));
    let centre: Option<Vec<f64>> = match centre {
        Some(c) => Some(c.to_vec()),
        None if one_sided => Some(model.predict(theta, loading)?),
        None => None,
    };
    let columns: Vec<Result<Option<Vec<f64>>, ForwardError>> = steps
        .par_iter()
        .enumerate()
        .map(|(j, step)| {
            let Some(step) = *step else {
                return Ok(None);
            };
            let mut ev = model.evaluator();
            let mut f = |t: &[f64], out: &mut [f64]| ev.predict_into(t, loading, out);
            let mut col = vec![0.0; n];
            match fd_column(&mut f, theta, j, step, centre.as_deref(), &mut col) {
                Ok(_) => Ok(Some(col)),
                // The model predicts at `theta` but admits no step of this
                // parameter either way (a Prony weight at the edge of
                // sum g_i <= 1 while its own bound lies behind it): no
                // local sensitivity, a zero column.
                Err(_) if centre.is_some() => Ok(Some(vec![0.0; n])),
                Err(e) => Err(e),
            }
        })
        .collect();
    let mut jac = DMatrix::zeros(n, theta.len());
    for (j, column) in columns.into_iter().enumerate() {
        if let Some(c) = column? {
            jac.column_mut(j).copy_from_slice(&c);
        }
    }
    Ok(jac)
}

/// The columns of `jac` from `p` on, made orthogonal to the first `p`
/// (the base parameters' sensitivities) by a thin QR of the latter: what an
/// enrichment can change that refitting the base parameters cannot.
pub fn projected_columns(jac: &DMatrix<f64>, p: usize) -> DMatrix<f64> {
    let q = jac.ncols() - p;
    let mut a = jac.columns(p, q).into_owned();
    if p > 0 {
        let qr = jac.columns(0, p).into_owned().qr();
        let qm = qr.q();
        let rm = qr.r();
        let scale = rm.diagonal().amax().max(f64::MIN_POSITIVE);
        for k in (0..p).filter(|&k| rm[(k, k)].abs() > 1e-10 * scale) {
            let qk = qm.column(k);
            for j in 0..q {
                let c = qk.dot(&a.column(j));
                a.column_mut(j).axpy(-c, &qk, 1.0);
            }
        }
    }
    a
}

/// Orthonormal basis of the column space of `a` (left singular vectors
/// above 1e-8 of the largest singular value).
fn column_basis(a: &DMatrix<f64>) -> DMatrix<f64> {
    if a.ncols() == 0 || a.norm() == 0.0 {
        return DMatrix::zeros(a.nrows(), 0);
    }
    let svd = a.clone().svd(true, false);
    let u = svd.u.expect("u requested");
    let smax = svd.singular_values.amax();
    let keep: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] > 1e-8 * smax)
        .collect();
    DMatrix::from_fn(a.nrows(), keep.len(), |i, k| u[(i, keep[k])])
}

/// Cosine of the smallest principal angle between the column spaces of two
/// effects' projected sensitivities ([`projected_columns`]): 1 when some
/// change of one effect's parameters moves the prediction exactly as a
/// change of the other's does (locally indistinguishable at "off"), 0 when
/// they act on orthogonal directions (Björck & Golub 1973).
pub fn sensitivity_overlap(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    let (ua, ub) = (column_basis(a), column_basis(b));
    if ua.ncols() == 0 || ub.ncols() == 0 {
        return 0.0;
    }
    let m = ua.transpose() * ub;
    m.svd(false, false).singular_values.amax().min(1.0)
}

/// Result of a score test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScoreTest {
    /// LM statistic r' A (A'A)^+ A' r / sigma^2 with A the new parameters'
    /// sensitivities made orthogonal to the base parameters'.
    pub statistic: f64,
    /// Degrees of freedom (numerical rank of A).
    pub dof: usize,
    /// Upper-tail chi-square p-value.
    pub p_value: f64,
    /// Gauss-Newton step of the new parameters from "off" (a starting point for the refit).
    pub step: Vec<f64>,
}

/// Score test at the "off" point: residuals `r` (data - base fit, which are
/// orthogonal to the base sensitivities at the base optimum), sensitivities
/// `jac` of the enriched model at its embedded point, whose first `p` columns
/// are the base parameters. The new columns are projected on the orthogonal
/// complement of the base columns, so the statistic measures only what the
/// base model cannot absorb by refitting its own parameters (Rao's score
/// test; Breusch & Pagan 1980 for the LM form). A new parameter sitting on a
/// lower (upper) bound whose step points below (above) it cannot move that
/// way: its column is dropped (a one-sided score test).
pub fn score_test(
    r: &[f64],
    jac: &DMatrix<f64>,
    p: usize,
    sigma: f64,
    at_lower: &[bool],
    at_upper: &[bool],
) -> ScoreTest {
    let n = r.len();
    let q = jac.ncols() - p;
    let rv = nalgebra::DVector::from_column_slice(r);
    let a = projected_columns(jac, p);
    let mut active: Vec<usize> = (0..q).filter(|&j| a.column(j).norm() > 0.0).collect();
    let mut step = vec![0.0; q];
    loop {
        if active.is_empty() {
            return ScoreTest {
                statistic: 0.0,
                dof: 0,
                p_value: 1.0,
                step,
            };
        }
        let sub = DMatrix::from_fn(n, active.len(), |i, k| a[(i, active[k])]);
        let svd = sub.clone().svd(true, true);
        let smax = svd.singular_values.amax();
        let tol = 1e-8 * smax;
        let u = svd.u.as_ref().expect("u");
        let vt = svd.v_t.as_ref().expect("v_t");
        let mut stat = 0.0;
        let mut rank = 0;
        let mut delta = vec![0.0; active.len()];
        for k in 0..svd.singular_values.len() {
            let s = svd.singular_values[k];
            if s > tol && s > 0.0 {
                rank += 1;
                let c = u.column(k).dot(&rv);
                stat += c * c;
                for (m, d) in delta.iter_mut().enumerate() {
                    *d += vt[(k, m)] * c / s;
                }
            }
        }
        // One-sided: drop a column whose step leaves the feasible side of its bound.
        let blocked = active
            .iter()
            .zip(&delta)
            .position(|(&j, &d)| (at_lower[j] && d < 0.0) || (at_upper[j] && d > 0.0));
        if let Some(k) = blocked {
            active.remove(k);
            continue;
        }
        step = vec![0.0; q];
        for (k, &j) in active.iter().enumerate() {
            step[j] = delta[k];
        }
        let statistic = stat / (sigma * sigma);
        return ScoreTest {
            statistic,
            dof: rank,
            p_value: super::structure::chi2_sf(statistic, rank as f64),
            step,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For a linear model the score statistic equals the likelihood ratio:
    /// sigma^2 S = SSE(base fit) - SSE(full fit), exactly.
    #[test]
    fn score_statistic_equals_the_linear_likelihood_ratio() {
        let x: Vec<f64> = (0..50).map(|i| 0.1 * i as f64).collect();
        // Data: 2 x + 0.3 x^2 + a deterministic wiggle standing in for noise.
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, v)| 2.0 * v + 0.3 * v * v + 0.05 * ((i * 7 % 11) as f64 - 5.0))
            .collect();
        let sxx: f64 = x.iter().map(|v| v * v).sum();
        let a: f64 = x.iter().zip(&y).map(|(u, w)| u * w).sum::<f64>() / sxx;
        let r: Vec<f64> = x.iter().zip(&y).map(|(u, w)| w - a * u).collect();
        let jac = DMatrix::from_fn(50, 2, |i, j| if j == 0 { x[i] } else { x[i] * x[i] });
        let sigma = 0.1;
        let s = score_test(&r, &jac, 1, sigma, &[false], &[false]);
        // Full least squares by the normal equations (2 x 2).
        let (s11, s12, s22) = (
            sxx,
            x.iter().map(|v| v.powi(3)).sum::<f64>(),
            x.iter().map(|v| v.powi(4)).sum::<f64>(),
        );
        let (b1, b2) = (
            x.iter().zip(&y).map(|(u, w)| u * w).sum::<f64>(),
            x.iter().zip(&y).map(|(u, w)| u * u * w).sum::<f64>(),
        );
        let det = s11 * s22 - s12 * s12;
        let (fa, fb) = ((s22 * b1 - s12 * b2) / det, (s11 * b2 - s12 * b1) / det);
        let sse = |f: &dyn Fn(f64) -> f64| {
            x.iter()
                .zip(&y)
                .map(|(u, w)| (w - f(*u)).powi(2))
                .sum::<f64>()
        };
        let lr = sse(&|u| a * u) - sse(&|u| fa * u + fb * u * u);
        assert!(
            (s.statistic * sigma * sigma - lr).abs() < 1e-9 * lr,
            "{} vs {lr}",
            s.statistic * sigma * sigma
        );
        assert_eq!(s.dof, 1);
        // The Gauss-Newton step from "off" is the full least-squares coefficient.
        assert!((s.step[0] - fb).abs() < 1e-9 * fb.abs());
        // One-sided: a parameter on its lower bound cannot take a negative step.
        let neg: Vec<f64> = r.iter().zip(&x).map(|(ri, u)| ri - 0.6 * u * u).collect();
        let blocked = score_test(&neg, &jac, 1, sigma, &[true], &[false]);
        assert_eq!((blocked.statistic, blocked.dof), (0.0, 0));
        assert!(score_test(&neg, &jac, 1, sigma, &[false], &[false]).statistic > 0.0);
    }
}
