//! Why an ANOVA could not be computed.

use thiserror::Error;

/// Why the ANOVA inputs are unusable.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum AnovaError {
    #[error("the model needs at least one factor")]
    NoFactors,
    #[error("factor `{factor}` has {got} values but the response has {expected}")]
    LengthMismatch {
        factor: String,
        got: usize,
        expected: usize,
    },
    #[error("response value {index} is NaN or infinite")]
    NotFinite { index: usize },
    #[error("factor `{factor}` has a single level (`{level}`): it cannot have an effect")]
    SingleLevel { factor: String, level: String },
    #[error("factor `{factor}` appears twice in the model")]
    DuplicateFactor { factor: String },
    #[error("{needed} runs needed at least, got {got}")]
    TooFewRuns { needed: usize, got: usize },
    #[error("the response does not vary (total sum of squares is zero)")]
    ConstantResponse,
    #[error("Lenth's method needs at least {needed} effects, got {got}")]
    TooFewEffects { needed: usize, got: usize },
    #[error(
        "Lenth's pseudo standard error is zero (at least half of the effects are exactly zero)"
    )]
    ZeroPse,
    #[error("alpha must lie in (0, 1), got {alpha}")]
    BadAlpha { alpha: f64 },
}
