//! A forward model that counts its predictions (the FE runs of a gap
//! diagnosis), in total and by model, and whose enrichments count too: the
//! N1 gap benches report where the runs go with it.

use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamSpace,
};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// FE simulations made through [`Counted`].
pub static RUNS: AtomicUsize = AtomicUsize::new(0);

/// FE simulations by model (`--explain`: where the runs go).
pub static BY_MODEL: Mutex<BTreeMap<String, usize>> = Mutex::new(BTreeMap::new());

/// A model that counts its predictions, and whose enrichments do too.
pub struct Counted(pub Arc<dyn ForwardModel>);

struct CountedEval<'a>(Box<dyn Evaluator + 'a>, String);

impl Evaluator for CountedEval<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        RUNS.fetch_add(1, Ordering::Relaxed);
        if let Ok(mut m) = BY_MODEL.lock() {
            *m.entry(self.1.clone()).or_default() += 1;
        }
        self.0.predict_into(theta, loading, out)
    }
}

impl ForwardModel for Counted {
    fn name(&self) -> String {
        self.0.name()
    }
    fn space(&self) -> &ParamSpace {
        self.0.space()
    }
    fn observable(&self) -> Observable {
        self.0.observable()
    }
    fn expensive(&self) -> bool {
        self.0.expensive()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(CountedEval(self.0.evaluator(), self.0.name()))
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for Counted {
    fn effects(&self) -> Vec<Effect> {
        palpate_core::enrichable::effects_of(self.0.as_ref())
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        let rich = palpate_core::enrichable::enrich(self.0.as_ref(), effect)?;
        Ok(Box::new(Counted(Arc::from(rich))))
    }
    fn enrich_forms(
        &self,
        effect: Effect,
    ) -> Result<Vec<palpate_core::enrichable::EffectForm>, ForwardError> {
        let forms = palpate_core::enrichable::enrich_forms(self.0.as_ref(), effect)?;
        Ok(forms
            .into_iter()
            .map(|f| palpate_core::enrichable::EffectForm {
                name: f.name,
                model: Box::new(Counted(Arc::from(f.model))),
            })
            .collect())
    }
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        palpate_core::enrichable::embed(self.0.as_ref(), base_theta)
    }
}
