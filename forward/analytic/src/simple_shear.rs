//! Homogeneous simple shear of an incompressible law, optionally superposed
//! on an axial stretch normal to the sheared plates.

use crate::convert::{check_law_params, check_loading, law_space};
use palpate_core::enrichable::{not_applicable, one_form, EffectForm};
use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace,
};
use palpate_enrich::{material_forms, richer_law, MaterialForm, Viscoelastic, DEFAULT_PRONY_TERMS};
use palpate_material::{Law, Volumetric};

/// Simple shear of amount `gamma` superposed on an axial stretch `lambda`
/// (Budday et al., Acta Biomater. 48 (2017) 319, section 2: shear of a cube
/// glued between two plates, alone and after an axial compression or
/// tension of the plate gap).
///
/// Axes: 1 the shear direction, 2 the plate normal (axial), 3 neutral. The
/// specimen is first stretched axially with free lateral faces,
/// `F_a = diag(lambda^-1/2, lambda, lambda^-1/2)`, then sheared by the plate
/// travel over the current gap, `F_s = I + gamma e1 (x) e2`:
///
/// ```text
/// F = F_s F_a = [[lambda^-1/2, gamma lambda, 0], [0, lambda, 0], [0, 0, lambda^-1/2]],  det F = 1.
/// ```
///
/// The observed stress is the shear force over the undeformed plate area,
/// the nominal (first Piola) component `P12 = dW/dF12`. Because
/// `(F^-T)_12 = 0` the incompressibility pressure does not enter it, so it
/// is `P12` of the law's isochoric stress ([`Law::stress_tangent`] with
/// [`Volumetric::Incompressible`]), for every law. For a law `W(I1, I2)`
/// with `B = F F^T`, `B_12 = gamma lambda^2`, `(B^-1)_12 = -gamma lambda`:
///
/// ```text
/// sigma_12 = 2 W1 B_12 - 2 W2 (B^-1)_12,   P12 = sigma_12 / lambda = 2 gamma (lambda W1 + W2),
/// I1 = lambda^2 (1 + gamma^2) + 2 / lambda,   I2 = 2 lambda + lambda^-2 + gamma^2 lambda,
/// ```
///
/// and at `lambda = 1` the classical `P12 = 2 gamma (W1 + W2)`, e.g.
/// neo-Hookean `P12 = 2 C10 gamma` (Rivlin 1948; Ogden, *Non-linear elastic
/// deformations*, 1984, sec. 5.2). Since `F12 = gamma lambda` and the volume
/// is constant along the path, `P12 = (1 / lambda) d W(F(gamma)) / d gamma`
/// exactly (the plate does work `P12 dF12` per unit reference volume), which
/// the tests check by finite differences of the energy.
#[derive(Debug, Clone, PartialEq)]
pub struct SimpleShear {
    pub law: Law,
    /// Axial stretch of the plate gap before shearing (1: plain simple shear).
    pub axial_stretch: f64,
    space: ParamSpace,
}

impl SimpleShear {
    /// Simple shear of `law` at axial stretch `axial_stretch` (> 0).
    pub fn new(law: Law, axial_stretch: f64) -> Result<Self, ForwardError> {
        if !(axial_stretch > 0.0 && axial_stretch.is_finite()) {
            return Err(ForwardError::InvalidConfig {
                field: "axial_stretch".into(),
                reason: format!("{axial_stretch}: a stretch must be positive and finite"),
            });
        }
        Ok(SimpleShear {
            law,
            axial_stretch,
            space: law_space(&law),
        })
    }

    /// The deformation gradient at amount of shear `gamma`.
    pub fn deformation(&self, gamma: f64) -> nalgebra::Matrix3<f64> {
        let l = self.axial_stretch;
        let t = 1.0 / l.sqrt();
        nalgebra::Matrix3::new(t, gamma * l, 0.0, 0.0, l, 0.0, 0.0, 0.0, t)
    }

    /// Nominal shear stress `P12` (MPa) at amount of shear `gamma`.
    pub fn stress(&self, theta: &[f64], gamma: f64) -> f64 {
        self.law
            .stress_tangent(theta, Volumetric::Incompressible, &self.deformation(gamma))
            .p[(0, 1)]
    }
}

struct SimpleShearEvaluator<'a> {
    model: &'a SimpleShear,
}

impl Evaluator for SimpleShearEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let m = self.model;
        check_law_params(&m.law, &m.space, theta)?;
        check_loading(loading, Drive::AmountOfShear, out.len())?;
        for (o, &g) in out.iter_mut().zip(&loading.drive) {
            *o = m.stress(theta, g);
            if !o.is_finite() {
                return Err(ForwardError::Unphysical {
                    drive: g,
                    reason: format!("{} shear stress is not finite", m.law),
                });
            }
        }
        Ok(())
    }
}

impl ForwardModel for SimpleShear {
    fn name(&self) -> String {
        if self.axial_stretch == 1.0 {
            format!("simple shear {}", self.law)
        } else {
            format!(
                "simple shear at axial stretch {} {}",
                self.axial_stretch, self.law
            )
        }
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::NominalStressMPa
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(SimpleShearEvaluator { model: self })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for SimpleShear {
    /// `material_form` (the next richer law, when there is one) and
    /// `viscoelasticity` (timed records).
    fn effects(&self) -> Vec<Effect> {
        let mut e = Vec::new();
        if richer_law(&self.law).is_some() {
            e.push(Effect::MaterialForm);
        }
        e.push(Effect::Viscoelasticity);
        e
    }
    /// `material_form`: the family of richer laws (`palpate_enrich::richer_laws`).
    fn enrich_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        match effect {
            Effect::MaterialForm => material_forms(&self.law, |l| {
                Ok(Box::new(SimpleShear::new(l, self.axial_stretch)?))
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
                    Box::new(SimpleShear::new(richer.law, self.axial_stretch)?),
                    richer.embed_law_params,
                    self.law.to_string(),
                    richer.space,
                )))
            }
            Effect::Viscoelasticity => Ok(Box::new(Viscoelastic::new(
                Box::new(self.clone()),
                DEFAULT_PRONY_TERMS,
            ))),
            _ => Err(not_applicable(effect, &self.name())),
        }
    }
}
