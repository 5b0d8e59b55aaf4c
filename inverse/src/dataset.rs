//! One experiment to fit: a model, its loading, the observations.

use crate::{InverseError, Sensitivities};
use palpate_core::{ForwardModel, Loading};
use std::sync::Arc;

/// A data set of an objective.
///
/// All data sets of one objective share one parameter vector, so their
/// models must have the same parameter names in the same order.
#[derive(Clone)]
pub struct DataSet {
    /// Name used in reports and errors.
    pub name: String,
    /// The forward model (shared, immutable).
    pub model: Arc<dyn ForwardModel>,
    /// The loading history the observations were recorded under.
    pub loading: Loading,
    /// Observed values, one per loading sample, in the model's observable unit.
    pub observed: Vec<f64>,
    /// Weight multiplying every residual of the set (default 1).
    pub weight: f64,
    /// Exact sensitivities, when the model provides them.
    pub sensitivities: Option<Arc<dyn Sensitivities>>,
}

impl std::fmt::Debug for DataSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DataSet")
            .field("name", &self.name)
            .field("model", &self.model.name())
            .field("samples", &self.loading.len())
            .field("weight", &self.weight)
            .field("exact_sensitivities", &self.sensitivities.is_some())
            .finish()
    }
}

impl DataSet {
    /// A data set with weight 1 and finite-difference sensitivities.
    pub fn new(
        name: impl Into<String>,
        model: Arc<dyn ForwardModel>,
        loading: Loading,
        observed: Vec<f64>,
    ) -> Self {
        DataSet {
            name: name.into(),
            model,
            loading,
            observed,
            weight: 1.0,
            sensitivities: None,
        }
    }

    /// The same set with another weight.
    pub fn with_weight(mut self, weight: f64) -> Self {
        self.weight = weight;
        self
    }

    /// The same set with exact sensitivities (they must describe `model`).
    pub fn with_sensitivities(mut self, sensitivities: Arc<dyn Sensitivities>) -> Self {
        self.sensitivities = Some(sensitivities);
        self
    }

    /// The same set with the exact sensitivities of its model when the
    /// model offers them ([`palpate_core::ForwardModel::as_sensitivities`]),
    /// unchanged (finite differences) otherwise.
    pub fn with_model_sensitivities(self) -> Self {
        match crate::ModelSensitivities::of(&self.model) {
            Some(s) => self.with_sensitivities(s),
            None => self,
        }
    }

    /// Checks lengths, finiteness, the weight and the loading.
    pub fn validate(&self) -> Result<(), InverseError> {
        if self.observed.len() != self.loading.len() {
            return Err(InverseError::LengthMismatch {
                set: self.name.clone(),
                observed: self.observed.len(),
                samples: self.loading.len(),
            });
        }
        if let Some(index) = self.observed.iter().position(|y| !y.is_finite()) {
            return Err(InverseError::NonFiniteObservation {
                set: self.name.clone(),
                index,
            });
        }
        if !(self.weight.is_finite() && self.weight > 0.0) {
            return Err(InverseError::InvalidWeight {
                set: self.name.clone(),
                weight: self.weight,
            });
        }
        self.loading
            .validate()
            .map_err(|reason| InverseError::InvalidLoading {
                set: self.name.clone(),
                reason,
            })
    }
}
