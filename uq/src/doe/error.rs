//! Why a design could not be built.

use thiserror::Error;

/// Why a design specification is invalid.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum DoeError {
    #[error("a design needs at least one factor")]
    NoFactors,
    #[error("factor `{factor}` needs at least 2 levels, has {got}")]
    TooFewLevels { factor: String, got: usize },
    #[error("factor `{factor}` lists level `{level}` twice")]
    DuplicateLevel { factor: String, level: String },
    #[error("factor name `{factor}` is used twice")]
    DuplicateFactor { factor: String },
    #[error("replicates must be at least 1, got {got}")]
    NoReplicates { got: usize },
    #[error("a fractional design needs two-level factors; `{factor}` has {got} levels")]
    NotTwoLevel { factor: String, got: usize },
    #[error("generator `{text}`: {reason}")]
    BadGenerator { text: String, reason: String },
    #[error("too many factors for a two-level design ({got}, at most {max})")]
    TooManyFactors { got: usize, max: usize },
    #[error("the design would have {runs} runs, more than the limit of {max}")]
    TooManyRuns { runs: usize, max: usize },
}
