//! From a description to a forward model.

use palpate_core::ForwardModel;

use super::Experiment;
use crate::FeError;

/// The model of an experiment: the FE setup its specimen and tool call
/// for.
#[derive(Debug, Clone)]
pub enum ExperimentModel {
    /// An axisymmetric cylinder (N1's setup, generalised).
    Cylinder(crate::N1Needle),
}

impl ExperimentModel {
    /// The model behind the forward trait.
    pub fn as_forward(&self) -> &dyn ForwardModel {
        match self {
            ExperimentModel::Cylinder(m) => m,
        }
    }
    /// The model boxed.
    pub fn boxed(self) -> Box<dyn ForwardModel> {
        match self {
            ExperimentModel::Cylinder(m) => Box::new(m),
        }
    }
}

impl Experiment {
    /// The forward model of this experiment.
    pub fn model(&self) -> Result<ExperimentModel, FeError> {
        Ok(ExperimentModel::Cylinder(crate::FeModel::from_setup(
            crate::N1Setup::from_experiment(self)?,
        )))
    }
}
