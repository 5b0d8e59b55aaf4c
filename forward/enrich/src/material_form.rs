//! Enrichment `material_form`: a richer hyperelastic law that contains the
//! base law as a special case.

use crate::convert::law_space;
use palpate_core::enrichable::{effects_of, enrich};
use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output,
    ParamSpace,
};
use palpate_material::Law;

/// A richer law and how a base parameter vector maps into it.
#[derive(Debug, Clone, PartialEq)]
pub struct RicherLaw {
    /// The richer law.
    pub law: Law,
    /// Values appended to the base law's parameters to give the richer law's
    /// parameters that reproduce the base law exactly (e.g. C20 = 0).
    pub embed_law_params: Vec<f64>,
    /// The richer law's parameters as the enrichment sees them (see [`richer_law`]).
    pub space: ParamSpace,
}

/// The next richer law of the same family, whose parameters are the base
/// law's followed by extra terms that vanish at the "off" point:
///
/// * neo-Hookean (C10) -> reduced polynomial N=2 (C10, C20), C20 = 0;
/// * reduced polynomial N -> N+1 (N < 6), C(N+1)0 = 0;
/// * Ogden N -> N+1: mu(N+1) = 0 (alpha(N+1) at its starting value).
///
/// Mooney-Rivlin and Arruda-Boyce have no nested richer law here (`None`).
///
/// For the reduced polynomial the added coefficient is bounded below by 0:
/// the enrichment adds a *stiffening* higher-order term (the departure from
/// neo-Hookean that soft solids show in compression). A softening departure
/// over moderate strains is the signature of a series compliance or of
/// relaxation during loading, and a free sign would let this enrichment
/// mimic those effects. Its starting value is a tenth of the richer law's
/// C10 start. Ogden's added modulus keeps its free sign.
pub fn richer_law(law: &Law) -> Option<RicherLaw> {
    let richer = match law {
        Law::NeoHookean => Law::ReducedPolynomial(2),
        Law::ReducedPolynomial(n) if *n < 6 => Law::ReducedPolynomial(n + 1),
        Law::Ogden(n) => Law::Ogden(n + 1),
        _ => return None,
    };
    let base_len = law.params().len();
    let extra = richer.params();
    if extra.len() <= base_len {
        return None;
    }
    let embed_law_params = extra[base_len..]
        .iter()
        .enumerate()
        // The first extra parameter is the new modulus (C(N+1)0 or mu(N+1)): zero.
        .map(|(i, p)| if i == 0 { 0.0 } else { p.initial })
        .collect();
    let mut space = law_space(&richer);
    if let Law::ReducedPolynomial(_) = richer {
        let start = 0.1 * space.params[0].initial.abs();
        let added = &mut space.params[base_len];
        added.lower = 0.0;
        added.initial = start;
    }
    Some(RicherLaw {
        law: richer,
        embed_law_params,
        space,
    })
}

/// A model with a richer law, which knows the "off" point that reproduces
/// the base law: [`Enrichable::embed`] appends the vanishing terms. Every
/// other method delegates to the wrapped model (its outputs included).
pub struct MaterialForm {
    inner: Box<dyn ForwardModel>,
    off_tail: Vec<f64>,
    base_law: String,
    space: ParamSpace,
}

impl MaterialForm {
    /// `inner` uses the richer law; `off_tail` completes a base parameter
    /// vector to the richer law's "off" point; `base_law` names the base law;
    /// `space` is the enrichment's parameter space (the inner model's names,
    /// possibly narrower bounds, checked before delegating).
    pub fn new(
        inner: Box<dyn ForwardModel>,
        off_tail: Vec<f64>,
        base_law: String,
        space: ParamSpace,
    ) -> Self {
        MaterialForm {
            inner,
            off_tail,
            base_law,
            space,
        }
    }
}

struct MaterialFormEvaluator<'a> {
    space: &'a ParamSpace,
    inner: Box<dyn Evaluator + 'a>,
}

impl Evaluator for MaterialFormEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.space.check(theta)?;
        self.inner.predict_into(theta, loading, out)
    }
    fn predict_outputs_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.space.check(theta)?;
        self.inner.predict_outputs_into(theta, loading, out)
    }
}

impl ForwardModel for MaterialForm {
    fn name(&self) -> String {
        format!("{} (richer than {})", self.inner.name(), self.base_law)
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        self.inner.observable()
    }
    fn outputs(&self) -> Vec<Output> {
        self.inner.outputs()
    }
    fn expensive(&self) -> bool {
        self.inner.expensive()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(MaterialFormEvaluator {
            space: &self.space,
            inner: self.inner.evaluator(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for MaterialForm {
    fn effects(&self) -> Vec<Effect> {
        effects_of(self.inner.as_ref())
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        enrich(self.inner.as_ref(), effect)
    }
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        v.extend_from_slice(&self.off_tail);
        v
    }
}
