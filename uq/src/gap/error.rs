//! Errors of the gap diagnosis.

use palpate_core::ForwardError;
use palpate_inverse::InverseError;
use thiserror::Error;

/// Why a diagnosis could not be made.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum GapError {
    /// Too few samples for the noise estimate and the tests.
    #[error("{got} samples; the diagnosis needs at least {needed} (the noise is estimated from second differences of neighbouring samples): record more samples along the loading path")]
    TooFewSamples { got: usize, needed: usize },
    /// Observations and loading disagree in length.
    #[error("{observed} observations for {samples} loading samples")]
    LengthMismatch { observed: usize, samples: usize },
    /// An observation is NaN or infinite.
    #[error("observation {index} is not finite")]
    NonFinite { index: usize },
    /// The data carry no noise the estimator can see (all pseudo-residuals zero).
    #[error("the noise estimate is zero: the data look noise-free, so no misfit can be judged against noise")]
    ZeroNoise,
    /// An option is out of range.
    #[error("option `{option}`: {reason}")]
    InvalidOption {
        option: &'static str,
        reason: String,
    },
    /// The base model could not be evaluated.
    #[error("base model: {0}")]
    Forward(#[from] ForwardError),
    /// The base model could not be fitted.
    #[error("fit of {model}: {source}")]
    Fit {
        model: String,
        #[source]
        source: InverseError,
    },
}
