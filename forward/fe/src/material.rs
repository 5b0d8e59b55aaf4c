//! The pointwise material seen by the elements: isochoric stress and tangent
//! from a deformation gradient. The volumetric part is the element's business
//! (mean dilatation penalty or an exact constraint, see [`crate::kernel`]).

use nalgebra::{Matrix3, SMatrix};
use palpate_material::invariant_kinematics::InvariantKinematics;
use palpate_material::{Law, Volumetric};

use crate::kinematics::F_COMPONENTS;
use crate::FeError;

/// Stress and tangent restricted to the five components a 2D element
/// carries ([`F_COMPONENTS`]): `P_k` and `A_kl`.
pub type StressTangent5 = ([f64; 5], [[f64; 5]; 5]);

/// First Piola stress and tangent `A = dP/dF` (9 x 9, index `3 i + j` for `F_ij`).
pub type StressTangent9 = (Matrix3<f64>, SMatrix<f64, 9, 9>);

/// A material at a quadrature point: the isochoric part `W(J^{-1/3} F)`
/// only, optionally with history variables.
///
/// History follows the FE layer's trial/commit protocol without the
/// material holding any state: the stress and the new history are pure
/// functions of the deformation gradient, the committed history `old` and
/// the time step `dt` ([`PointMaterial::stress_tangent_with_history`],
/// [`PointMaterial::update_history`]); the body keeps the committed values
/// and the trial values of the last assembly, so a cut increment simply
/// recomputes from the committed ones.
pub trait PointMaterial: Send + Sync {
    /// `P_iso = dW/dF` and `A_iso = dP_iso/dF` at `f`.
    fn iso_stress_tangent(&self, f: &Matrix3<f64>) -> StressTangent9;
    /// History variables per quadrature point (0: elastic, the default).
    fn history_len(&self) -> usize {
        0
    }
    /// Stress and tangent (`dP/dF` at fixed `old` and `dt`) at `f` after a
    /// step `dt` (s) from the committed history `old`. Default: elastic.
    fn stress_tangent_with_history(
        &self,
        f: &Matrix3<f64>,
        _dt: f64,
        _old: &[f64],
    ) -> StressTangent9 {
        self.iso_stress_tangent(f)
    }
    /// The history after a step `dt` to `f` from `old`, into `new`
    /// (`history_len` values each). Default: nothing to update.
    fn update_history(&self, _f: &Matrix3<f64>, _dt: f64, _old: &[f64], _new: &mut [f64]) {}
    /// Initial shear modulus (MPa), used to scale penalties and tolerances.
    fn shear_modulus(&self) -> f64;
    /// The five components of `P_iso` and (when `tangent`, else zeros)
    /// `A_iso` that a 2D element uses, for a gradient of the 2D form
    /// `[[F00, F01, 0], [F10, F11, 0], [0, 0, F22]]`. The default restricts
    /// [`PointMaterial::iso_stress_tangent`].
    fn iso_stress_tangent_2d(&self, f: &Matrix3<f64>, tangent: bool) -> StressTangent5 {
        restrict_2d(self.iso_stress_tangent(f), tangent)
    }
}

/// The five components ([`F_COMPONENTS`]) of a 9-component stress and
/// (when `tangent`, else zeros) tangent.
fn restrict_2d((p, a): StressTangent9, tangent: bool) -> StressTangent5 {
    let p5 = std::array::from_fn(|k| p[(F_COMPONENTS[k] / 3, F_COMPONENTS[k] % 3)]);
    let a5 = if tangent {
        std::array::from_fn(|k| std::array::from_fn(|l| a[(F_COMPONENTS[k], F_COMPONENTS[l])]))
    } else {
        [[0.0; 5]; 5]
    };
    (p5, a5)
}

/// A material seen at one quadrature point with its committed history and
/// time step: an elastic [`PointMaterial`] for the kinematics, whatever the
/// material's history (elastic materials keep their fast 2D path).
pub struct AtPoint<'a> {
    pub material: &'a dyn PointMaterial,
    pub old: &'a [f64],
    pub dt: f64,
}

