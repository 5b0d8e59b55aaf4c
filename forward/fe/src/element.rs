//! The 4-node quadrilateral with a constant (P0) pressure and dilatation per
//! element: the Simo-Taylor-Pister three-field element (Q1/P0), locking-free
//! for near and exact incompressibility.
//!
//! With the decoupled energy `Psi(F) = W(J^{-1/3} F) + U(J)` the three-field
//! functional with piecewise-constant pressure and dilatation condenses to
//!
//! ```text
//! Pi_e(u) = sum_gp W_iso(F_gp) dV_gp + V_e U(v_e / V_e)            (penalty, U from D1)
//! Pi_e(u, q) = sum_gp W_iso(F_gp) dV_gp + s q (v_e - V_e)           (exact constraint)
//! ```
//!
//! where `V_e` and `v_e = sum_gp J_gp dV_gp` are the reference and current
//! element volumes (Simo, Taylor & Pister 1985, CMAME 51:177; the "mean
//! dilatation" form of Nagtegaal, Parks & Rice 1974). `v_e` is computed
//! exactly by the 2 x 2 rule (the integrand is of degree 2 in each variable).
//! The Lagrange multiplier `q` is scaled by `s = mu / sqrt(A_e)` so that its
//! row has the magnitude of the displacement rows; the pressure (mean stress,
//! tension positive) is `p = s q`. Residual and tangent are the exact first
//! and second derivatives of `Pi_e`, so the tangent is symmetric.

use nalgebra::Matrix3;

use crate::kinematics::{jacobian_derivs, Kinematics};
use crate::material::PointMaterial;
use crate::quadrature::gauss_2x2;
use crate::FeError;

/// How the element enforces incompressibility.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VolumeConstraint {
    /// `U(J) = (J - 1)^2 / D1` of the mean dilatation (bulk modulus `2 / D1`).
    Penalty { d1: f64 },
    /// `v_e = V_e` exactly, with a Lagrange multiplier per element scaled by
    /// `scale` (MPa per unit multiplier).
    Exact { scale: f64 },
}

impl VolumeConstraint {
    /// Local degrees of freedom: 8 displacements, plus the multiplier.
    pub fn local_dofs(&self) -> usize {
        match self {
            VolumeConstraint::Penalty { .. } => 8,
            VolumeConstraint::Exact { .. } => 9,
        }
    }
}

/// Residual (internal force) and tangent of one element; dof order
/// `(u_r, u_z)` of corners 0..3, then the multiplier.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementOutput {
    pub residual: [f64; 9],
    pub tangent: [[f64; 9]; 9],
    /// Current volume `v_e` (mm^3).
    pub volume: f64,
    /// Reference volume `V_e` (mm^3).
    pub ref_volume: f64,
    /// Element pressure (mean stress, MPa, tension positive).
    pub pressure: f64,
}

impl Default for ElementOutput {
    fn default() -> Self {
        ElementOutput {
            residual: [0.0; 9],
            tangent: [[0.0; 9]; 9],
            volume: 0.0,
            ref_volume: 0.0,
            pressure: 0.0,
        }
    }
}

/// Geometry of one quadrature point: shape functions and reference gradients.
struct PointGeom {
    n: [f64; 4],
    dn: [[f64; 2]; 4],
    r_ref: f64,
    dv: f64,
}

