//! GMRES with right preconditioning (Saad & Schultz 1986; Saad, *Iterative
//! Methods for Sparse Linear Systems*, 2nd ed., algorithm 9.5): the
//! iterate `x_m = M^-1 V_m y_m` minimises `||b - A x||` over the Krylov
//! space of `A M^-1`, with the Arnoldi basis `V` by modified Gram-Schmidt
//! and the least-squares problem by Givens rotations, so the residual norm
//! `|g_(m+1)|` is known at every step without forming `x`. One cycle (no
//! restart): the caller falls back to a direct solve when it does not
//! converge. Used with the LDL^T of a frictional tangent's symmetric part
//! as `M` ([`crate::sparse::SparseLu::set_gmres`]), where `A M^-1` is the
//! identity plus a small, local perturbation and a few iterations suffice.
//!
//! faer 0.24 has BiCGSTAB (`faer::operator::bicgstab`) but no GMRES;
//! GMRES is used because its residual decreases monotonically (a stalled
//! solve is seen and handed to the LU at once, not after erratic BiCGSTAB
//! steps), and with a preconditioner this close to the matrix one cycle
//! of a few iterations is enough, so its `k` stored vectors cost little.

/// How a GMRES solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GmresOutcome {
    /// `||b - A x|| <= tolerance ||b||` after this many iterations.
    Converged { iterations: usize },
    /// The iteration limit came first (`x` holds the last iterate).
    NotConverged { iterations: usize },
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Solves `A x = b` from `x_0 = 0`: `apply(v, y)` writes `A v` into `y`,
/// `precondition(z)` overwrites `z` with `M^-1 z`. Stops at a relative
/// residual of `tolerance` or after `max_iterations`.
pub fn gmres(
    mut apply: impl FnMut(&[f64], &mut [f64]),
    mut precondition: impl FnMut(&mut [f64]),
    b: &[f64],
    x: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> GmresOutcome {
    let n = b.len();
    x.iter_mut().for_each(|v| *v = 0.0);
    let beta = dot(b, b).sqrt();
    if beta == 0.0 {
        return GmresOutcome::Converged { iterations: 0 };
    }
    let m = max_iterations.max(1);
    let mut basis: Vec<Vec<f64>> = vec![b.iter().map(|v| v / beta).collect()];
    // h[j] is column j of the Hessenberg matrix (j + 2 entries), rotated
    let mut h: Vec<Vec<f64>> = Vec::with_capacity(m);
    let (mut cs, mut sn): (Vec<f64>, Vec<f64>) = (Vec::with_capacity(m), Vec::with_capacity(m));
    let mut g = vec![beta];
    let mut z = vec![0.0; n];
    let mut w = vec![0.0; n];
    let mut converged = false;
    let mut k = 0;
    while k < m {
        z.copy_from_slice(&basis[k]);
        precondition(&mut z);
        apply(&z, &mut w);
        let mut col = Vec::with_capacity(k + 2);
        for v in &basis {
            let hij = dot(&w, v);
            w.iter_mut().zip(v).for_each(|(a, b)| *a -= hij * b);
            col.push(hij);
        }
        let norm = dot(&w, &w).sqrt();
        col.push(norm);
        for i in 0..k {
            let (a, b) = (col[i], col[i + 1]);
            col[i] = cs[i] * a + sn[i] * b;
            col[i + 1] = -sn[i] * a + cs[i] * b;
        }
        let r = col[k].hypot(col[k + 1]);
        let (c, s) = if r == 0.0 {
            (1.0, 0.0)
        } else {
            (col[k] / r, col[k + 1] / r)
        };
        col[k] = r;
        col[k + 1] = 0.0;
        cs.push(c);
        sn.push(s);
        g.push(-s * g[k]);
        g[k] *= c;
        h.push(col);
        k += 1;
        if g[k].abs() <= tolerance * beta || norm == 0.0 || !norm.is_finite() {
            converged = g[k].abs() <= tolerance * beta || norm == 0.0;
            break;
        }
        basis.push(w.iter().map(|v| v / norm).collect());
    }
    // back substitution H y = g, then x = M^-1 V y
    let mut y = vec![0.0; k];
    for i in (0..k).rev() {
        let mut s = g[i];
        for (j, yj) in y.iter().enumerate().skip(i + 1) {
            s -= h[j][i] * yj;
        }
        y[i] = if h[i][i] != 0.0 { s / h[i][i] } else { 0.0 };
    }
    z.iter_mut().for_each(|v| *v = 0.0);
    for (v, yi) in basis.iter().zip(&y) {
        z.iter_mut().zip(v).for_each(|(a, b)| *a += yi * b);
    }
    precondition(&mut z);
    x.copy_from_slice(&z);
    if converged {
        GmresOutcome::Converged { iterations: k }
    } else {
        GmresOutcome::NotConverged { iterations: k }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A nonsymmetric tridiagonal system with a Jacobi preconditioner: the
    /// solution is recovered to the tolerance, and an iteration limit of 2
    /// is reported as not converged.
    #[test]
    fn solves_a_nonsymmetric_system_with_a_preconditioner() {
        let n = 30;
        let diag: Vec<f64> = (0..n).map(|i| 4.0 + 0.1 * i as f64).collect();
        let apply = |x: &[f64], y: &mut [f64]| {
            for i in 0..n {
                y[i] = diag[i] * x[i];
                if i > 0 {
                    y[i] -= 1.5 * x[i - 1];
                }
                if i + 1 < n {
                    y[i] += 0.5 * x[i + 1];
                }
            }
        };
        let exact: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).cos()).collect();
        let mut b = vec![0.0; n];
        apply(&exact, &mut b);
        let jacobi = |z: &mut [f64]| z.iter_mut().zip(&diag).for_each(|(v, d)| *v /= d);
        let mut x = vec![0.0; n];
        let out = gmres(apply, jacobi, &b, &mut x, 1e-12, 60);
        assert!(
            matches!(out, GmresOutcome::Converged { iterations } if iterations < 30),
            "{out:?}"
        );
        let err = x
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < 1e-10, "{err}");
        let out = gmres(apply, jacobi, &b, &mut x, 1e-12, 2);
        assert_eq!(out, GmresOutcome::NotConverged { iterations: 2 });
        let zero = gmres(apply, jacobi, &vec![0.0; n], &mut x, 1e-12, 5);
        assert_eq!(zero, GmresOutcome::Converged { iterations: 0 });
        assert!(x.iter().all(|v| *v == 0.0));
    }
}
