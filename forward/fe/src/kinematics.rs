//! The kinematic idealisation of a two-dimensional element: how the in-plane
//! displacement field makes a 3 x 3 deformation gradient and what volume a
//! unit of reference area carries.
//!
//! Components are ordered (r, z, theta) for [`Kinematics::Axisymmetric`] and
//! (x, y, z) for [`Kinematics::PlaneStrain`]. A 2D element only ever touches
//! the five components `F00, F01, F10, F11, F22` ([`F_COMPONENTS`]).

//! The kinematic idealisation of a body: how the displacement field makes a
//! 3 x 3 deformation gradient `F`, which components of `F` vary with the
//! unknowns (the "B" operator: `dF_k / du_(a, c)` for node `a`, component
//! `c`), what volume a unit of reference measure carries, and, for plane
//! stress, how the out-of-plane stretch is condensed at the point.
//! Elements and contact take all of this from here.
//!
//! Components of `F` are indexed row-major, `k = 3 i + j` for `F_ij`.
//! Coordinates are (x, y, z) for [`Kinematics::ThreeD`], (x, y) in-plane with
//! z out of plane for the plane idealisations, and (r, z, theta) =
//! (x, y, hoop) for [`Kinematics::Axisymmetric`].

use nalgebra::Matrix3;
use palpate_material::Volumetric;
use serde::{Deserialize, Serialize};

use crate::material::PointMaterial;

/// Indices (row-major, `3 i + j`) of the five deformation-gradient
/// components an axisymmetric or plane-strain element carries.
pub const F_COMPONENTS: [usize; 5] = [0, 1, 3, 4, 8];

/// The in-plane components of a plane-stress element (`F22` is condensed).
pub const F_IN_PLANE: [usize; 4] = [0, 1, 3, 4];

/// All nine components (3D).
pub const F_ALL: [usize; 9] = [0, 1, 2, 3, 4, 5, 6, 7, 8];

/// The kinematic idealisation owned by a body.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kinematics {
    /// Three-dimensional continuum: three displacement components per node.
    ThreeD,
    /// Body of revolution about the y (= z_axial) axis, x = r: hoop stretch
    /// `F22 = r / R = 1 + u_r / R`, volume element `2 pi R dR dZ` (the whole
    /// 360 degrees).
    Axisymmetric,
    /// Plane strain of a slab of the given thickness (mm): `F22 = 1`.
    PlaneStrain { thickness: f64 },
    /// Plane stress of a thin sheet of the given (reference) thickness (mm):
    /// `P22 = 0`. Incompressible laws: `F22 = 1 / det F_2D` (the pressure is
    /// eliminated by the plane-stress condition, no pressure field);
    /// compressible: `F22` solves `P22(F22) = 0` at the point (Newton), and
    /// the in-plane tangent is the static condensation
    /// `A_ab,cd - A_ab,22 A_22,cd / A_22,22`.
    PlaneStress { thickness: f64 },
}

impl Kinematics {
    /// Displacement components per node (2 or 3).
    pub fn dim(&self) -> usize {
        match self {
            Kinematics::ThreeD => 3,
            _ => 2,
        }
    }

