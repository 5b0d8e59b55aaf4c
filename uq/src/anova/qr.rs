//! Sequential QR factorisation of a model matrix, column by column, that
//! skips columns aliased with earlier ones.
//!
//! Hand-written (modified Gram-Schmidt, each column orthogonalised twice —
//! "twice is enough", Giraud et al. 2005, Numer. Math. 101:87) rather than
//! nalgebra's Householder QR: sequential (Type I) sums of squares need the
//! columns in model order, and an aliased column (an unbalanced or fractional
//! design) must be detected and dropped in place, keeping the order, as R's
//! `lm` does with its limited pivoting; nalgebra's QR has no such mode and
//! its column-pivoted QR reorders all columns.

/// The triangular factor R of the kept columns, Q^T y and the residual of y.
#[derive(Debug, Clone)]
pub(crate) struct SequentialQr {
    /// R, row-major upper triangular, kept x kept.
    pub r: Vec<Vec<f64>>,
    /// For each kept column, its index in the input columns.
    pub kept: Vec<usize>,
    /// Q^T y per kept column.
    pub qty: Vec<f64>,
    /// y minus its projection on the kept columns.
    pub residual: Vec<f64>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn axpy(v: &mut [f64], c: f64, q: &[f64]) {
    for (vi, qi) in v.iter_mut().zip(q) {
        *vi -= c * qi;
    }
}

/// Relative size below which a column is taken as a combination of earlier ones.
const ALIAS_TOL: f64 = 1e-9;

impl SequentialQr {
    /// Factorises `columns` (each of length n) in order and projects `y`.
    pub fn new(columns: &[Vec<f64>], y: &[f64]) -> SequentialQr {
        let mut q: Vec<Vec<f64>> = Vec::new();
        let mut rcols: Vec<Vec<f64>> = Vec::new(); // column j of R (length kept_before + 1)
        let mut kept = Vec::new();
        for (j, x) in columns.iter().enumerate() {
            let xnorm = dot(x, x).sqrt();
            if xnorm == 0.0 {
                continue;
            }
            let mut v = x.clone();
            let mut rc = vec![0.0; q.len()];
            for _pass in 0..2 {
                for (i, qi) in q.iter().enumerate() {
                    let c = dot(qi, &v);
                    axpy(&mut v, c, qi);
                    rc[i] += c;
                }
            }
            let norm = dot(&v, &v).sqrt();
            if norm <= ALIAS_TOL * xnorm {
                continue;
            }
            v.iter_mut().for_each(|e| *e /= norm);
            rc.push(norm);
            q.push(v);
            rcols.push(rc);
            kept.push(j);
        }
        let m = q.len();
        let mut r = vec![vec![0.0; m]; m];
        for (j, rc) in rcols.iter().enumerate() {
            for (i, &v) in rc.iter().enumerate() {
                r[i][j] = v;
            }
        }
        let mut residual = y.to_vec();
        let mut qty = vec![0.0; m];
        for _pass in 0..2 {
            for (i, qi) in q.iter().enumerate() {
                let c = dot(qi, &residual);
                axpy(&mut residual, c, qi);
                qty[i] += c;
            }
        }
        SequentialQr {
            r,
            kept,
            qty,
            residual,
        }
    }

    /// Coefficients of the kept columns: solves R b = Q^T y by back substitution.
    pub fn coefficients(&self) -> Vec<f64> {
        let m = self.qty.len();
        let mut b = vec![0.0; m];
        for i in (0..m).rev() {
            let s: f64 = (i + 1..m).map(|j| self.r[i][j] * b[j]).sum();
            b[i] = (self.qty[i] - s) / self.r[i][i];
        }
        b
    }

    /// Diagonal of (X^T X)^{-1} = R^{-1} R^{-T} over the kept columns: entry j
    /// is |z|^2 where R^T z = e_j (forward substitution; no inverse formed).
    pub fn unscaled_variances(&self) -> Vec<f64> {
        let m = self.qty.len();
        (0..m)
            .map(|j| {
                // R^T is lower triangular; z_i = 0 for i < j.
                let mut z = vec![0.0; m];
                z[j] = 1.0 / self.r[j][j];
                for i in j + 1..m {
                    let s: f64 = (j..i).map(|k| self.r[k][i] * z[k]).sum();
                    z[i] = -s / self.r[i][i];
                }
                z.iter().map(|v| v * v).sum()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_line_fit_and_alias_detection() {
        // y = 1 + 2 x exactly; third column = 2 * second (aliased).
        let x = [0.0, 1.0, 2.0, 3.0];
        let cols = vec![
            vec![1.0; 4],
            x.to_vec(),
            x.iter().map(|v| 2.0 * v).collect(),
        ];
        let y: Vec<f64> = x.iter().map(|v| 1.0 + 2.0 * v).collect();
        let qr = SequentialQr::new(&cols, &y);
        assert_eq!(qr.kept, vec![0, 1]);
        let b = qr.coefficients();
        assert!(
            (b[0] - 1.0).abs() < 1e-14 && (b[1] - 2.0).abs() < 1e-14,
            "{b:?}"
        );
        assert!(qr.residual.iter().all(|r| r.abs() < 1e-14));
        // X^T X = [[4, 6], [6, 14]], whose inverse is [[0.7, -0.3], [-0.3, 0.2]].
        let v = qr.unscaled_variances();
        assert!(
            (v[0] - 0.7).abs() < 1e-14 && (v[1] - 0.2).abs() < 1e-14,
            "{v:?}"
        );
    }
}
