//! Generic kinematics: first Piola stress and its tangent `dP/dF` from the principal derivatives
//! of an isotropic isochoric energy, with the volumetric part added.
//!
//! # Formulation
//!
//! With `C = F^T F = sum_a l_a^2 N_a N_a^T` and `n_a = F N_a / l_a`, the energy of the full
//! stretches is `psi(l) = W(J^{-1/3} l) + U(J)`, `J = l1 l2 l3`. In log stretches `e_a = ln l_a`
//! the isochoric projection is linear, `ebar = (I - 1 1^T / 3) e`, so with
//! `gt_a = lbar_a W_a`, `Ht_ab = lbar_a lbar_b W_ab + delta_ab gt_a` (derivatives in `ebar`):
//!
//! * `g = dpsi/de = P gt + U'(J) J 1`,
//! * `H = d2psi/de2 = P Ht P + (U''(J) J^2 + U'(J) J) 1 1^T`, with `P = I - 1 1^T / 3`,
//! * `psi_a = g_a / l_a`, `psi_ab = (H_ab - delta_ab g_a) / (l_a l_b)`.
//!
//! Then (Ogden, *Non-linear Elastic Deformations*, 1984, sec. 6.1; Connolly, Mackenzie & Gorash,
//! Comput. Mech. 64 (2019) 1273-1288, eqs. for the first elasticity tensor):
//!
//! `P = sum_a psi_a n_a (x) N_a`,
//!
//! `A = sum_ab psi_ab (n_a (x) N_a)(x)(n_b (x) N_b)
//!    + sum_{a != b} c1_ab (n_a (x) N_b)(x)(n_a (x) N_b) + c2_ab (n_a (x) N_b)(x)(n_b (x) N_a)`,
//!
//! `c1_ab = (psi_a l_a - psi_b l_b) / (l_a^2 - l_b^2) = (gt_a - gt_b) / (l_a^2 - l_b^2)`,
//! `c2_ab = (psi_a l_b - psi_b l_a) / (l_a^2 - l_b^2) = (c1_ab l_b - psi_b) / l_a` (symmetrised in a, b).
//!
//! # Equal and near-equal stretches
//!
//! `c1_ab` is 0/0 when `l_a = l_b`. Its limit (L'Hopital along `e_a - e_b -> 0`) is
//! `c1_ab -> (H_aa + H_bb - 2 H_ab) / (4 l_a l_b)` (the volumetric and projection parts cancel in
//! both forms, so `Ht` is used). The limit is used whenever `|ln l_a - ln l_b| < 1e-6`: the
//! rounding error of the difference quotient there is about `1e-16 / 1e-6`, the truncation error of
//! the (symmetric, hence second order) limit about `(alpha * 1e-6)^2`. Within an eigenspace the
//! eigenvectors returned by the eigen-solver are arbitrary, but the limit formula gives the same
//! tensor for every orthonormal basis of it (it is the limit of the unique tangent of nearby
//! distinct-stretch states), so no perturbation of `F` is needed.

use nalgebra::{Matrix3, SMatrix, SVector, SymmetricEigen};
use serde::{Deserialize, Serialize};

use crate::Volumetric;

/// Energy `W` with its derivatives with respect to the principal stretches, taken as independent.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PrincipalDerivs {
    /// `W(l1, l2, l3)`.
    pub w: f64,
    /// `dW/dl_a`.
    pub dw: [f64; 3],
    /// `d2W/dl_a dl_b`.
    pub d2w: [[f64; 3]; 3],
}

impl PrincipalDerivs {
    /// All entries NaN (returned for unusable input instead of panicking).
    pub fn nan() -> Self {
        PrincipalDerivs {
            w: f64::NAN,
            dw: [f64::NAN; 3],
            d2w: [[f64::NAN; 3]; 3],
        }
    }
}

/// Energy, first Piola stress and material tangent at one deformation gradient.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StressTangent {
    /// `Psi(F) = W(J^{-1/3} F) + U(J)` in MPa (= mJ/mm^3).
    pub psi: f64,
    /// First Piola stress `P_ij = dPsi/dF_ij` in MPa.
    pub p: Matrix3<f64>,
    /// `A[(i*3 + j, k*3 + l)] = dP_ij / dF_kl` in MPa; symmetric (`A_ijkl = A_klij`).
    pub a: SMatrix<f64, 9, 9>,
}

impl StressTangent {
    /// All entries NaN.
    pub fn nan() -> Self {
        StressTangent {
            psi: f64::NAN,
            p: Matrix3::from_element(f64::NAN),
            a: SMatrix::<f64, 9, 9>::from_element(f64::NAN),
        }
    }
}

