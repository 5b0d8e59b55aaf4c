//! Laplace approximation of a posterior and the evidence it implies.
//!
//! Around the mode z* of the log-density in the unbounded space,
//! log p(z) ≈ log p(z*) - 1/2 (z - z*)^T H (z - z*), so the posterior is
//! approximately N(z*, H^-1) and the evidence (the integral of the
//! unnormalised density, which the log-Jacobian makes the same in the
//! unbounded and the physical space) is
//!
//!   log Z ≈ log p(z*) + d/2 log(2 pi) - 1/2 log det H
//!
//! (Tierney & Kadane 1986; MacKay 2003, *Information Theory, Inference and
//! Learning Algorithms*, eq. 27.10). Physical-space moments follow by the
//! delta method through the bound transforms: x = x(z*), cov_x = J cov_z J
//! with J = diag(dx/dz).
//!
//! The mode is found by damped Newton steps on a finite-difference Hessian
//! (central differences of the log-density, O(d^2) evaluations per step): the
//! posteriors here have a handful of parameters, and a Levenberg-damped
//! Newton with a backtracking line search converges in a few steps from a
//! least-squares fit or the best MCMC draw.

use super::density::LogDensity;
use super::error::McmcError;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// A Laplace approximation in the unbounded space.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Laplace {
    /// Mode z*.
    pub mode: Vec<f64>,
    /// log p(z*) (unnormalised).
    pub log_density_at_mode: f64,
    /// Covariance H^-1, row-major.
    pub covariance: Vec<Vec<f64>>,
    /// Laplace estimate of the log evidence.
    pub log_evidence: f64,
    /// Log-density evaluations spent.
    pub evaluations: u64,
}

impl Laplace {
    /// Standard deviations sqrt(diag H^-1).
    pub fn sd(&self) -> Vec<f64> {
        (0..self.mode.len())
            .map(|i| self.covariance[i][i].sqrt())
            .collect()
    }
}

fn hessian(
    f: &mut dyn FnMut(&[f64]) -> f64,
    z: &[f64],
    f0: f64,
    h: &[f64],
) -> (DMatrix<f64>, DVector<f64>) {
    let d = z.len();
    let mut hess = DMatrix::zeros(d, d);
    let mut grad = DVector::zeros(d);
    let mut zz = z.to_vec();
    for i in 0..d {
        zz[i] = z[i] + h[i];
        let fp = f(&zz);
        zz[i] = z[i] - h[i];
        let fm = f(&zz);
        zz[i] = z[i];
        grad[i] = (fp - fm) / (2.0 * h[i]);
        hess[(i, i)] = (fp - 2.0 * f0 + fm) / (h[i] * h[i]);
        for j in 0..i {
            let mut e = |si: f64, sj: f64| {
                zz[i] = z[i] + si * h[i];
                zz[j] = z[j] + sj * h[j];
                let v = f(&zz);
                zz[i] = z[i];
                zz[j] = z[j];
                v
            };
            let v =
                (e(1.0, 1.0) - e(1.0, -1.0) - e(-1.0, 1.0) + e(-1.0, -1.0)) / (4.0 * h[i] * h[j]);
            hess[(i, j)] = v;
            hess[(j, i)] = v;
        }
    }
    (hess, grad)
}