impl PointMaterial for AtPoint<'_> {
    fn iso_stress_tangent(&self, f: &Matrix3<f64>) -> StressTangent9 {
        self.material
            .stress_tangent_with_history(f, self.dt, self.old)
    }
    fn shear_modulus(&self) -> f64 {
        self.material.shear_modulus()
    }
    fn iso_stress_tangent_2d(&self, f: &Matrix3<f64>, tangent: bool) -> StressTangent5 {
        if self.material.history_len() == 0 {
            return self.material.iso_stress_tangent_2d(f, tangent);
        }
        restrict_2d(self.iso_stress_tangent(f), tangent)
    }
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
    /// For the laws written in invariants, the isochoric stress and tangent
    /// entries of `palpate_material::invariant_kinematics::InvariantKinematics`
    /// (the same formulas as the material's 9 x 9 path) for the five 2D components only (15 tangent
    /// entries instead of 45; none when `tangent` is false): the material
    /// evaluation was 30 % of an N1 run. Ogden goes through the 9 x 9 path.
    fn iso_stress_tangent_2d(&self, f: &Matrix3<f64>, tangent: bool) -> StressTangent5 {
        let Some(kin) = InvariantKinematics::new(f) else {
            return ([f64::NAN; 5], [[f64::NAN; 5]; 5]);
        };
        let (i1b, i2b) = kin.modified();
        let Some(d) = self.law.invariant_derivs(&self.params, i1b, i2b) else {
            return restrict_2d(self.iso_stress_tangent(f), tangent);
        };
        let idx = F_COMPONENTS.map(|r| (r / 3, r % 3));
        let p = kin.iso_stress(&d);
        let p5 = idx.map(|(i, jj)| p[(i, jj)]);
        let mut a5 = [[0.0; 5]; 5];
        if !tangent {
            return (p5, a5);
        }
        for r in 0..5 {
            let (i, jj) = idx[r];
            for s in r..5 {
                let (k, l) = idx[s];
                a5[r][s] = kin.iso_tangent(&d, i, jj, k, l);
                a5[s][r] = a5[r][s];
            }
        }
        (p5, a5)
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

    /// The five-component fast path equals the material crate's 9 x 9
    /// stress and tangent on those components, for every invariant law and
    /// (through the fallback) Ogden.
    #[test]
    fn two_dimensional_fast_path_equals_the_full_tangent() {
        let f = Matrix3::new(1.3, 0.25, 0.0, -0.15, 0.8, 0.0, 0.0, 0.0, 1.1);
        let cases: [(&str, Vec<f64>); 8] = [
            ("neo-hookean", vec![0.5]),
            ("mooney-rivlin", vec![0.3, 0.1]),
            ("reduced-polynomial:2", vec![0.4, 0.2]),
            ("arruda-boyce", vec![0.6, 1.5]),
            ("ogden:1", vec![0.5, 3.0]),
            ("gent", vec![0.5, 10.0]),
            ("veronda-westmann", vec![2.0, 0.25]),
            ("humphrey", vec![1.0, 0.8]),
        ];
        for (law, p) in cases {
            let m = LawMaterial::new(law.parse().unwrap(), p).unwrap();
            let (p9, a9) = m.iso_stress_tangent(&f);
            let (p5, a5) = m.iso_stress_tangent_2d(&f, true);
            let scale = a9.abs().max();
            for k in 0..5 {
                let (i, j) = (F_COMPONENTS[k] / 3, F_COMPONENTS[k] % 3);
                assert!((p5[k] - p9[(i, j)]).abs() < 1e-12 * scale, "{law} P{k}");
                for l in 0..5 {
                    let d = a5[k][l] - a9[(F_COMPONENTS[k], F_COMPONENTS[l])];
                    assert!(d.abs() < 1e-12 * scale, "{law} A{k}{l}: {d}");
                }
            }
            let (q5, z5) = m.iso_stress_tangent_2d(&f, false);
            assert_eq!(q5, p5);
            assert!(z5.iter().flatten().all(|v| *v == 0.0));
        }
    }
}
