//! Benchmark C1: homogeneous compression of a cylinder between lubricated platens.

use crate::convert::{check_law_params, check_loading, law_space};
use crate::Compressible;
use palpate_core::enrichable::{not_applicable, one_form, EffectForm};
use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace,
};
use palpate_enrich::{material_forms, richer_law, wrap, MaterialForm};
use palpate_material::{homogeneous, Law};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Cylinder of benchmark C1 (docs/benchmarks.md): diameter 38 mm, height 9 mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct C1Geometry {
    pub diameter_mm: f64,
    pub height_mm: f64,
}

impl Default for C1Geometry {
    fn default() -> Self {
        C1Geometry {
            diameter_mm: 38.0,
            height_mm: 9.0,
        }
    }
}

impl C1Geometry {
    pub(crate) fn check(&self) -> Result<(), ForwardError> {
        for (field, v) in [
            ("diameter_mm", self.diameter_mm),
            ("height_mm", self.height_mm),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ForwardError::InvalidConfig {
                    field: field.into(),
                    reason: format!("must be a positive length, got {v}"),
                });
            }
        }
        Ok(())
    }

    /// Axial stretch for platen travel `d` (positive in compression):
    /// lambda = 1 - d / H, an error when the specimen would be crushed.
    pub(crate) fn stretch(&self, d: f64) -> Result<f64, ForwardError> {
        let s = 1.0 - d / self.height_mm;
        if s > 0.0 {
            Ok(s)
        } else {
            Err(ForwardError::Unphysical {
                drive: d,
                reason: format!(
                    "platen travel reaches the specimen height {} mm",
                    self.height_mm
                ),
            })
        }
    }
}

/// Undeformed cross-section pi D^2 / 4 in mm^2 (C1: 1134.11 mm^2).
pub fn c1_area_mm2(g: &C1Geometry) -> f64 {
    std::f64::consts::PI * 0.25 * g.diameter_mm * g.diameter_mm
}

/// C1 compression of an incompressible law with frictionless platens.
///
/// The deformation is homogeneous uniaxial with axial stretch
/// lambda = 1 - d / H, so the reaction force (positive in compression) is
/// F = -P(lambda) A with P the uniaxial nominal stress (see [`crate::Homogeneous`])
/// and A = pi D^2 / 4 the undeformed area. Neo-Hookean:
/// F = -2 C10 (lambda - lambda^-2) A. Rate independent: `loading.time` is
/// ignored.
#[derive(Debug, Clone, PartialEq)]
pub struct C1Compression {
    pub law: Law,
    pub geometry: C1Geometry,
    space: ParamSpace,
}

impl C1Compression {
    /// C1 with the benchmark geometry.
    pub fn new(law: Law) -> Self {
        Self::with_geometry(law, C1Geometry::default())
    }

    /// C1 with another cylinder.
    pub fn with_geometry(law: Law, geometry: C1Geometry) -> Self {
        let space = law_space(&law);
        C1Compression {
            law,
            geometry,
            space,
        }
    }
}

struct C1Evaluator<'a> {
    model: &'a C1Compression,
}

impl Evaluator for C1Evaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let m = self.model;
        m.geometry.check()?;
        check_law_params(&m.law, &m.space, theta)?;
        check_loading(loading, Drive::DisplacementMm, out.len())?;
        let area = c1_area_mm2(&m.geometry);
        for (o, &d) in out.iter_mut().zip(&loading.drive) {
            let s = m.geometry.stretch(d)?;
            *o = -homogeneous::uniaxial(&m.law, theta, s) * area;
            if !o.is_finite() {
                return Err(ForwardError::Unphysical {
                    drive: d,
                    reason: format!("{} stress is not finite", m.law),
                });
            }
        }
        Ok(())
    }
}

impl ForwardModel for C1Compression {
    fn name(&self) -> String {
        format!("C1 compression, {}", self.law)
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(C1Evaluator { model: self })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for C1Compression {
    /// material_form (when a richer law exists), viscoelasticity,
    /// zero_offset, compressibility, tool_compliance.
    fn effects(&self) -> Vec<Effect> {
        let mut e = Vec::new();
        if richer_law(&self.law).is_some() {
            e.push(Effect::MaterialForm);
        }
        e.extend([
            Effect::Viscoelasticity,
            Effect::ZeroOffset,
            Effect::Compressibility,
            Effect::ToolCompliance,
        ]);
        e
    }
    /// `material_form`: the family of richer laws (`palpate_enrich::richer_laws`).
    fn enrich_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        match effect {
            Effect::MaterialForm => material_forms(&self.law, |l| {
                Ok(Box::new(C1Compression::with_geometry(l, self.geometry)))
            }),
            _ => Ok(one_form(self.enrich(effect)?)),
        }
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        match effect {
            Effect::MaterialForm => {
                let richer =
                    richer_law(&self.law).ok_or_else(|| not_applicable(effect, &self.name()))?;
                Ok(Box::new(MaterialForm::new(
                    Box::new(C1Compression::with_geometry(richer.law, self.geometry)),
                    richer.embed_law_params,
                    self.law.to_string(),
                    richer.space,
                )))
            }
            Effect::Compressibility => Ok(Box::new(Compressible::with_geometry(
                self.law,
                self.geometry,
            ))),
            Effect::Viscoelasticity | Effect::ZeroOffset | Effect::ToolCompliance => {
                wrap(effect, Arc::new(self.clone()))
            }
            _ => Err(not_applicable(effect, &self.name())),
        }
    }
}
