//! General biaxial extension of an incompressible sheet (Kawabata et al. 1981).

use crate::convert::{check_law_params, check_loading, law_space};
use palpate_core::enrichable::{not_applicable, one_form, EffectForm};
use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace,
};
use palpate_enrich::{material_forms, richer_law, MaterialForm};
use palpate_material::Law;

/// Nominal stresses of a sheet stretched by `lambda1` and `lambda2` in its
/// plane, thickness stretch `lambda3 = 1 / (lambda1 lambda2)` and stress
/// free through the thickness (Kawabata, Matsuda, Tei & Kawai,
/// Macromolecules 14 (1981) 154; Ogden 1984, sec. 7.2):
///
/// ```text
/// P1 = dW/dl1 - (l3 / l1) dW/dl3,   P2 = dW/dl2 - (l3 / l2) dW/dl3,
/// ```
///
/// with `dW/dl_a` the law's principal derivatives
/// ([`Law::isochoric_principal`]); the pressure `p = l3 dW/dl3` is fixed by
/// `sigma3 = 0`. Equivalently `P_a = d W(l1, l2, 1/(l1 l2)) / d l_a` (the
/// reduced energy; checked by finite differences in the tests). Equibiaxial
/// (`l1 = l2`), pure shear (`l2 = 1`) and, with `P2 = 0` imposed instead of
/// `l2`, uniaxial tension are special cases; here both stretches are given.
///
/// Layout of a record (two stretches and two stresses per row): the drive
/// holds `l1, l2` of row 0, then `l1, l2` of row 1, ...; the output at drive
/// slot `k` is the nominal stress along the direction whose stretch is
/// `drive[k]` (`P1` at even slots, `P2` at odd ones), so each sample is
/// "a stress against its own stretch" and plots read naturally.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneralBiaxial {
    pub law: Law,
    space: ParamSpace,
}

impl GeneralBiaxial {
    /// General biaxial extension of `law`.
    pub fn new(law: Law) -> Self {
        GeneralBiaxial {
            law,
            space: law_space(&law),
        }
    }

    /// `(P1, P2)` in MPa at in-plane stretches `l1`, `l2` (parameters assumed checked).
    pub fn stresses(&self, theta: &[f64], l1: f64, l2: f64) -> (f64, f64) {
        let l3 = 1.0 / (l1 * l2);
        let d = self.law.isochoric_principal(theta, [l1, l2, l3]);
        let p = l3 * d.dw[2];
        (d.dw[0] - p / l1, d.dw[1] - p / l2)
    }
}

struct GeneralBiaxialEvaluator<'a> {
    model: &'a GeneralBiaxial,
}

impl Evaluator for GeneralBiaxialEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let m = self.model;
        check_law_params(&m.law, &m.space, theta)?;
        check_loading(loading, Drive::Stretch, out.len())?;
        if !loading.len().is_multiple_of(2) {
            return Err(ForwardError::InvalidLoading(format!(
                "a general biaxial record has pairs (lambda1, lambda2); got {} stretches",
                loading.len()
            )));
        }
        for (o, l) in out.chunks_exact_mut(2).zip(loading.drive.chunks_exact(2)) {
            if let Some(&bad) = l.iter().find(|&&s| s.is_nan() || s <= 0.0) {
                return Err(ForwardError::Unphysical {
                    drive: bad,
                    reason: "stretch must be positive".into(),
                });
            }
            let (p1, p2) = m.stresses(theta, l[0], l[1]);
            if !(p1.is_finite() && p2.is_finite()) {
                return Err(ForwardError::Unphysical {
                    drive: l[0],
                    reason: format!("{} stress is not finite at lambda2 = {}", m.law, l[1]),
                });
            }
            o[0] = p1;
            o[1] = p2;
        }
        Ok(())
    }
}

impl ForwardModel for GeneralBiaxial {
    fn name(&self) -> String {
        format!("general biaxial {}", self.law)
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::NominalStressMPa
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(GeneralBiaxialEvaluator { model: self })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for GeneralBiaxial {
    /// `material_form` only (when the law has a richer form): the paired
    /// layout is not a time history, so the wrappers that act along a
    /// history (viscoelasticity) do not apply, and its two stretches have no
    /// one zero to offset.
    fn effects(&self) -> Vec<Effect> {
        if richer_law(&self.law).is_some() {
            vec![Effect::MaterialForm]
        } else {
            Vec::new()
        }
    }
    /// `material_form`: the family of richer laws (`palpate_enrich::richer_laws`).
    fn enrich_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        match effect {
            Effect::MaterialForm => {
                material_forms(&self.law, |l| Ok(Box::new(GeneralBiaxial::new(l))))
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
                    Box::new(GeneralBiaxial::new(richer.law)),
                    richer.embed_law_params,
                    self.law.to_string(),
                    richer.space,
                )))
            }
            _ => Err(not_applicable(effect, &self.name())),
        }
    }
}
