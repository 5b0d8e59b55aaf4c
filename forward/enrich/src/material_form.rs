//! Enrichment `material_form`: a richer hyperelastic law that contains the
//! base law as a special case.

use crate::convert::law_space;
use crate::wrap::wrap;
use crate::WRAPPER_EFFECTS;
use palpate_core::enrichable::{effects_of, embed, enrich, not_applicable, EffectForm};
use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output,
    ParamRole, ParamSpace, ParamSpec,
};
use palpate_material::{Law, EXPONENT_BOUND, GENT_JM_BOUND, OGDEN_ALPHA_BOUND};
use std::sync::Arc;

/// How the richer law's parameters, as the enrichment presents them, give
/// the law's own: the enrichment keeps the base's `C10` (half the initial
/// shear modulus of neo-Hookean) first, so that a base fit is a start of
/// the richer one and "off" is a point of the enrichment's space.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawMap {
    /// The law's own parameters.
    Identity,
    /// Ogden, `[C10, alpha1, mu2, alpha2, ..]`: `mu1 = 2 C10 - mu2 - ..`
    /// (the initial shear modulus stays `2 C10`), off at `alpha1 = 2` and
    /// the other moduli 0.
    Ogden,
    /// Gent, `[C10, Jm_inv]`: `mu = 2 C10`, `Jm = 1 / (Jm_inv + 1 / GENT_JM_BOUND)`,
    /// off at `Jm_inv = 0` (the law's largest `Jm`, neo-Hookean to a relative
    /// `(I1 - 3) / 1e4`).
    Gent,
    /// Humphrey, `[C10, C2]`: `C1 = C10 / (C2 + 1e-9)` (the initial shear
    /// modulus `2 C1 C2` stays `2 C10`), off at `C2 = 0` (neo-Hookean to a
    /// relative `1e-9 (I1 - 3)`).
    Humphrey,
}

/// Smallest exponent rate of the Humphrey form (its "off" point).
const HUMPHREY_FLOOR: f64 = 1e-9;

impl LawMap {
    /// The law's parameters from the enrichment's (`theta` exactly the law's count).
    pub fn to_law(self, theta: &[f64]) -> Vec<f64> {
        match self {
            LawMap::Identity => theta.to_vec(),
            LawMap::Ogden => {
                let mut v = theta.to_vec();
                let others: f64 = theta.iter().skip(2).step_by(2).sum();
                v[0] = 2.0 * theta[0] - others;
                v
            }
            LawMap::Gent => vec![2.0 * theta[0], 1.0 / (theta[1] + 1.0 / GENT_JM_BOUND)],
            LawMap::Humphrey => {
                let c2 = theta[1] + HUMPHREY_FLOOR;
                vec![theta[0] / c2, c2]
            }
        }
    }
}

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
    /// From those to the law's own.
    pub map: LawMap,
}

impl RicherLaw {
    /// Short name: the law's (`reduced-polynomial:2`, `ogden:1`, `gent`, ...).
    pub fn name(&self) -> String {
        self.law.to_string()
    }
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
        map: LawMap::Identity,
    })
}

