//! Standard errors, correlations and the identifiability verdict.
//!
//! With `J` the Jacobian of the (weighted) residuals with respect to the
//! free physical parameters at the optimum and `sigma^2 = SSE / (n - p)`,
//! the asymptotic covariance is `C = sigma^2 (J^T J)^{-1}` (Bates & Watts
//! 1988, "Nonlinear regression analysis and its applications", §2.3; Seber
//! & Wild 1989, §2.1). It is computed without forming `J^T J`: with column
//! scaling `c_j = ||J_j||` and the SVD `J diag(1/c) = U S V^T`,
//! `C = sigma^2 diag(1/c) V S^-2 V^T diag(1/c)`. The condition number of the
//! scaled `J^T J` is `(s_max / s_min)^2`.

use nalgebra::DMatrix;
use serde::Serialize;

/// Condition number of the scaled `J^T J` above which a fit is not identifiable.
pub const MAX_CONDITION: f64 = 1e10;
/// Relative singular value of the scaled Jacobian below which it counts as zero (rank).
pub const RANK_TOLERANCE: f64 = 1e-9;
/// |correlation| above which two parameters are not separately identifiable.
pub const MAX_CORRELATION: f64 = 0.999;

/// Two strongly correlated parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CorrelatedPair {
    pub first: String,
    pub second: String,
    pub correlation: f64,
}

/// Whether the data determine the free parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identifiability {
    pub identifiable: bool,
    /// Condition number of the column-scaled `J^T J` (infinite when singular).
    pub condition_number: f64,
    /// Numerical rank of `J` (over the parameters not on a bound).
    pub rank: usize,
    /// Parameters not on a bound.
    pub parameters: usize,
    /// Parameters involved in a (near) rank deficiency or a strong correlation.
    pub involved: Vec<String>,
    pub correlated_pairs: Vec<CorrelatedPair>,
    /// Parameters sitting on a bound (excluded from the covariance).
    pub at_bound: Vec<String>,
    /// A sentence saying why.
    pub reason: String,
}

/// Covariance of the free parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Covariance {
    pub names: Vec<String>,
    /// `sigma^2 = SSE / (n - p)`, `None` when `n <= p`.
    pub sigma2: Option<f64>,
    /// Physical standard errors; `None` for parameters on a bound, in an
    /// exact rank deficiency, or when `sigma^2` is undefined.
    pub standard_errors: Vec<Option<f64>>,
    /// Covariance matrix (NaN where undefined; serialises as null).
    pub matrix: Vec<Vec<f64>>,
    /// Correlation matrix (NaN where undefined; serialises as null).
    pub correlation: Vec<Vec<f64>>,
    pub identifiability: Identifiability,
}

/// Covariance from the physical Jacobian `jx` (`m x q`), the SSE, the free
/// names and which parameters sit on a bound.
pub fn covariance(jx: &DMatrix<f64>, sse: f64, names: &[String], at_bound: &[bool]) -> Covariance {
    let (m, q) = jx.shape();
    let sigma2 = (m > q).then(|| sse / (m - q) as f64);
    covariance_with_noise(jx, sigma2, names, at_bound)
}

