//! Why a sampler could not run.

use thiserror::Error;

/// Errors of the samplers and the Laplace approximation.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum McmcError {
    /// The start point has the wrong length.
    #[error("start point has {got} coordinates, the density has {expected}")]
    DimensionMismatch { expected: usize, got: usize },
    /// No finite log-density was found near the start point.
    #[error("chain {chain}: no finite log-density within {tries} tries around the start point")]
    NoFiniteStart { chain: usize, tries: usize },
    /// A setting is out of range.
    #[error("setting `{field}`: {reason}")]
    InvalidSettings { field: String, reason: String },
    /// The mode search or the Hessian failed.
    #[error("Laplace approximation: {reason}")]
    Laplace { reason: String },
}
