//! Enrichment `compressibility` of C1: a finite bulk modulus.

use crate::c1::{c1_area_mm2, C1Geometry};
use crate::convert::{check_law_params, check_loading, law_space, split};
use palpate_core::enrichable::not_applicable;
use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamRole, ParamSpace, ParamSpec,
};
use palpate_enrich::{wrap, WRAPPER_EFFECTS};
use palpate_material::{homogeneous, Law};
use std::sync::Arc;

/// C1 compression of a compressible material, Psi = W(J^-1/3 F) + U(J) with
/// U = (J - 1)^2 / D1 (bulk modulus K = 2 / D1, Abaqus convention). With
/// lubricated platens the deformation stays homogeneous: axial stretch
/// lambda = 1 - d/H and the lateral stretch solved so that the lateral stress
/// vanishes (`palpate_material::homogeneous::uniaxial_compressible`);
/// F = -P(lambda) pi D^2 / 4.
///
/// Parameters: the law's, then `D1` (1/MPa) >= 0. D1 = 0 is exactly the
/// incompressible model ([`crate::C1Compression`]), so "off" is reachable
/// and a score test can take the one-sided derivative there.
#[derive(Debug, Clone, PartialEq)]
pub struct Compressible {
    pub law: Law,
    pub geometry: C1Geometry,
    law_space_len: usize,
    space: ParamSpace,
}

impl Compressible {
    /// Compressible C1 with the benchmark geometry.
    pub fn new(law: Law) -> Self {
        Self::with_geometry(law, C1Geometry::default())
    }

    /// Compressible C1 with another cylinder.
    pub fn with_geometry(law: Law, geometry: C1Geometry) -> Self {
        let base = law_space(&law);
        let law_space_len = base.len();
        let space = base
            .extended(&[ParamSpec::new("D1", "1/MPa", 0.0, f64::INFINITY, 1.0)
                .with_role(ParamRole::Compliance)]);
        Compressible {
            law,
            geometry,
            law_space_len,
            space,
        }
    }
}

/// Lateral-stress-free homogeneous uniaxial state of Psi = W(J^-1/3 lambda) + (J - 1)^2 / D1
/// at axial stretch `l`: returns (axial nominal stress, lateral stretch m).
///
/// With principal stretches (l, m, m), J = l m^2, isochoric stretches
/// lb = J^-1/3 (l, m, m) and tau_a = lb_a dW/dlb_a, the principal nominal
/// stresses are P_a = (tau_a - sum_b tau_b / 3 + J U'(J)) / lambda_a
/// (Holzapfel, *Nonlinear Solid Mechanics*, 2000, section 6.11), with
/// U' = 2 (J - 1) / D1. The lateral condition g(m) = tau_2 - sum tau / 3 +
/// 2 J (J - 1) / D1 = 0 is bracketed from the incompressible guess m = l^-1/2
/// and solved by the Illinois (modified regula falsi) method to round-off.
///
/// This is the same equilibrium as
/// `palpate_material::homogeneous::uniaxial_compressible` (cross-checked in
/// the tests), written here on the principal derivatives alone because the
/// general routine assembles the full 9x9 tangent at every iteration and is
/// about 20x slower, which dominates the refits of the gap diagnosis.
pub fn lateral_stress_free(law: &Law, p: &[f64], d1: f64, l: f64) -> Option<(f64, f64)> {
    let parts = |m: f64| {
        let j = l * m * m;
        let c = j.powf(-1.0 / 3.0);
        let lb = [c * l, c * m, c * m];
        let dw = law.isochoric_principal(p, lb).dw;
        let tau = [lb[0] * dw[0], lb[1] * dw[1], lb[2] * dw[2]];
        let mean = (tau[0] + tau[1] + tau[2]) / 3.0;
        let vol = 2.0 * j * (j - 1.0) / d1;
        (tau[0] - mean + vol, tau[1] - mean + vol)
    };
    let g = |m: f64| parts(m).1;
    let m0 = l.powf(-0.5);
    let g0 = g(m0);
    if !g0.is_finite() {
        return None;
    }
    // Bracket [a, b] with g(a) < 0 < g(b) (g increases with m for a stable material).
    let (mut a, mut b, mut ga, mut gb);
    if g0 == 0.0 {
        return Some((parts(m0).0 / l, m0));
    } else if g0 < 0.0 {
        (a, ga) = (m0, g0);
        b = m0;
        loop {
            b *= 1.25;
            gb = g(b);
            if gb > 0.0 {
                break;
            }
            if !gb.is_finite() || b > 1e3 * m0 {
                return None;
            }
            (a, ga) = (b, gb);
        }
    } else {
        (b, gb) = (m0, g0);
        a = m0;
        loop {
            a *= 0.8;
            ga = g(a);
            if ga < 0.0 {
                break;
            }
            if !ga.is_finite() || a < 1e-3 * m0 {
                return None;
            }
            (b, gb) = (a, ga);
        }
    }
    let scale = law.shear_modulus(p).abs().max(1e-300);
    let mut side = 0i8;
    for _ in 0..200 {
        let m = (a * gb - b * ga) / (gb - ga);
        let gm = g(m);
        if gm.abs() <= 1e-14 * scale || (b - a) <= 4.0 * f64::EPSILON * m {
            return Some((parts(m).0 / l, m));
        }
        if gm < 0.0 {
            (a, ga) = (m, gm);
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        } else {
            (b, gb) = (m, gm);
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        }
    }
    None
}

struct CompressibleEvaluator<'a> {
    model: &'a Compressible,
}

impl Evaluator for CompressibleEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let m = self.model;
        m.geometry.check()?;
        let (law_theta, own) = split(theta, &m.space, 1)?;
        debug_assert_eq!(law_theta.len(), m.law_space_len);
        check_law_params(&m.law, &law_space(&m.law), law_theta)?;
        check_loading(loading, Drive::DisplacementMm, out.len())?;
        let d1 = own[0];
        let area = c1_area_mm2(&m.geometry);
        for (o, &d) in out.iter_mut().zip(&loading.drive) {
            let s = m.geometry.stretch(d)?;
            let p = if d1 == 0.0 {
                homogeneous::uniaxial(&m.law, law_theta, s)
            } else {
                lateral_stress_free(&m.law, law_theta, d1, s)
                    .ok_or_else(|| ForwardError::Unphysical {
                        drive: d,
                        reason: format!("no lateral stretch with zero lateral stress (D1 = {d1})"),
                    })?
                    .0
            };
            *o = -p * area;
            if !o.is_finite() {
                return Err(ForwardError::Unphysical {
                    drive: d,
                    reason: "stress is not finite".into(),
                });
            }
        }
        Ok(())
    }
}

impl ForwardModel for Compressible {
    fn name(&self) -> String {
        format!("C1 compression, {}, compressible", self.law)
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(CompressibleEvaluator { model: self })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for Compressible {
    fn effects(&self) -> Vec<Effect> {
        WRAPPER_EFFECTS.to_vec()
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        if WRAPPER_EFFECTS.contains(&effect) {
            wrap(effect, Arc::new(self.clone()))
        } else {
            Err(not_applicable(effect, &self.name()))
        }
    }
    /// Law parameters, then D1 = 0 (incompressible).
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        v.push(0.0);
        v
    }
}