    /// The components of `F` that vary with the unknowns (the rows of B).
    pub fn components(&self) -> &'static [usize] {
        match self {
            Kinematics::ThreeD => &F_ALL,
            Kinematics::Axisymmetric | Kinematics::PlaneStrain { .. } => &F_COMPONENTS,
            Kinematics::PlaneStress { .. } => &F_IN_PLANE,
        }
    }

    /// Whether the body needs a pressure field to be locking-free (every
    /// idealisation but plane stress, where the plane-stress condition
    /// removes the volumetric constraint).
    pub fn needs_pressure(&self) -> bool {
        !matches!(self, Kinematics::PlaneStress { .. })
    }

    /// Checks the thickness of the plane idealisations.
    pub fn check(&self) -> Result<(), String> {
        match *self {
            Kinematics::PlaneStrain { thickness } | Kinematics::PlaneStress { thickness }
                if !(thickness > 0.0 && thickness.is_finite()) =>
            {
                Err(format!("thickness {thickness} must be > 0"))
            }
            _ => Ok(()),
        }
    }

    /// Reference volume per unit reference measure (area in 2D, volume in
    /// 3D) at the reference point `x_ref`.
    pub fn volume_factor(&self, r_ref: f64) -> f64 {
        match *self {
            Kinematics::Axisymmetric => 2.0 * std::f64::consts::PI * r_ref,
            Kinematics::PlaneStrain { thickness } | Kinematics::PlaneStress { thickness } => {
                thickness
            }
            Kinematics::ThreeD => 1.0,
        }
    }

    /// Out-of-plane stretch `F22` of the axisymmetric and plane-strain
    /// idealisations and its derivative with respect to the in-plane
    /// displacement component 0 at a point with interpolated reference
    /// coordinate `r_ref` and displacement `u_r`: `(F22, dF22/du_r)`;
    /// multiply the latter by the shape function. (Plane stress: `(1, 0)`,
    /// replaced by [`Kinematics::stress_tangent`]; 3D: unused.)
    pub fn out_of_plane(&self, r_ref: f64, u_r: f64) -> (f64, f64) {
        match *self {
            Kinematics::Axisymmetric => (1.0 + u_r / r_ref, 1.0 / r_ref),
            _ => (1.0, 0.0),
        }
    }

    /// First Piola stress `P` and tangent `A = dP/dF` of `mat` at `f`
    /// restricted to [`Kinematics::components`] (full `3 i + j` indexing,
    /// other entries zero), for the isochoric part (the volumetric part is
    /// the element's pressure field) — except in plane stress, where the
    /// whole energy is condensed at the point (see
    /// [`Kinematics::PlaneStress`]) and `f[(2, 2)]` is overwritten with the
    /// condensed stretch. `vol` is the volumetric treatment of the law.
    /// `None` when the point cannot be evaluated (no plane-stress stretch
    /// found, non-finite stress).
    pub fn stress_tangent(
        &self,
        mat: &dyn PointMaterial,
        vol: Volumetric,
        f: &mut Matrix3<f64>,
        tangent: bool,
    ) -> Option<([f64; 9], [[f64; 9]; 9])> {
        let mut p = [0.0; 9];
        let mut a = [[0.0; 9]; 9];
        match self {
            Kinematics::ThreeD => {
                let (p9, a9) = mat.iso_stress_tangent(f);
                for k in 0..9 {
                    p[k] = p9[(k / 3, k % 3)];
                    if tangent {
                        for l in 0..9 {
                            a[k][l] = a9[(k, l)];
                        }
                    }
                }
            }
            Kinematics::Axisymmetric | Kinematics::PlaneStrain { .. } => {
                let (p5, a5) = mat.iso_stress_tangent_2d(f, tangent);
                for (r, &k) in F_COMPONENTS.iter().enumerate() {
                    p[k] = p5[r];
                    for (s, &l) in F_COMPONENTS.iter().enumerate() {
                        a[k][l] = a5[r][s];
                    }
                }
            }
            Kinematics::PlaneStress { .. } => return plane_stress(mat, vol, f, tangent),
        }
        p.iter().all(|v| v.is_finite()).then_some((p, a))
    }
}

/// Total (isochoric + volumetric `U(J)`) stress and tangent of `mat` at `f`
/// on all nine components: `P = P_iso + U'(J) cof F`,
/// `A = A_iso + U''(J) cof F (x) cof F + U'(J) d2J/dF2`.
pub fn total_stress_tangent(
    mat: &dyn PointMaterial,
    vol: Volumetric,
    f: &Matrix3<f64>,
) -> ([f64; 9], [[f64; 9]; 9]) {
    let (p9, a9) = mat.iso_stress_tangent(f);
    let (j, cof, h) = jacobian_derivs_3d(f);
    let (du, d2u) = (vol.du(j), vol.d2u(j));
    let mut p = [0.0; 9];
    let mut a = [[0.0; 9]; 9];
    for k in 0..9 {
        p[k] = p9[(k / 3, k % 3)] + du * cof[k];
        for l in 0..9 {
            a[k][l] = a9[(k, l)] + d2u * cof[k] * cof[l] + du * h[k][l];
        }
    }
    (p, a)
}

