//! Enrichment `compressibility` of C1: a finite bulk modulus.

use crate::c1::{c1_area_mm2, C1Geometry};
use crate::convert::{check_law_params, check_loading, law_space, split};
use crate::homogeneous::not_applicable;
use crate::wrap::{wrap, WRAPPER_EFFECTS};
use palpate_core::{
    Drive, Effect, Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamSpace,
    ParamSpec,
};
use palpate_material::{homogeneous, Law, Volumetric};
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
        let space = base.extended(&[ParamSpec::new("D1", "1/MPa", 0.0, f64::INFINITY, 1.0)]);
        Compressible {
            law,
            geometry,
            law_space_len,
            space,
        }
    }
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
                homogeneous::uniaxial_compressible(&m.law, law_theta, Volumetric::D1(d1), s)
                    .map_err(|e| ForwardError::Unphysical {
                        drive: d,
                        reason: e.to_string(),
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