/// Finds the mode from `z0` and builds the Laplace approximation.
pub fn laplace(density: &dyn LogDensity, z0: &[f64]) -> Result<Laplace, McmcError> {
    let d = density.dim();
    if z0.len() != d {
        return Err(McmcError::DimensionMismatch {
            expected: d,
            got: z0.len(),
        });
    }
    let mut w = density.worker();
    let mut evals = 0u64;
    let mut f = |z: &[f64]| {
        evals += 1;
        let v = w.log_density(z);
        if v.is_nan() {
            f64::NEG_INFINITY
        } else {
            v
        }
    };
    let mut z = z0.to_vec();
    let mut fz = f(&z);
    if !fz.is_finite() {
        return Err(McmcError::Laplace {
            reason: "log-density is not finite at the start point".into(),
        });
    }
    let mut lambda = 1e-3;
    // Difference steps: first relative to z, then a tenth of the current
    // conditional posterior SD of each coordinate (1 / sqrt(A_kk), the
    // width across the others held), so badly scaled coordinates get
    // sensible steps. Not the marginal SD sqrt((A^-1)_kk): along a narrow
    // curved ridge (an AR(1) noise's SD against its coefficient on a dense
    // record, 0.02 wide and 1 long in z) a step of a tenth of the marginal
    // SD crosses the ridge several times over, and the differences then
    // miss the small curvature along it: the Hessian comes out indefinite.
    let mut h: Vec<f64> = z.iter().map(|v| 1e-4 * v.abs().max(1.0)).collect();
    for _ in 0..200 {
        let (hess, grad) = hessian(&mut f, &z, fz, &h);
        // Newton step on -log p: (A + lambda diag) dz = grad with A = -H.
        let a = -hess;
        if (0..d).all(|k| a[(k, k)] > 0.0 && a[(k, k)].is_finite()) {
            for k in 0..d {
                h[k] = 0.1 / a[(k, k)].sqrt();
            }
        }
        let mut improved = false;
        for _ in 0..30 {
            let mut m = a.clone();
            // Damping floor relative to the largest curvature, so a flat
            // coordinate (a parameter near a bound, whose log-transform
            // flattens the density) still gets a finite step.
            let floor = 1e-8 * (0..d).map(|i| a[(i, i)].abs()).fold(1e-300, f64::max);
            for i in 0..d {
                m[(i, i)] += lambda * a[(i, i)].abs().max(floor);
            }
            let Some(ch) = m.cholesky() else {
                lambda *= 10.0;
                continue;
            };
            let dz = ch.solve(&grad);
            let zn: Vec<f64> = z.iter().zip(dz.iter()).map(|(a, b)| a + b).collect();
            let fnew = f(&zn);
            if fnew.is_finite() && fnew >= fz {
                let gain = fnew - fz;
                z = zn;
                fz = fnew;
                lambda = (lambda * 0.3).max(1e-12);
                improved = gain > 1e-12 || dz.norm() > 1e-10;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    let (hess, _) = hessian(&mut f, &z, fz, &h);
    let a = -hess;
    let ch = a.clone().cholesky().ok_or_else(|| McmcError::Laplace {
        reason: "the negative Hessian at the mode is not positive definite (flat or non-identifiable direction)".into(),
    })?;
    let cov = ch.inverse();
    let log_det: f64 = 2.0 * (0..d).map(|i| ch.l()[(i, i)].ln()).sum::<f64>();
    let log_evidence = fz + 0.5 * d as f64 * (2.0 * std::f64::consts::PI).ln() - 0.5 * log_det;
    Ok(Laplace {
        mode: z,
        log_density_at_mode: fz,
        covariance: (0..d)
            .map(|i| (0..d).map(|j| cov[(i, j)]).collect())
            .collect(),
        log_evidence,
        evaluations: evals,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcmc::FnDensity;

    #[test]
    fn gaussian_mode_covariance_and_evidence_are_exact() {
        // p(z) = 5 * N(z; m, S) unnormalised by 5: log Z = ln 5.
        let m = [1.0, -2.0];
        let (s11, s22, s12) = (0.5f64, 2.0f64, 0.6f64);
        let det = s11 * s22 - s12 * s12;
        let d = FnDensity::new(2, move |z: &[f64]| {
            let (a, b) = (z[0] - m[0], z[1] - m[1]);
            let q = (s22 * a * a - 2.0 * s12 * a * b + s11 * b * b) / det;
            5f64.ln() - 0.5 * q - (2.0 * std::f64::consts::PI).ln() - 0.5 * det.ln()
        });
        let l = laplace(&d, &[0.0, 0.0]).unwrap();
        assert!(
            (l.mode[0] - 1.0).abs() < 1e-6 && (l.mode[1] + 2.0).abs() < 1e-6,
            "{:?}",
            l.mode
        );
        assert!((l.covariance[0][0] - s11).abs() < 1e-5);
        assert!((l.covariance[0][1] - s12).abs() < 1e-5);
        assert!((l.covariance[1][1] - s22).abs() < 1e-5);
        assert!(
            (l.log_evidence - 5f64.ln()).abs() < 1e-6,
            "{}",
            l.log_evidence
        );
    }

    /// A narrow ridge of the shape an AR(1) noise's SD and coefficient make
    /// on a dense record (u = y - x / 2 is pinned by 1200 residuals, 0.02
    /// wide, x only by its prior, 1 wide): the mode and covariance come out
    /// (x: 1, y: 1/4 + 1/2400, covariance 1/2). With steps of a tenth of the
    /// marginal SD the differences made the Hessian indefinite here.
    #[test]
    fn a_narrow_ridge_gives_a_positive_definite_hessian() {
        let n = 1200.0;
        let d = FnDensity::new(2, move |z: &[f64]| {
            let u = z[1] - 0.5 * z[0];
            -n * u - 0.5 * n * (-2.0 * u).exp() - 0.5 * z[0] * z[0]
        });
        for z0 in [[3.0, 1.0], [0.5, -0.3], [-2.0, 2.0]] {
            let l = laplace(&d, &z0).unwrap_or_else(|e| panic!("from {z0:?}: {e}"));
            assert!(l.mode.iter().all(|m| m.abs() < 1e-3), "{:?}", l.mode);
            let c = &l.covariance;
            assert!((c[0][0] - 1.0).abs() < 0.02, "{c:?}");
            assert!((c[0][1] - 0.5).abs() < 0.01, "{c:?}");
            assert!((c[1][1] - (0.25 + 1.0 / 2400.0)).abs() < 0.005, "{c:?}");
        }
    }
}