/// Plane-stress condensation at a point (see [`Kinematics::PlaneStress`]).
fn plane_stress(
    mat: &dyn PointMaterial,
    vol: Volumetric,
    f: &mut Matrix3<f64>,
    tangent: bool,
) -> Option<([f64; 9], [[f64; 9]; 9])> {
    let det2 = f[(0, 0)] * f[(1, 1)] - f[(0, 1)] * f[(1, 0)];
    if !(det2 > 0.0) {
        return None;
    }
    let mut p = [0.0; 9];
    let mut a = [[0.0; 9]; 9];
    match vol {
        Volumetric::Incompressible => {
            // F22 = 1 / d, d = det F_2D: dF22/dF_ab = -c_ab / d^2 with the
            // cofactor c = (F11, -F10, -F01, F00) on (00, 01, 10, 11), and
            // d2F22 = 2 c c / d^3 - dc/dF / d^2.
            let f22 = 1.0 / det2;
            f[(2, 2)] = f22;
            // the five components F00, F01, F10, F11, F22 of P_iso and A_iso
            // (the 2D path: the stress alone when no tangent is asked for)
            let (p5, a5) = mat.iso_stress_tangent_2d(f, tangent);
            let c = [f[(1, 1)], -f[(1, 0)], -f[(0, 1)], f[(0, 0)]];
            let g: [f64; 4] = std::array::from_fn(|r| -c[r] * f22 * f22);
            // dc_r / dF_s: c00/dF11 = 1, c01/dF10 = -1, c10/dF01 = -1, c11/dF00 = 1
            let dc = |r: usize, s: usize| -> f64 {
                match (r, s) {
                    (0, 3) | (3, 0) => 1.0,
                    (1, 2) | (2, 1) => -1.0,
                    _ => 0.0,
                }
            };
            // (F_IN_PLANE[r] == F_COMPONENTS[r] for r < 4; F22 is 4)
            let p22 = p5[4];
            for (r, &k) in F_IN_PLANE.iter().enumerate() {
                p[k] = p5[r] + p22 * g[r];
                if !tangent {
                    continue;
                }
                for (s, &l) in F_IN_PLANE.iter().enumerate() {
                    let h = 2.0 * c[r] * c[s] * f22 * f22 * f22 - dc(r, s) * f22 * f22;
                    a[k][l] = a5[r][s]
                        + a5[r][4] * g[s]
                        + a5[4][s] * g[r]
                        + a5[4][4] * g[r] * g[s]
                        + p22 * h;
                }
            }
        }
        Volumetric::D1(_) => {
            // Newton on P22(F22) = 0 from the incompressible guess.
            let mut f22 = 1.0 / det2;
            let mut converged = false;
            for _ in 0..50 {
                f[(2, 2)] = f22;
                let (pt, at) = total_stress_tangent(mat, vol, f);
                let (r, d) = (pt[8], at[8][8]);
                if !(d > 0.0) || !r.is_finite() {
                    return None;
                }
                let step = r / d;
                let mut next = f22 - step;
                if next <= 0.0 {
                    next = 0.5 * f22;
                }
                f22 = next;
                if step.abs() <= 1e-14 * f22 {
                    converged = true;
                    break;
                }
            }
            if !converged {
                return None;
            }
            f[(2, 2)] = f22;
            let (pt, at) = total_stress_tangent(mat, vol, f);
            for &k in &F_IN_PLANE {
                p[k] = pt[k];
                if !tangent {
                    continue;
                }
                for &l in &F_IN_PLANE {
                    a[k][l] = at[k][l] - at[k][8] * at[8][l] / at[8][8];
                }
            }
        }
    }
    p.iter().all(|v| v.is_finite()).then_some((p, a))
}