/// Covariance from the physical Jacobian `jx` for a known noise variance
/// `sigma2` per residual (`None`: standard errors undefined): the inverse
/// Fisher information `sigma2 (J^T J)^{-1}` (experiment design,
/// [`crate::design`]), with the same rank and identifiability verdict as
/// [`covariance`].
pub fn covariance_with_noise(
    jx: &DMatrix<f64>,
    sigma2: Option<f64>,
    names: &[String],
    at_bound: &[bool],
) -> Covariance {
    let (m, q) = jx.shape();
    let active: Vec<usize> = (0..q).filter(|&j| !at_bound[j]).collect();
    let qa = active.len();
    let mut matrix = vec![vec![f64::NAN; q]; q];
    let mut involved = vec![false; q];
    let mut exact_deficient = vec![false; q];
    let mut condition_number = 1.0;
    let mut rank = 0;
    if qa > 0 {
        let c: Vec<f64> = active.iter().map(|&j| jx.column(j).norm()).collect();
        let mut js = DMatrix::zeros(m, qa);
        for (a, &j) in active.iter().enumerate() {
            let s = if c[a] > 0.0 { 1.0 / c[a] } else { 1.0 };
            js.column_mut(a).copy_from(&(jx.column(j) * s));
        }
        let svd = js.svd(false, true);
        let v_t = svd.v_t.expect("V requested");
        let s = &svd.singular_values;
        let s_max = s.iter().cloned().fold(0.0, f64::max);
        // Finite-difference Jacobians are accurate to ~1e-10 relative, so
        // singular values below RANK_TOLERANCE * s_max are taken as zero.
        let tol = s_max * RANK_TOLERANCE;
        let s_min = if m < qa {
            0.0
        } else {
            s.iter().cloned().fold(f64::INFINITY, f64::min)
        };
        condition_number = if s_min > 0.0 {
            (s_max / s_min).powi(2)
        } else {
            f64::INFINITY
        };
        rank = s.iter().filter(|&&v| v > tol).count();
        if m < qa {
            // Fewer residuals than parameters: a null space V does not show.
            for &j in &active {
                involved[j] = true;
                exact_deficient[j] = true;
            }
        }
        for (i, &si) in s.iter().enumerate() {
            let weak = si <= tol || (s_max / si).powi(2) > MAX_CONDITION;
            if weak {
                for (a, &j) in active.iter().enumerate() {
                    if v_t[(i, a)].abs() >= 0.1 {
                        involved[j] = true;
                        if si <= tol {
                            exact_deficient[j] = true;
                        }
                    }
                }
            }
        }
        for (a, &ja) in active.iter().enumerate() {
            if c[a] == 0.0 {
                involved[ja] = true;
                exact_deficient[ja] = true;
            }
        }
        // Pseudo-inverse of the scaled J^T J over the kept singular values.
        for (a, &ja) in active.iter().enumerate() {
            for (b, &jb) in active.iter().enumerate() {
                let mut sum = 0.0;
                for (i, &si) in s.iter().enumerate() {
                    if si > tol {
                        sum += v_t[(i, a)] * v_t[(i, b)] / (si * si);
                    }
                }
                let ca = if c[a] > 0.0 { c[a] } else { 1.0 };
                let cb = if c[b] > 0.0 { c[b] } else { 1.0 };
                matrix[ja][jb] = sum / (ca * cb);
            }
        }
    }
    // Correlation (independent of sigma^2) from the unscaled pseudo-inverse.
    let defined = |j: usize| !at_bound[j] && !exact_deficient[j];
    let mut correlation = vec![vec![f64::NAN; q]; q];
    let mut pairs = Vec::new();
    for a in 0..q {
        for b in 0..q {
            if defined(a) && defined(b) {
                let v = matrix[a][b] / (matrix[a][a] * matrix[b][b]).sqrt();
                correlation[a][b] = if a == b { 1.0 } else { v };
                if b > a && v.abs() > MAX_CORRELATION {
                    involved[a] = true;
                    involved[b] = true;
                    pairs.push(CorrelatedPair {
                        first: names[a].clone(),
                        second: names[b].clone(),
                        correlation: v,
                    });
                }
            }
        }
    }
    let standard_errors: Vec<Option<f64>> = (0..q)
        .map(|j| match sigma2 {
            Some(s2) if defined(j) => Some((s2 * matrix[j][j]).sqrt()),
            _ => None,
        })
        .collect();
    for row in matrix.iter_mut() {
        for v in row.iter_mut() {
            *v *= sigma2.unwrap_or(f64::NAN);
        }
    }
    for (j, row) in matrix.iter_mut().enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            if !defined(j) || !defined(k) {
                *v = f64::NAN;
            }
        }
    }
    let involved_names: Vec<String> = (0..q)
        .filter(|&j| involved[j])
        .map(|j| names[j].clone())
        .collect();
    let identifiable = involved_names.is_empty() && condition_number <= MAX_CONDITION;
    let reason = if identifiable {
        format!("rank {rank} of {qa}, condition number {condition_number:.3e}")
    } else if rank < qa {
        format!(
            "rank deficient ({rank} of {qa}); involved: {}",
            involved_names.join(", ")
        )
    } else if !pairs.is_empty() {
        format!(
            "|correlation| > {MAX_CORRELATION}: {}",
            pairs
                .iter()
                .map(|p| format!("{}~{} ({:.6})", p.first, p.second, p.correlation))
                .collect::<Vec<_>>()
                .join(", ")
        )
    } else {
        format!(
            "condition number {condition_number:.3e} > {MAX_CONDITION:e}; involved: {}",
            involved_names.join(", ")
        )
    };
    Covariance {
        names: names.to_vec(),
        sigma2,
        standard_errors,
        matrix,
        correlation,
        identifiability: Identifiability {
            identifiable,
            condition_number,
            rank,
            parameters: qa,
            involved: involved_names,
            correlated_pairs: pairs,
            at_bound: (0..q)
                .filter(|&j| at_bound[j])
                .map(|j| names[j].clone())
                .collect(),
            reason,
        },
    }
}
