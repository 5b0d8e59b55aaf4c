//! Several effects at once: the base model enriched with a set of effects,
//! its parameters laid out as the explanation's selection needs them.
//!
//! Enrichments compose through [`Enrichable::enrich`] (each enriched model
//! offers the effects that can still be added to it), but not in every
//! order: a law change (`material_form`, `compressibility`) is offered by
//! the bare model only, a wrapper (zero offset, relaxation) by anything it
//! wraps. [`compose`] tries the effects in the order law first, wrappers
//! last ([`PRIORITY`]), then any other order, and keeps the first chain
//! every step of which is offered. The chain's parameters come in its own
//! order; [`Composite`] presents them with a given prefix first (the
//! parameters of the set the new effect is added to, so that the
//! assessment sees "the base followed by the effect's own", as for one
//! effect) and knows the new parameters' "off" values, which reproduce the
//! prefix model exactly.

use super::plausible::bound_offsets;
use palpate_core::enrichable::{embed, enrich, enrich_forms, not_applicable};
use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output,
    ParamSpace, ParamSpec,
};
use std::collections::BTreeMap;

/// Order in which effects are stacked on the base model: the effects that
/// change the law or the setup first (they are offered by the bare model
/// only), the drive/response wrappers last: the zero offset innermost (it
/// shifts the drive the response sees), then the relaxation of that
/// response, then a series compliance of the machine, in series with the
/// whole specimen.
pub(crate) const PRIORITY: [Effect; 10] = [
    Effect::MaterialForm,
    Effect::Compressibility,
    Effect::TensionCompressionAsymmetry,
    Effect::Friction,
    Effect::BoundaryCondition,
    Effect::ModellingSpace,
    Effect::Inclusion,
    Effect::ZeroOffset,
    Effect::Viscoelasticity,
    Effect::ToolCompliance,
];

/// A chain of enrichments presented with some parameters first.
pub(crate) struct Composite {
    inner: Box<dyn ForwardModel>,
    space: ParamSpace,
    /// Index in the inner model of each outer parameter.
    to_inner: Vec<usize>,
    /// Number of prefix parameters.
    prefix: usize,
    /// "Off" values of the parameters after the prefix.
    off_tail: Vec<f64>,
}

/// Every ordering of `items` (Heap's algorithm); for the handful of effects
/// a set holds.
fn permutations(items: &[Effect]) -> Vec<Vec<Effect>> {
    fn heap(k: usize, a: &mut Vec<Effect>, out: &mut Vec<Vec<Effect>>) {
        if k <= 1 {
            out.push(a.clone());
            return;
        }
        for i in 0..k {
            heap(k - 1, a, out);
            let j = if k.is_multiple_of(2) { i } else { 0 };
            a.swap(j, k - 1);
        }
    }
    let mut a = items.to_vec();
    let mut out = Vec::new();
    heap(a.len(), &mut a, &mut out);
    out
}

/// `model` with `effect` in the form `forms` names (by its index among
/// [`enrich_forms`]; the default form when absent).
pub(crate) fn enrich_form(
    model: &dyn ForwardModel,
    effect: Effect,
    forms: &BTreeMap<Effect, usize>,
) -> Option<Box<dyn ForwardModel>> {
    match forms.get(&effect) {
        Some(&k) if k > 0 => enrich_forms(model, effect)
            .ok()?
            .into_iter()
            .nth(k)
            .map(|f| f.model),
        _ => enrich(model, effect).ok(),
    }
}

/// A chain of effects on a base model: the model, its parameter specs and
/// its "off" point.
type Chain = (Box<dyn ForwardModel>, Vec<ParamSpec>, Vec<f64>);

/// The chain of `order` on `base`, its parameter specs (each parameter's
/// spec where it first appears: the base's own, then each effect's, so
/// that an effect's narrower bounds survive the steps after it) and the
/// chain's "off" point for `base_theta`.
fn chain(
    base: &dyn ForwardModel,
    order: &[Effect],
    base_theta: &[f64],
    forms: &BTreeMap<Effect, usize>,
) -> Option<Chain> {
    let mut first: Vec<ParamSpec> = base.space().params.clone();
    let mut theta = base_theta.to_vec();
    let mut model: Option<Box<dyn ForwardModel>> = None;
    for &e in order {
        let next = match &model {
            None => enrich_form(base, e, forms)?,
            Some(m) => enrich_form(m.as_ref(), e, forms)?,
        };
        theta = embed(next.as_ref(), &theta);
        if theta.len() != next.space().len() {
            return None;
        }
        for s in &next.space().params {
            if !first.iter().any(|f| f.name == s.name) {
                first.push(s.clone());
            }
        }
        model = Some(next);
    }
    let model = model?;
    let specs = model
        .space()
        .params
        .iter()
        .map(|s| {
            first
                .iter()
                .find(|f| f.name == s.name)
                .cloned()
                .unwrap_or_else(|| s.clone())
        })
        .collect();
    Some((model, specs, theta))
}