/// `J = det F`, its gradient (the cofactor, `dJ/dF_ij`, row-major) and its
/// Hessian `d2J / dF_ij dF_kl = e_ikm e_jln F_mn` (Holzapfel, *Nonlinear
/// Solid Mechanics*, 2000, 1.255) for a full 3 x 3 gradient.
pub fn jacobian_derivs_3d(f: &Matrix3<f64>) -> (f64, [f64; 9], [[f64; 9]; 9]) {
    let j = f.determinant();
    let cof = [
        f[(1, 1)] * f[(2, 2)] - f[(1, 2)] * f[(2, 1)],
        f[(1, 2)] * f[(2, 0)] - f[(1, 0)] * f[(2, 2)],
        f[(1, 0)] * f[(2, 1)] - f[(1, 1)] * f[(2, 0)],
        f[(0, 2)] * f[(2, 1)] - f[(0, 1)] * f[(2, 2)],
        f[(0, 0)] * f[(2, 2)] - f[(0, 2)] * f[(2, 0)],
        f[(0, 1)] * f[(2, 0)] - f[(0, 0)] * f[(2, 1)],
        f[(0, 1)] * f[(1, 2)] - f[(0, 2)] * f[(1, 1)],
        f[(0, 2)] * f[(1, 0)] - f[(0, 0)] * f[(1, 2)],
        f[(0, 0)] * f[(1, 1)] - f[(0, 1)] * f[(1, 0)],
    ];
    let eps = |a: usize, b: usize, c: usize| -> f64 {
        match (a, b, c) {
            (0, 1, 2) | (1, 2, 0) | (2, 0, 1) => 1.0,
            (0, 2, 1) | (2, 1, 0) | (1, 0, 2) => -1.0,
            _ => 0.0,
        }
    };
    let mut h = [[0.0; 9]; 9];
    for i in 0..3 {
        for jj in 0..3 {
            for k in 0..3 {
                for l in 0..3 {
                    if i == k || jj == l {
                        continue;
                    }
                    let (m, n) = (3 - i - k, 3 - jj - l);
                    h[3 * i + jj][3 * k + l] = eps(i, k, m) * eps(jj, l, n) * f[(m, n)];
                }
            }
        }
    }
    (j, cof, h)
}

