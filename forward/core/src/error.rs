//! Errors a forward model can return.

use thiserror::Error;

/// Why a forward evaluation failed.
///
/// `NotConverged` carries the samples that did converge, so a caller keeps the
/// part of the curve that was computed (standard 8 of STYLE.md).
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ForwardError {
    /// A parameter value is outside what the model accepts.
    #[error("parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        name: String,
        value: f64,
        reason: String,
    },
    /// The parameter vector has the wrong length.
    #[error("expected {expected} parameters, got {got}")]
    WrongParameterCount { expected: usize, got: usize },
    /// The loading history does not suit the model.
    #[error("loading history: {0}")]
    InvalidLoading(String),
    /// A configuration field (tool, geometry, mesh) is invalid.
    #[error("configuration `{field}`: {reason}")]
    InvalidConfig { field: String, reason: String },
    /// The nonlinear solution failed after all step cuts; `completed` holds the
    /// predictions of the samples that did converge (a prefix of the history).
    #[error("did not converge at sample {sample} (drive {drive}) after {cuts} step cuts: {reason}; {} samples kept", completed.len())]
    NotConverged {
        sample: usize,
        drive: f64,
        cuts: usize,
        reason: String,
        completed: Vec<f64>,
    },
    /// The material response became unphysical (e.g. a stretch with no
    /// solution, loss of ellipticity) at this drive value.
    #[error("unphysical response at drive {drive}: {reason}")]
    Unphysical { drive: f64, reason: String },
}
