//! The `Enrichable` capability: effects a model can be enriched with, for the
//! sim-to-real gap diagnosis (`GAP.md`).
//!
//! Only the gap diagnosis asks a model for its effects, so this is a layered
//! capability (STYLE.md 3) rather than part of [`ForwardModel`]: a model that
//! has it returns `Some(self)` from [`ForwardModel::as_enrichable`].

use crate::{Effect, ForwardError, ForwardModel, ParamSpace};

/// A model that knows which unmodelled effects ([`Effect`]) it can add, and
/// the enriched model for each.
///
/// ```
/// use palpate_core::{enrichable, Effect, Enrichable, ForwardModel};
/// # use palpate_core::{Evaluator, ForwardError, Loading, Observable, ParamSpace, ParamSpec};
/// # struct Spring(ParamSpace);
/// # struct Eval;
/// # impl Evaluator for Eval {
/// #     fn predict_into(&mut self, t: &[f64], l: &Loading, o: &mut [f64]) -> Result<(), ForwardError> {
/// #         for (o, d) in o.iter_mut().zip(&l.drive) { *o = t[0] * d; }
/// #         Ok(())
/// #     }
/// # }
/// # impl ForwardModel for Spring {
/// #     fn name(&self) -> String { "spring".into() }
/// #     fn space(&self) -> &ParamSpace { &self.0 }
/// #     fn observable(&self) -> Observable { Observable::ForceN }
/// #     fn evaluator(&self) -> Box<dyn Evaluator + '_> { Box::new(Eval) }
/// # }
/// # let model: Box<dyn ForwardModel> =
/// #     Box::new(Spring(ParamSpace::new(vec![ParamSpec::new("k", "N/mm", 0.0, 10.0, 1.0)])));
/// // A model without the capability offers no effect.
/// assert!(model.as_enrichable().is_none());
/// assert!(enrichable::effects_of(model.as_ref()).is_empty());
/// assert!(enrichable::enrich(model.as_ref(), Effect::ZeroOffset).is_err());
/// ```
pub trait Enrichable: ForwardModel {
    /// Effects (GAP.md) for which [`Enrichable::enrich`] gives an enriched model.
    fn effects(&self) -> Vec<Effect>;

    /// The model with `effect` added. The enriched model's parameters are this
    /// model's parameters followed by (or, for `material_form`, replacing the
    /// law's with) the effect's own; [`embed`] maps a parameter vector of this
    /// model to the enriched model's "effect off" point.
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError>;

    /// The forms `effect` can take when there are several (the richer laws
    /// of `material_form`), each named and enriched as by
    /// [`Enrichable::enrich`] (parameters and "off" point alike); the first
    /// is the one [`Enrichable::enrich`] gives. Default: that one alone,
    /// named after the enriched model.
    fn enrich_forms(&self, effect: Effect) -> Result<Vec<EffectForm>, ForwardError> {
        Ok(one_form(self.enrich(effect)?))
    }

    /// For an enriched model: the parameter vector that reproduces the base
    /// model with parameters `base_theta` (the effect switched off).
    /// Default: [`default_embed`].
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        default_embed(self.space(), base_theta)
    }
}

/// One form of an effect ([`Enrichable::enrich_forms`]): a short name (e.g.
/// the richer law, `ogden:1`) and the enriched model.
pub struct EffectForm {
    pub name: String,
    pub model: Box<dyn ForwardModel>,
}

/// An effect of one form: `model`, named after itself.
pub fn one_form(model: Box<dyn ForwardModel>) -> Vec<EffectForm> {
    vec![EffectForm {
        name: model.name(),
        model,
    }]
}

/// The forms of `effect` that `model` offers ([`Enrichable::enrich_forms`]),
/// or the error of [`enrich`].
pub fn enrich_forms(
    model: &dyn ForwardModel,
    effect: Effect,
) -> Result<Vec<EffectForm>, ForwardError> {
    match model.as_enrichable() {
        Some(e) => e.enrich_forms(effect),
        None => Err(not_applicable(effect, &model.name())),
    }
}

/// `base_theta` followed by the initial values of the remaining parameters
/// of `space` (the default "off" point of an enriched model).
pub fn default_embed(space: &ParamSpace, base_theta: &[f64]) -> Vec<f64> {
    let mut v = base_theta.to_vec();
    v.extend(
        space
            .params
            .iter()
            .skip(base_theta.len())
            .map(|p| p.initial),
    );
    v
}

/// The effects `model` offers: none unless it is [`Enrichable`].
pub fn effects_of(model: &dyn ForwardModel) -> Vec<Effect> {
    model
        .as_enrichable()
        .map(Enrichable::effects)
        .unwrap_or_default()
}

/// `model` with `effect` added, or an error naming the model when it does
/// not offer that effect (or is not [`Enrichable`] at all).
pub fn enrich(
    model: &dyn ForwardModel,
    effect: Effect,
) -> Result<Box<dyn ForwardModel>, ForwardError> {
    match model.as_enrichable() {
        Some(e) => e.enrich(effect),
        None => Err(not_applicable(effect, &model.name())),
    }
}

/// The "effect off" point of an enriched model `enriched` for base
/// parameters `base_theta`: its [`Enrichable::embed`], or [`default_embed`]
/// when it is not itself enrichable.
pub fn embed(enriched: &dyn ForwardModel, base_theta: &[f64]) -> Vec<f64> {
    match enriched.as_enrichable() {
        Some(e) => e.embed(base_theta),
        None => default_embed(enriched.space(), base_theta),
    }
}

/// The error for an effect that does not apply to the model named `name`.
pub fn not_applicable(effect: Effect, name: &str) -> ForwardError {
    ForwardError::InvalidConfig {
        field: "effect".into(),
        reason: format!("`{effect}` does not apply to {name}"),
    }
}