fn point_geom(kin: Kinematics, x: &[[f64; 2]; 4], xi: [f64; 2], w: f64) -> Result<PointGeom, f64> {
    let (s, t) = (xi[0], xi[1]);
    let n = [
        0.25 * (1.0 - s) * (1.0 - t),
        0.25 * (1.0 + s) * (1.0 - t),
        0.25 * (1.0 + s) * (1.0 + t),
        0.25 * (1.0 - s) * (1.0 + t),
    ];
    let dns = [
        [-0.25 * (1.0 - t), -0.25 * (1.0 - s)],
        [0.25 * (1.0 - t), -0.25 * (1.0 + s)],
        [0.25 * (1.0 + t), 0.25 * (1.0 + s)],
        [-0.25 * (1.0 + t), 0.25 * (1.0 - s)],
    ];
    let mut jac = [[0.0; 2]; 2]; // jac[i][k] = dX_i / dxi_k
    let mut r_ref = 0.0;
    for a in 0..4 {
        r_ref += n[a] * x[a][0];
        for i in 0..2 {
            for k in 0..2 {
                jac[i][k] += x[a][i] * dns[a][k];
            }
        }
    }
    let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
    if det <= 0.0 {
        return Err(det);
    }
    // dN/dX = dN/dxi * (dxi/dX); closed-form 2x2 inverse of the Jacobian.
    let inv = [
        [jac[1][1] / det, -jac[0][1] / det],
        [-jac[1][0] / det, jac[0][0] / det],
    ];
    let mut dn = [[0.0; 2]; 4];
    for a in 0..4 {
        for j in 0..2 {
            dn[a][j] = dns[a][0] * inv[0][j] + dns[a][1] * inv[1][j];
        }
    }
    Ok(PointGeom {
        n,
        dn,
        r_ref,
        dv: kin.volume_factor(r_ref) * det * w,
    })
}

/// Reference volume of an element (mm^3).
pub fn reference_volume(kin: Kinematics, x: &[[f64; 2]; 4]) -> f64 {
    gauss_2x2()
        .iter()
        .map(|&(xi, w)| point_geom(kin, x, xi, w).map(|g| g.dv).unwrap_or(0.0))
        .sum()
}

/// The 5-component deformation gradient and its B matrix (5 x 8) at a point.
fn gradient(kin: Kinematics, g: &PointGeom, u: &[[f64; 2]; 4]) -> ([f64; 5], [[f64; 8]; 5]) {
    let mut grad = [[0.0; 2]; 2];
    let mut ur = 0.0;
    for a in 0..4 {
        ur += g.n[a] * u[a][0];
        for i in 0..2 {
            for j in 0..2 {
                grad[i][j] += u[a][i] * g.dn[a][j];
            }
        }
    }
    let (f22, df22) = kin.out_of_plane(g.r_ref, ur);
    let f = [
        1.0 + grad[0][0],
        grad[0][1],
        grad[1][0],
        1.0 + grad[1][1],
        f22,
    ];
    let mut b = [[0.0; 8]; 5];
    for a in 0..4 {
        b[0][2 * a] = g.dn[a][0];
        b[1][2 * a] = g.dn[a][1];
        b[2][2 * a + 1] = g.dn[a][0];
        b[3][2 * a + 1] = g.dn[a][1];
        b[4][2 * a] = g.n[a] * df22;
    }
    (f, b)
}

fn full_f(f: &[f64; 5]) -> Matrix3<f64> {
    Matrix3::new(f[0], f[1], 0.0, f[2], f[3], 0.0, 0.0, 0.0, f[4])
}