/// The family of richer laws `material_form` searches, [`richer_law`]'s
/// first. Of neo-Hookean (each nests it: its "off" point is neo-Hookean
/// with the same C10, and its first parameter is that C10):
///
/// * reduced polynomial N=2 ([`richer_law`]: a stiffening C20 >= 0);
/// * reduced polynomial N=3 (Yeoh): C20 of either sign, a stiffening
///   C30 >= 0 (the S-shape of rubber: softening, then stiffening);
/// * Mooney-Rivlin: C01 of either sign (a dependence on I2);
/// * Ogden with one term (`C10`, `alpha1`; off at alpha1 = 2) and two terms
///   (`C10`, `alpha1`, `mu2`, `alpha2`; off at alpha1 = 2, mu2 = 0), the
///   initial shear modulus kept at 2 C10 ([`LawMap::Ogden`]);
/// * Gent (`C10`, `Jm_inv` >= 0: limited chain extensibility, [`LawMap::Gent`]);
/// * Humphrey's exponential law (`C10`, `C2` >= 0, [`LawMap::Humphrey`]).
///
/// Of any other law, [`richer_law`] alone (or nothing). The diagnosis
/// picks the member by its held-out misfit, charging each extra parameter.
pub fn richer_laws(law: &Law) -> Vec<RicherLaw> {
    let mut out: Vec<RicherLaw> = richer_law(law).into_iter().collect();
    if *law != Law::NeoHookean {
        return out;
    }
    let c10 = || law_space(&Law::NeoHookean).params[0].clone();
    let spec = |name: &str, lower: f64, upper: f64, initial: f64, modulus: bool| {
        ParamSpec::new(
            name,
            if modulus { "MPa" } else { "1" },
            lower,
            upper,
            initial,
        )
        .with_role(if modulus {
            ParamRole::Modulus
        } else {
            ParamRole::Shape
        })
    };
    let inf = f64::INFINITY;
    let c10_start = c10().initial;
    // Yeoh: C20 free, C30 stiffening.
    out.push(RicherLaw {
        law: Law::ReducedPolynomial(3),
        embed_law_params: vec![0.0, 0.0],
        space: ParamSpace::new(vec![
            c10(),
            spec("C20", -inf, inf, -0.1 * c10_start, true),
            spec("C30", 0.0, inf, 0.1 * c10_start, true),
        ]),
        map: LawMap::Identity,
    });
    out.push(RicherLaw {
        law: Law::MooneyRivlin,
        embed_law_params: vec![0.0],
        space: ParamSpace::new(vec![c10(), spec("C01", -inf, inf, 0.1 * c10_start, true)]),
        map: LawMap::Identity,
    });
    let alpha = |name: &str, initial: f64| {
        spec(name, -OGDEN_ALPHA_BOUND, OGDEN_ALPHA_BOUND, initial, false)
    };
    out.push(RicherLaw {
        law: Law::Ogden(1),
        embed_law_params: vec![2.0],
        space: ParamSpace::new(vec![c10(), alpha("alpha1", 4.0)]),
        map: LawMap::Ogden,
    });
    out.push(RicherLaw {
        law: Law::Ogden(2),
        embed_law_params: vec![2.0, 0.0, -2.0],
        space: ParamSpace::new(vec![
            c10(),
            alpha("alpha1", 4.0),
            spec("mu2", -inf, inf, 0.2 * c10_start, true),
            alpha("alpha2", -2.0),
        ]),
        map: LawMap::Ogden,
    });
    out.push(RicherLaw {
        law: Law::Gent,
        embed_law_params: vec![0.0],
        space: ParamSpace::new(vec![c10(), spec("Jm_inv", 0.0, 10.0, 0.05, false)]),
        map: LawMap::Gent,
    });
    out.push(RicherLaw {
        law: Law::Humphrey,
        embed_law_params: vec![0.0],
        space: ParamSpace::new(vec![c10(), spec("C2", 0.0, EXPONENT_BOUND, 0.2, false)]),
        map: LawMap::Humphrey,
    });
    out
}

/// The forms of `material_form` for a model of law `law`: each law of
/// [`richer_laws`] as a [`MaterialForm`] around the model `build` makes
/// with that law.
pub fn material_forms(
    law: &Law,
    build: impl Fn(Law) -> Result<Box<dyn ForwardModel>, ForwardError>,
) -> Result<Vec<EffectForm>, ForwardError> {
    let family = richer_laws(law);
    if family.is_empty() {
        return Err(not_applicable(Effect::MaterialForm, &law.to_string()));
    }
    family
        .into_iter()
        .map(|r| {
            let name = r.name();
            let inner = build(r.law)?;
            Ok(EffectForm {
                name,
                model: Box::new(MaterialForm::from_richer(inner, r, law.to_string())),
            })
        })
        .collect()
}

/// A model with a richer law, which knows the "off" point that reproduces
/// the base law: [`Enrichable::embed`] appends the vanishing terms. The
/// first parameters (the law's, as the enrichment presents them) pass
/// through a [`LawMap`]; the rest, and every other method, go to the
/// wrapped model (its outputs included). Further effects wrap this model
/// (drive/response wrappers) or are added to the wrapped one under the
/// same map (compressibility).
#[derive(Clone)]
pub struct MaterialForm {
    inner: Arc<dyn ForwardModel>,
    /// "Off" values appended to a base vector; `None` when this model
    /// enriches a material form (then the wrapped model's own embed).
    off_tail: Option<Vec<f64>>,
    base_law: String,
    space: ParamSpace,
    map: LawMap,
    /// Number of leading parameters that pass through `map`.
    law_len: usize,
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
        let law_len = space.len();
        MaterialForm {
            inner: Arc::from(inner),
            off_tail: Some(off_tail),
            base_law,
            space,
            map: LawMap::Identity,
            law_len,
        }
    }

    /// `inner` with the law of `richer`, presented as `richer` says.
    pub fn from_richer(inner: Box<dyn ForwardModel>, richer: RicherLaw, base_law: String) -> Self {
        let law_len = richer.space.len();
        MaterialForm {
            inner: Arc::from(inner),
            off_tail: Some(richer.embed_law_params),
            base_law,
            space: richer.space,
            map: richer.map,
            law_len,
        }
    }

    /// The wrapped model's parameters for this model's `theta` (checked).
    fn inner_theta(&self, theta: &[f64]) -> Result<Vec<f64>, ForwardError> {
        self.space.check(theta)?;
        let mut v = self.map.to_law(&theta[..self.law_len]);
        v.extend_from_slice(&theta[self.law_len..]);
        Ok(v)
    }
}

