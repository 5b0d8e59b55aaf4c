//! The pointwise material seen by the elements: isochoric stress and tangent
//! from a deformation gradient. The volumetric part is the element's business
//! (mean dilatation penalty or an exact constraint, see [`crate::element`]).

use nalgebra::{Matrix3, SMatrix};
use palpate_material::{Law, Volumetric};

use crate::FeError;

/// First Piola stress and tangent `A = dP/dF` (9 x 9, index `3 i + j` for `F_ij`).
pub type StressTangent9 = (Matrix3<f64>, SMatrix<f64, 9, 9>);

/// A hyperelastic material at a quadrature point: the isochoric part
/// `W(J^{-1/3} F)` only.
pub trait PointMaterial: Sync {
    /// `P_iso = dW/dF` and `A_iso = dP_iso/dF` at `f`.
    fn iso_stress_tangent(&self, f: &Matrix3<f64>) -> StressTangent9;
    /// Initial shear modulus (MPa), used to scale penalties and tolerances.
    fn shear_modulus(&self) -> f64;
}

/// A palpate-material [`Law`] with its parameters (MPa or dimensionless).
#[derive(Debug, Clone, PartialEq)]
pub struct LawMaterial {
    pub law: Law,
    pub params: Vec<f64>,
}

impl LawMaterial {
    /// Checks the parameters with [`Law::check`].
    pub fn new(law: Law, params: Vec<f64>) -> Result<Self, FeError> {
        law.check(&params).map_err(|e| FeError::InvalidConfig {
            field: "material".into(),
            reason: e.to_string(),
        })?;
        Ok(LawMaterial { law, params })
    }
}

impl PointMaterial for LawMaterial {
    fn iso_stress_tangent(&self, f: &Matrix3<f64>) -> StressTangent9 {
        let st = self
            .law
            .stress_tangent(&self.params, Volumetric::Incompressible, f);
        (st.p, st.a)
    }
    fn shear_modulus(&self) -> f64 {
        self.law.shear_modulus(&self.params)
    }
}

/// Incompressible neo-Hookean `W = C10 (I1b - 3)` with its closed-form
/// stress and tangent, kept for tests of the element that must not depend on
/// the material crate (Holzapfel, *Nonlinear Solid Mechanics*, 6.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NeoHookeanIso {
    pub c10: f64,
}

impl PointMaterial for NeoHookeanIso {
    fn iso_stress_tangent(&self, f: &Matrix3<f64>) -> StressTangent9 {
        // W = C10 (J^{-2/3} F:F - 3); P = 2 C10 J^{-2/3} (F - (F:F)/3 F^{-T})
        let j = f.determinant();
        let finv_t = f.try_inverse().unwrap_or_else(Matrix3::zeros).transpose();
        let i1 = f.norm_squared();
        let a = 2.0 * self.c10 * j.powf(-2.0 / 3.0);
        let p = a * (f - i1 / 3.0 * finv_t);
        let mut t = SMatrix::<f64, 9, 9>::zeros();
        for i in 0..3 {
            for jj in 0..3 {
                for k in 0..3 {
                    for l in 0..3 {
                        let d_ik_jl = if i == k && jj == l { 1.0 } else { 0.0 };
                        // d(J^{-2/3})/dF_kl = -2/3 J^{-2/3} Finv^T_kl
                        let v = d_ik_jl - 2.0 / 3.0 * f[(k, l)] * finv_t[(i, jj)]
                            + i1 / 3.0 * finv_t[(i, l)] * finv_t[(k, jj)]
                            - 2.0 / 3.0
                                * finv_t[(k, l)]
                                * (f[(i, jj)] - i1 / 3.0 * finv_t[(i, jj)]);
                        t[(3 * i + jj, 3 * k + l)] = a * v;
                    }
                }
            }
        }
        (p, t)
    }
    fn shear_modulus(&self) -> f64 {
        2.0 * self.c10
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neo_hookean_tangent_matches_finite_differences() {
        let m = NeoHookeanIso { c10: 0.7 };
        let f = Matrix3::new(1.1, 0.2, 0.0, -0.1, 0.9, 0.05, 0.0, 0.03, 1.2);
        let (_, a) = m.iso_stress_tangent(&f);
        let h = 1e-6;
        for k in 0..9 {
            let mut fp = f;
            let mut fm = f;
            fp[(k / 3, k % 3)] += h;
            fm[(k / 3, k % 3)] -= h;
            let dp = (m.iso_stress_tangent(&fp).0 - m.iso_stress_tangent(&fm).0) / (2.0 * h);
            for i in 0..9 {
                assert!((dp[(i / 3, i % 3)] - a[(i, k)]).abs() < 1e-7, "{i} {k}");
            }
        }
        // zero stress at rest
        assert!(m.iso_stress_tangent(&Matrix3::identity()).0.norm() < 1e-14);
    }
}