/// `base` with every effect of `effects`, its parameters ordered as
/// `prefix` (names of the model the newest effect is added to) followed by
/// the rest; `base_theta` (the base model's parameters) gives the "off"
/// values of the rest; zero offsets held within `offsets` (what the record
/// permits, [`super::plausible::offset_range`]); each effect in the form
/// `forms` names ([`enrich_form`]). `None` when no order of
/// the effects is offered, or when a name of `prefix` is missing or twice
/// in the chain.
pub(crate) fn compose(
    base: &dyn ForwardModel,
    effects: &[Effect],
    prefix: &[String],
    base_theta: &[f64],
    offsets: Option<(f64, f64)>,
    forms: &BTreeMap<Effect, usize>,
) -> Option<Composite> {
    if effects.is_empty() {
        return None;
    }
    let mut preferred = effects.to_vec();
    preferred.sort_by_key(|e| {
        PRIORITY
            .iter()
            .position(|p| p == e)
            .unwrap_or(PRIORITY.len())
    });
    let mut orders = vec![preferred.clone()];
    if effects.len() <= 4 {
        orders.extend(
            permutations(&preferred)
                .into_iter()
                .filter(|o| *o != preferred),
        );
    }
    for order in orders {
        let Some((inner, specs, theta)) = chain(base, &order, base_theta, forms) else {
            continue;
        };
        let names: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
        let unique = names
            .iter()
            .enumerate()
            .all(|(i, n)| !names[..i].contains(n));
        if !unique {
            continue;
        }
        let Some(mut to_inner) = prefix
            .iter()
            .map(|p| names.iter().position(|n| n == p))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        let rest: Vec<usize> = (0..names.len()).filter(|i| !to_inner.contains(i)).collect();
        let off_tail = rest.iter().map(|&i| theta[i]).collect();
        to_inner.extend(rest);
        let mut specs: Vec<ParamSpec> = to_inner.iter().map(|&i| specs[i].clone()).collect();
        bound_offsets(&mut specs, offsets);
        let space = ParamSpace::new(specs);
        return Some(Composite {
            inner,
            space,
            to_inner,
            prefix: prefix.len(),
            off_tail,
        });
    }
    None
}

impl Composite {
    /// One enriched model `inner` (its first `p` parameters the base's) with
    /// its zero offsets held within `offsets`; `off` its "off" point. `None`
    /// when no bound moves.
    pub fn bounded(
        inner: Box<dyn ForwardModel>,
        off: &[f64],
        p: usize,
        offsets: Option<(f64, f64)>,
    ) -> Option<Composite> {
        let mut specs = inner.space().params.clone();
        if !bound_offsets(&mut specs, offsets) {
            return None;
        }
        Some(Composite {
            to_inner: (0..specs.len()).collect(),
            space: ParamSpace::new(specs),
            inner,
            prefix: p,
            off_tail: off[p..].to_vec(),
        })
    }
}

struct CompositeEval<'a> {
    model: &'a Composite,
    inner: Box<dyn Evaluator + 'a>,
    theta: Vec<f64>,
}

impl Evaluator for CompositeEval<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let m = self.model;
        if theta.len() != m.to_inner.len() {
            return Err(ForwardError::InvalidConfig {
                field: "theta".into(),
                reason: format!(
                    "{} parameters for {} of {}",
                    theta.len(),
                    m.to_inner.len(),
                    m.inner.name()
                ),
            });
        }
        self.theta.resize(theta.len(), 0.0);
        for (&i, &v) in m.to_inner.iter().zip(theta) {
            self.theta[i] = v;
        }
        self.inner.predict_into(&self.theta, loading, out)
    }
}

impl ForwardModel for Composite {
    fn name(&self) -> String {
        self.inner.name()
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        self.inner.observable()
    }
    /// The first output only: the diagnosis fits that one.
    fn outputs(&self) -> Vec<Output> {
        self.inner.outputs().into_iter().take(1).collect()
    }
    fn expensive(&self) -> bool {
        self.inner.expensive()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(CompositeEval {
            model: self,
            inner: self.inner.evaluator(),
            theta: Vec::new(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for Composite {
    /// None: a larger set is composed from the base model again.
    fn effects(&self) -> Vec<Effect> {
        Vec::new()
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        Err(not_applicable(effect, &self.name()))
    }
    /// The prefix parameters, then the new effects' "off" values.
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        if base_theta.len() == self.prefix {
            v.extend_from_slice(&self.off_tail);
        } else {
            v.extend(
                self.space
                    .params
                    .iter()
                    .skip(base_theta.len())
                    .map(|p| p.initial),
            );
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutations_of_three_effects() {
        let p = permutations(&[
            Effect::ZeroOffset,
            Effect::Viscoelasticity,
            Effect::MaterialForm,
        ]);
        assert_eq!(p.len(), 6);
        for (i, a) in p.iter().enumerate() {
            assert!(!p[..i].contains(a));
        }
    }
}