/// Residual and (when `tangent`) tangent of one element.
///
/// `x`: reference corner coordinates, `u`: corner displacements, `q`: the
/// element multiplier (ignored for the penalty form).
#[allow(clippy::too_many_arguments)]
pub fn quad4(
    kin: Kinematics,
    x: &[[f64; 2]; 4],
    u: &[[f64; 2]; 4],
    q: f64,
    mat: &dyn PointMaterial,
    constraint: VolumeConstraint,
    tangent: bool,
    element: usize,
    out: &mut ElementOutput,
) -> Result<(), FeError> {
    out.residual = [0.0; 9];
    if tangent {
        out.tangent = [[0.0; 9]; 9];
    }
    let mut dvol = [0.0; 8];
    let mut d2vol = [[0.0; 8]; 8];
    let (mut vol, mut vref) = (0.0, 0.0);
    for (xi, w) in gauss_2x2() {
        let g = point_geom(kin, x, xi, w).map_err(|det| FeError::InvalidMesh {
            field: format!("element {element}"),
            reason: format!(
                "reference Jacobian {det:.3e} <= 0 (corners must be counter-clockwise)"
            ),
        })?;
        let (f, b) = gradient(kin, &g, u);
        let (j, dj, hj) = jacobian_derivs(&f);
        if !(j > 0.0) || !(f[0] * f[3] - f[1] * f[2] > 0.0) {
            return Err(FeError::InvertedElement { element, det_f: j });
        }
        let (p5, a5) = mat.iso_stress_tangent_2d(&full_f(&f), tangent);
        if p5.iter().any(|v| !v.is_finite()) {
            return Err(FeError::NonFiniteStress { element });
        }
        vol += j * g.dv;
        vref += g.dv;
        for c in 0..8 {
            let mut sp = 0.0;
            let mut sj = 0.0;
            for k in 0..5 {
                sp += b[k][c] * p5[k];
                sj += b[k][c] * dj[k];
            }
            out.residual[c] += sp * g.dv;
            dvol[c] += sj * g.dv;
        }
        if tangent {
            // B^T A B and B^T H_J B, using the sparsity of B (each column has
            // at most three non-zero rows).
            let mut ab = [[0.0; 8]; 5]; // A B and H B
            let mut hb = [[0.0; 8]; 5];
            for k in 0..5 {
                for c in 0..8 {
                    let (mut s1, mut s2) = (0.0, 0.0);
                    for l in 0..5 {
                        s1 += a5[k][l] * b[l][c];
                        s2 += hj[k][l] * b[l][c];
                    }
                    ab[k][c] = s1;
                    hb[k][c] = s2;
                }
            }
            for c in 0..8 {
                for d in 0..8 {
                    let (mut s1, mut s2) = (0.0, 0.0);
                    for k in 0..5 {
                        s1 += b[k][c] * ab[k][d];
                        s2 += b[k][c] * hb[k][d];
                    }
                    out.tangent[c][d] += s1 * g.dv;
                    d2vol[c][d] += s2 * g.dv;
                }
            }
        }
    }
    out.volume = vol;
    out.ref_volume = vref;
    match constraint {
        VolumeConstraint::Penalty { d1 } => {
            let theta = vol / vref;
            let du = 2.0 * (theta - 1.0) / d1;
            let d2u = 2.0 / d1;
            out.pressure = du;
            for c in 0..8 {
                out.residual[c] += du * dvol[c];
            }
            if tangent {
                for c in 0..8 {
                    for d in 0..8 {
                        out.tangent[c][d] += d2u / vref * dvol[c] * dvol[d] + du * d2vol[c][d];
                    }
                }
            }
        }
        VolumeConstraint::Exact { scale } => {
            let p = scale * q;
            out.pressure = p;
            for c in 0..8 {
                out.residual[c] += p * dvol[c];
            }
            out.residual[8] = scale * (vol - vref);
            if tangent {
                for c in 0..8 {
                    for d in 0..8 {
                        out.tangent[c][d] += p * d2vol[c][d];
                    }
                    out.tangent[c][8] = scale * dvol[c];
                    out.tangent[8][c] = scale * dvol[c];
                }
                out.tangent[8][8] = 0.0;
            }
        }
    }
    Ok(())
}