/// `J = det F` of the 5-component gradient `[F00, F01, F10, F11, F22]`, its
/// gradient and its (constant-pattern) Hessian.
pub fn jacobian_derivs(f: &[f64; 5]) -> (f64, [f64; 5], [[f64; 5]; 5]) {
    let [f00, f01, f10, f11, f22] = *f;
    let det2 = f00 * f11 - f01 * f10;
    let j = det2 * f22;
    let g = [f11 * f22, -f10 * f22, -f01 * f22, f00 * f22, det2];
    let mut h = [[0.0; 5]; 5];
    let mut set = |a: usize, b: usize, v: f64| {
        h[a][b] = v;
        h[b][a] = v;
    };
    set(0, 3, f22);
    set(1, 2, -f22);
    set(0, 4, f11);
    set(3, 4, f00);
    set(1, 4, -f10);
    set(2, 4, -f01);
    (j, g, h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::NeoHookeanIso;

    #[test]
    fn jacobian_3d_derivatives_match_finite_differences() {
        let f = Matrix3::new(1.1, 0.2, -0.1, -0.3, 0.9, 0.05, 0.02, 0.1, 1.05);
        let (j, g, h) = jacobian_derivs_3d(&f);
        assert!((j - f.determinant()).abs() < 1e-14);
        let eps = 1e-6;
        for k in 0..9 {
            let (mut fp, mut fm) = (f, f);
            fp[(k / 3, k % 3)] += eps;
            fm[(k / 3, k % 3)] -= eps;
            let (jp, gp, _) = jacobian_derivs_3d(&fp);
            let (jm, gm, _) = jacobian_derivs_3d(&fm);
            assert!(((jp - jm) / (2.0 * eps) - g[k]).abs() < 1e-8);
            for l in 0..9 {
                assert!(((gp[l] - gm[l]) / (2.0 * eps) - h[l][k]).abs() < 1e-8);
            }
        }
    }

    /// Plane stress: the condensed stress is the derivative of the
    /// condensed energy and the tangent the derivative of the stress, for
    /// the exact (F22 = 1/det) and the compressible (P22 = 0) forms; and
    /// P22 = 0 is met.
    #[test]
    fn plane_stress_condensation_matches_finite_differences() {
        let m = NeoHookeanIso { c10: 0.4 };
        let kin = Kinematics::PlaneStress { thickness: 1.0 };
        for vol in [Volumetric::Incompressible, Volumetric::D1(0.5)] {
            let f0 = Matrix3::new(1.2, 0.15, 0.0, -0.1, 0.85, 0.0, 0.0, 0.0, 1.0);
            let mut f = f0;
            let (p, a) = kin.stress_tangent(&m, vol, &mut f, true).unwrap();
            if let Volumetric::D1(_) = vol {
                let (pt, _) = total_stress_tangent(&m, vol, &f);
                assert!(pt[8].abs() < 1e-10, "P22 = {}", pt[8]);
            } else {
                let d = f0[(0, 0)] * f0[(1, 1)] - f0[(0, 1)] * f0[(1, 0)];
                assert!((f[(2, 2)] * d - 1.0).abs() < 1e-14);
            }
            let h = 1e-6;
            for &l in &F_IN_PLANE {
                let (mut fp, mut fm) = (f0, f0);
                fp[(l / 3, l % 3)] += h;
                fm[(l / 3, l % 3)] -= h;
                let (pp, _) = kin.stress_tangent(&m, vol, &mut fp, false).unwrap();
                let (pm, _) = kin.stress_tangent(&m, vol, &mut fm, false).unwrap();
                for &k in &F_IN_PLANE {
                    let fd = (pp[k] - pm[k]) / (2.0 * h);
                    assert!(
                        (fd - a[k][l]).abs() < 1e-6,
                        "{vol:?} A[{k}][{l}] {} vs {fd}",
                        a[k][l]
                    );
                }
            }
            // stress = d energy / dF with the energy of the condensed state
            let energy = |f2: Matrix3<f64>| -> f64 {
                let mut ff = f2;
                kin.stress_tangent(&m, vol, &mut ff, false).unwrap();
                let j = ff.determinant();
                let fb = ff * j.powf(-1.0 / 3.0);
                m.c10 * (fb.norm_squared() - 3.0) + vol.u(j)
            };
            for &k in &F_IN_PLANE {
                let (mut fp, mut fm) = (f0, f0);
                fp[(k / 3, k % 3)] += h;
                fm[(k / 3, k % 3)] -= h;
                let fd = (energy(fp) - energy(fm)) / (2.0 * h);
                assert!((fd - p[k]).abs() < 1e-6, "{vol:?} P[{k}] {} vs {fd}", p[k]);
            }
        }
    }

    #[test]
    fn jacobian_derivatives_match_finite_differences() {
        let f = [1.1, 0.2, -0.3, 0.9, 1.05];
        let (j, g, h) = jacobian_derivs(&f);
        assert!((j - (1.1 * 0.9 + 0.06) * 1.05).abs() < 1e-14);
        let eps = 1e-6;
        for k in 0..5 {
            let (mut fp, mut fm) = (f, f);
            fp[k] += eps;
            fm[k] -= eps;
            let (jp, gp, _) = jacobian_derivs(&fp);
            let (jm, gm, _) = jacobian_derivs(&fm);
            assert!(((jp - jm) / (2.0 * eps) - g[k]).abs() < 1e-8);
            for l in 0..5 {
                assert!(((gp[l] - gm[l]) / (2.0 * eps) - h[l][k]).abs() < 1e-8);
            }
        }
    }
}