struct MaterialFormEvaluator<'a> {
    model: &'a MaterialForm,
    inner: Box<dyn Evaluator + 'a>,
}

impl Evaluator for MaterialFormEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let t = self.model.inner_theta(theta)?;
        self.inner.predict_into(&t, loading, out)
    }
    fn predict_outputs_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let t = self.model.inner_theta(theta)?;
        self.inner.predict_outputs_into(&t, loading, out)
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
            model: self,
            inner: self.inner.evaluator(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for MaterialForm {
    /// The wrapped model's effects but `material_form` itself.
    fn effects(&self) -> Vec<Effect> {
        effects_of(self.inner.as_ref())
            .into_iter()
            .filter(|e| *e != Effect::MaterialForm)
            .collect()
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        if !self.effects().contains(&effect) {
            return Err(not_applicable(effect, &self.name()));
        }
        if WRAPPER_EFFECTS.contains(&effect) {
            return wrap(effect, Arc::new(self.clone()));
        }
        // A change of the setup (compressibility): the wrapped model's,
        // its new parameters after this model's.
        let inner = enrich(self.inner.as_ref(), effect)?;
        let own = self.space.len();
        if inner.space().len() < own {
            return Err(not_applicable(effect, &self.name()));
        }
        let extra: Vec<ParamSpec> = inner.space().params[own..].to_vec();
        Ok(Box::new(MaterialForm {
            space: self.space.extended(&extra),
            inner: Arc::from(inner),
            off_tail: None,
            base_law: self.base_law.clone(),
            map: self.map,
            law_len: self.law_len,
        }))
    }
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        match &self.off_tail {
            Some(tail) => v.extend_from_slice(tail),
            None => {
                // the wrapped model's "off" values for the mapped vector
                let mut mapped = self
                    .map
                    .to_law(&base_theta[..self.law_len.min(base_theta.len())]);
                mapped.extend_from_slice(&base_theta[self.law_len.min(base_theta.len())..]);
                let full = embed(self.inner.as_ref(), &mapped);
                v.extend_from_slice(&full[mapped.len().min(full.len())..]);
            }
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_material::homogeneous;

    #[test]
    fn every_richer_law_of_neo_hookean_reproduces_it_at_off_and_departs_from_it() {
        let family = richer_laws(&Law::NeoHookean);
        let names: Vec<String> = family.iter().map(RicherLaw::name).collect();
        assert_eq!(family.len(), 7, "{names:?}");
        assert_eq!(family[0], richer_law(&Law::NeoHookean).unwrap());
        let c10 = 1.2e-3;
        for r in &family {
            let mut off = vec![c10];
            off.extend_from_slice(&r.embed_law_params);
            assert!(
                r.space.check(&off).is_ok(),
                "{}: off outside its space",
                r.name()
            );
            let law_params = r.map.to_law(&off);
            for s in [0.7, 0.9, 1.2, 1.6] {
                let nh = homogeneous::uniaxial(&Law::NeoHookean, &[c10], s);
                let rich = homogeneous::uniaxial(&r.law, &law_params, s);
                // Gent's off point is its largest Jm (1e4): neo-Hookean to 1e-4
                assert!(
                    (rich - nh).abs() <= 1e-4 * nh.abs(),
                    "{} at stretch {s}: {rich} for {nh}",
                    r.name()
                );
            }
            // the starting point of the added terms changes the response
            let start = r.space.initial();
            let mut moved = vec![c10];
            moved.extend_from_slice(&start[1..]);
            let law_params = r.map.to_law(&moved);
            let (nh, rich) = (
                homogeneous::uniaxial(&Law::NeoHookean, &[c10], 1.6),
                homogeneous::uniaxial(&r.law, &law_params, 1.6),
            );
            assert!(
                (rich - nh).abs() > 1e-3 * nh.abs(),
                "{}: {rich} {nh}",
                r.name()
            );
        }
        // another base law has its next richer law only
        assert_eq!(richer_laws(&Law::ReducedPolynomial(2)).len(), 1);
        assert!(richer_laws(&Law::MooneyRivlin).is_empty());
    }
}
