//! Exact sensitivities for the estimators: the trait is palpate-core's
//! ([`palpate_core::Sensitivities`], re-exported here), offered by a model
//! through [`palpate_core::ForwardModel::as_sensitivities`];
//! [`ModelSensitivities`] makes that capability of a shared model the
//! `Arc` a [`crate::DataSet`] carries.

use std::sync::Arc;

pub use palpate_core::Sensitivities;
use palpate_core::{ForwardError, ForwardModel, Loading};

/// The exact sensitivities of a shared model that offers them
/// ([`ForwardModel::as_sensitivities`]).
pub struct ModelSensitivities {
    model: Arc<dyn ForwardModel>,
}

impl ModelSensitivities {
    /// `Some` when `model` offers exact sensitivities, `None` otherwise
    /// (the estimators then use finite differences).
    pub fn of(model: &Arc<dyn ForwardModel>) -> Option<Arc<dyn Sensitivities>> {
        model.as_sensitivities()?;
        Some(Arc::new(ModelSensitivities {
            model: Arc::clone(model),
        }))
    }
}

impl Sensitivities for ModelSensitivities {
    fn predict_with_jacobian(
        &self,
        theta: &[f64],
        loading: &Loading,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), ForwardError> {
        match self.model.as_sensitivities() {
            Some(s) => s.predict_with_jacobian(theta, loading),
            None => Err(ForwardError::InvalidConfig {
                field: "sensitivities".into(),
                reason: format!("{} offers no exact sensitivities", self.model.name()),
            }),
        }
    }
}
