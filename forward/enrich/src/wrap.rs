//! Composition of the drive/response wrappers (viscoelasticity, zero offset,
//! tool compliance): which effects a wrapped model still offers, and how to
//! add one.

use crate::{ToolCompliance, Viscoelastic, ZeroOffset};
use palpate_core::enrichable::{effects_of, not_applicable};
use palpate_core::{Effect, ForwardError, ForwardModel, Observable};
use std::sync::Arc;

/// Effects that are added by wrapping a model (rather than by changing its law).
pub const WRAPPER_EFFECTS: [Effect; 3] = [
    Effect::Viscoelasticity,
    Effect::ZeroOffset,
    Effect::ToolCompliance,
];

/// Number of Prony terms an enrichment with `viscoelasticity` adds.
pub const DEFAULT_PRONY_TERMS: usize = 2;

/// `model` enriched with one wrapper effect (one of [`WRAPPER_EFFECTS`]).
/// The zero offset of a model that predicts a nominal stress (a
/// stretch-driven homogeneous test) is an offset of the stretch
/// ([`ZeroOffset::on_stretch`]), of any other model one of the displacement.
pub fn wrap(
    effect: Effect,
    model: Arc<dyn ForwardModel>,
) -> Result<Box<dyn ForwardModel>, ForwardError> {
    match effect {
        Effect::Viscoelasticity => Ok(Box::new(Viscoelastic::from_arc(model, DEFAULT_PRONY_TERMS))),
        Effect::ZeroOffset if model.observable() == Observable::NominalStressMPa => {
            Ok(Box::new(ZeroOffset::on_stretch(model)))
        }
        Effect::ZeroOffset => Ok(Box::new(ZeroOffset::from_arc(model))),
        Effect::ToolCompliance => Ok(Box::new(ToolCompliance::from_arc(model))),
        _ => Err(not_applicable(effect, &model.name())),
    }
}

/// Effects a wrapper around `inner` offers: the inner model's wrapper
/// effects, minus the wrapper's own (each is added at most once; law
/// changes are only offered by the bare models).
pub fn wrapper_effects(inner: &dyn ForwardModel, own: Effect) -> Vec<Effect> {
    effects_of(inner)
        .into_iter()
        .filter(|e| WRAPPER_EFFECTS.contains(e) && *e != own)
        .collect()
}

/// Enrichment of a wrapper `this` (an `Arc` of itself) with `effect`.
pub(crate) fn enrich_wrapper(
    this: Arc<dyn ForwardModel>,
    inner: &dyn ForwardModel,
    own: Effect,
    effect: Effect,
) -> Result<Box<dyn ForwardModel>, ForwardError> {
    if wrapper_effects(inner, own).contains(&effect) {
        wrap(effect, this)
    } else {
        Err(not_applicable(effect, &this.name()))
    }
}