/// Element-average Cauchy stress (MPa, components rr, zz, tt, rz) for output.
pub fn mean_cauchy_stress(
    kin: Kinematics,
    x: &[[f64; 2]; 4],
    u: &[[f64; 2]; 4],
    pressure: f64,
    mat: &dyn PointMaterial,
) -> [f64; 4] {
    let mut s = [0.0; 4];
    let mut vsum = 0.0;
    for (xi, w) in gauss_2x2() {
        let Ok(g) = point_geom(kin, x, xi, w) else {
            continue;
        };
        let (f5, _) = gradient(kin, &g, u);
        let f = full_f(&f5);
        let j = f.determinant();
        let (p_iso, _) = mat.iso_stress_tangent(&f);
        // sigma = J^{-1} P F^T + p I (the volumetric part p J F^{-T} gives p I)
        let sig = p_iso * f.transpose() / j + Matrix3::identity() * pressure;
        for (k, (i, jj)) in [(0, 0), (1, 1), (2, 2), (0, 1)].into_iter().enumerate() {
            s[k] += sig[(i, jj)] * g.dv;
        }
        vsum += g.dv;
    }
    s.map(|v| v / vsum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::NeoHookeanIso;

    fn setup() -> ([[f64; 2]; 4], [[f64; 2]; 4]) {
        let x = [[0.5, 0.0], [1.6, 0.1], [1.5, 1.2], [0.4, 0.9]];
        let u = [[0.05, -0.02], [0.1, 0.03], [-0.04, -0.1], [0.02, 0.05]];
        (x, u)
    }

    fn check_fd(constraint: VolumeConstraint, kin: Kinematics) {
        let (x, u) = setup();
        let m = NeoHookeanIso { c10: 0.5 };
        let q = 0.3;
        let mut out = ElementOutput::default();
        quad4(kin, &x, &u, q, &m, constraint, true, 0, &mut out).unwrap();
        let n = constraint.local_dofs();
        let h = 1e-6;
        let mut plus = ElementOutput::default();
        let mut minus = ElementOutput::default();
        for c in 0..n {
            let (mut up, mut um, mut qp, mut qm) = (u, u, q, q);
            if c < 8 {
                up[c / 2][c % 2] += h;
                um[c / 2][c % 2] -= h;
            } else {
                qp += h;
                qm -= h;
            }
            quad4(kin, &x, &up, qp, &m, constraint, false, 0, &mut plus).unwrap();
            quad4(kin, &x, &um, qm, &m, constraint, false, 0, &mut minus).unwrap();
            for r in 0..n {
                let fd = (plus.residual[r] - minus.residual[r]) / (2.0 * h);
                let k = out.tangent[r][c];
                assert!(
                    (fd - k).abs() < 1e-6 * (1.0 + k.abs()),
                    "{constraint:?} K[{r}][{c}] = {k}, fd {fd}"
                );
            }
        }
        // symmetric tangent (energy-derived)
        for r in 0..n {
            for c in 0..n {
                assert!(
                    (out.tangent[r][c] - out.tangent[c][r]).abs()
                        < 1e-10 * (1.0 + out.tangent[r][c].abs())
                );
            }
        }
    }

    #[test]
    fn tangent_matches_finite_differences_penalty_and_exact() {
        for kin in [
            Kinematics::Axisymmetric,
            Kinematics::PlaneStrain { thickness: 2.0 },
        ] {
            check_fd(VolumeConstraint::Penalty { d1: 0.01 }, kin);
            check_fd(VolumeConstraint::Exact { scale: 0.7 }, kin);
        }
    }

    #[test]
    fn reference_volume_is_pappus() {
        // Rectangle r in [1, 3], z in [0, 2]: V = 2 pi * area * centroid = 2 pi * 4 * 2
        let x = [[1.0, 0.0], [3.0, 0.0], [3.0, 2.0], [1.0, 2.0]];
        let v = reference_volume(Kinematics::Axisymmetric, &x);
        assert!((v - 16.0 * std::f64::consts::PI).abs() < 1e-12);
        // current volume after a rigid translation in z is unchanged, residual zero
        let u = [[0.0, 0.3]; 4];
        let mut out = ElementOutput::default();
        let m = NeoHookeanIso { c10: 0.5 };
        quad4(
            Kinematics::Axisymmetric,
            &x,
            &u,
            0.0,
            &m,
            VolumeConstraint::Penalty { d1: 0.1 },
            false,
            0,
            &mut out,
        )
        .unwrap();
        assert!((out.volume - v).abs() < 1e-12);
        assert!(out.residual.iter().all(|r| r.abs() < 1e-12));
    }
}
