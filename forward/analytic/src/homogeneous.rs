//! Homogeneous uniaxial, equibiaxial and planar tests of an incompressible law.

use crate::convert::{check_law_params, check_loading, law_space};
use crate::Mode;
use palpate_core::enrichable::{not_applicable, one_form, EffectForm};
use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace,
};
use palpate_enrich::{
    material_forms, richer_law, MaterialForm, TensionCompressionAsymmetry, Viscoelastic,
    ZeroOffset, DEFAULT_PRONY_TERMS,
};
use palpate_material::stability::Mode as StretchMode;
use palpate_material::{homogeneous, Law};
use std::sync::Arc;

/// Nominal (first Piola-Kirchhoff) stress along the loading direction of a
/// homogeneous incompressible test, in MPa, against the principal stretch.
///
/// With W(lambda1, lambda2, lambda3) and the lateral stress eliminated through
/// the incompressibility pressure (Ogden, *Non-linear elastic deformations*,
/// 1984, section 7.2; Treloar 1975):
///
/// * uniaxial: P = dW/dl1 - (s^-1/2 / s) dW/dl2 with lambda = (s, s^-1/2, s^-1/2),
///   e.g. neo-Hookean P = 2 C10 (s - s^-2);
/// * equibiaxial: lambda = (s, s, s^-2); planar: lambda = (s, 1, 1/s).
///
/// The formulas are `palpate_material::homogeneous`; this type turns them into a
/// [`ForwardModel`] with `Drive::Stretch` and `Observable::NominalStressMPa`.
#[derive(Debug, Clone, PartialEq)]
pub struct Homogeneous {
    pub law: Law,
    pub mode: Mode,
    space: ParamSpace,
}

impl Homogeneous {
    /// The `mode` test of material `law`; parameters are the law's (MPa).
    pub fn new(law: Law, mode: Mode) -> Self {
        let space = law_space(&law);
        Homogeneous { law, mode, space }
    }

    /// Nominal stress at one stretch (parameters assumed checked).
    pub fn stress(&self, theta: &[f64], stretch: f64) -> f64 {
        match self.mode {
            Mode::Uniaxial => homogeneous::uniaxial(&self.law, theta, stretch),
            Mode::Equibiaxial => homogeneous::equibiaxial(&self.law, theta, stretch),
            Mode::Planar => homogeneous::planar(&self.law, theta, stretch),
        }
    }
}

struct HomogeneousEvaluator<'a> {
    model: &'a Homogeneous,
}

impl Evaluator for HomogeneousEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let m = self.model;
        check_law_params(&m.law, &m.space, theta)?;
        check_loading(loading, Drive::Stretch, out.len())?;
        for (o, &s) in out.iter_mut().zip(&loading.drive) {
            if s <= 0.0 {
                return Err(ForwardError::Unphysical {
                    drive: s,
                    reason: "stretch must be positive".into(),
                });
            }
            *o = m.stress(theta, s);
            if !o.is_finite() {
                // The law's own diagnosis where it has one (Gent's limit, an overflowing exponential).
                let principal = match m.mode {
                    Mode::Uniaxial => StretchMode::Uniaxial,
                    Mode::Equibiaxial => StretchMode::Biaxial,
                    Mode::Planar => StretchMode::Planar,
                };
                let reason = match m.law.check_stretches(theta, principal.stretches(s)) {
                    Err(e) => e.to_string(),
                    Ok(()) => format!("{} stress is not finite", m.law),
                };
                return Err(ForwardError::Unphysical { drive: s, reason });
            }
        }
        Ok(())
    }
}

impl ForwardModel for Homogeneous {
    fn name(&self) -> String {
        format!("{} {}", self.mode, self.law)
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::NominalStressMPa
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(HomogeneousEvaluator { model: self })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for Homogeneous {
    fn effects(&self) -> Vec<Effect> {
        let mut e = Vec::new();
        if richer_law(&self.law).is_some() {
            e.push(Effect::MaterialForm);
        }
        e.push(Effect::Viscoelasticity);
        e.push(Effect::ZeroOffset);
        e.push(Effect::TensionCompressionAsymmetry);
        e
    }
    /// `material_form`: the family of richer laws (`palpate_enrich::richer_laws`).
    fn enrich_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        match effect {
            Effect::MaterialForm => {
                material_forms(&self.law, |l| Ok(Box::new(Homogeneous::new(l, self.mode))))
            }
            _ => Ok(one_form(self.enrich(effect)?)),
        }
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        match effect {
            Effect::MaterialForm => {
                let richer =
                    richer_law(&self.law).ok_or_else(|| not_applicable(effect, &self.name()))?;
                Ok(Box::new(MaterialForm::new(
                    Box::new(Homogeneous::new(richer.law, self.mode)),
                    richer.embed_law_params,
                    self.law.to_string(),
                    richer.space,
                )))
            }
            Effect::Viscoelasticity => Ok(Box::new(Viscoelastic::new(
                Box::new(self.clone()),
                DEFAULT_PRONY_TERMS,
            ))),
            Effect::ZeroOffset => Ok(Box::new(ZeroOffset::on_stretch(Arc::new(self.clone())))),
            Effect::TensionCompressionAsymmetry => Ok(Box::new(
                TensionCompressionAsymmetry::from_arc(Arc::new(self.clone())),
            )),
            _ => Err(not_applicable(effect, &self.name())),
        }
    }
}