/// Relative stretch difference below which the equal-stretch limit of `c1_ab` is used.
const EQUAL_LOG_STRETCH: f64 = 1e-6;

/// `vec(a b^T)` with index `i*3 + j`.
fn dyad(a: &SVector<f64, 3>, b: &SVector<f64, 3>) -> SVector<f64, 9> {
    SVector::<f64, 9>::from_fn(|r, _| a[r / 3] * b[r % 3])
}

/// Stress and tangent of `Psi(F) = W(J^{-1/3} F) + U(J)` for an isotropic `W` given by its
/// principal derivatives `iso(lbar)` at isochoric stretches (see the module doc for the equations).
/// Returns NaN entries when `det F <= 0` or `F` is not finite.
pub fn stress_tangent(
    iso: impl Fn([f64; 3]) -> PrincipalDerivs,
    vol: Volumetric,
    f: &Matrix3<f64>,
) -> StressTangent {
    let j = f.determinant();
    if !(j > 0.0 && j.is_finite()) {
        return StressTangent::nan();
    }
    let eig = SymmetricEigen::new(f.transpose() * f);
    let lam: [f64; 3] = std::array::from_fn(|a| eig.eigenvalues[a].max(0.0).sqrt());
    if lam.iter().any(|&l| l <= 0.0) {
        return StressTangent::nan();
    }
    let jm13 = j.powf(-1.0 / 3.0);
    let lbar = lam.map(|l| l * jm13);
    let d = iso(lbar);

    // Derivatives of W in the isochoric log stretches.
    let gt: [f64; 3] = std::array::from_fn(|a| lbar[a] * d.dw[a]);
    let mut ht = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            ht[a][b] = lbar[a] * lbar[b] * 0.5 * (d.d2w[a][b] + d.d2w[b][a]);
        }
        ht[a][a] += gt[a];
    }
    // Project onto the deviatoric log strains and add the volumetric part.
    let (du, d2u) = (vol.du(j), vol.d2u(j));
    let gmean = (gt[0] + gt[1] + gt[2]) / 3.0;
    let g: [f64; 3] = std::array::from_fn(|a| gt[a] - gmean + du * j);
    let row: [f64; 3] = std::array::from_fn(|a| (ht[a][0] + ht[a][1] + ht[a][2]) / 3.0);
    let all = (row[0] + row[1] + row[2]) / 3.0;
    let kvol = d2u * j * j + du * j;
    let mut h = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            h[a][b] = ht[a][b] - row[a] - row[b] + all + kvol;
        }
    }
    // Derivatives in the full stretches.
    let psi_a: [f64; 3] = std::array::from_fn(|a| g[a] / lam[a]);
    let mut psi_ab = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            let diag = if a == b { g[a] } else { 0.0 };
            psi_ab[a][b] = (h[a][b] - diag) / (lam[a] * lam[b]);
        }
    }

    let big_n: [SVector<f64, 3>; 3] =
        std::array::from_fn(|a| eig.eigenvectors.column(a).into_owned());
    let small_n: [SVector<f64, 3>; 3] = std::array::from_fn(|a| f * big_n[a] / lam[a]);

    let mut p = Matrix3::zeros();
    for a in 0..3 {
        p += small_n[a] * big_n[a].transpose() * psi_a[a];
    }

    let m: [[SVector<f64, 9>; 3]; 3] =
        std::array::from_fn(|a| std::array::from_fn(|b| dyad(&small_n[a], &big_n[b])));
    let mut tangent = SMatrix::<f64, 9, 9>::zeros();
    for a in 0..3 {
        for b in 0..3 {
            tangent.ger(psi_ab[a][b], &m[a][a], &m[b][b], 1.0);
        }
    }
    for a in 0..3 {
        for b in 0..3 {
            if a == b {
                continue;
            }
            let c1 = if (lam[a].ln() - lam[b].ln()).abs() < EQUAL_LOG_STRETCH {
                (ht[a][a] + ht[b][b] - ht[a][b] - ht[b][a]) / (4.0 * lam[a] * lam[b])
            } else {
                (gt[a] - gt[b]) / (lam[a] * lam[a] - lam[b] * lam[b])
            };
            let c2 = 0.5 * ((c1 * lam[b] - psi_a[b]) / lam[a] + (c1 * lam[a] - psi_a[a]) / lam[b]);
            tangent.ger(c1, &m[a][b], &m[a][b], 1.0);
            tangent.ger(c2, &m[a][b], &m[b][a], 1.0);
        }
    }

    StressTangent {
        psi: d.w + vol.u(j),
        p,
        a: tangent,
    }
}
