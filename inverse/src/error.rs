//! Errors of the estimators.

use palpate_core::ForwardError;
use thiserror::Error;

/// Why a fit could not be set up or run.
///
/// Forward failures carry the data set and the physical parameter vector of
/// the evaluation that failed, so a caller can reproduce it.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum InverseError {
    /// A forward evaluation failed at a point the estimator could not avoid
    /// (the starting point, or a finite-difference step).
    #[error("forward model of data set `{set}` failed at theta = {theta:?} ({stage}): {source}")]
    Forward {
        set: String,
        theta: Vec<f64>,
        stage: &'static str,
        #[source]
        source: Box<ForwardError>,
    },
    /// The objective has no data set.
    #[error("the objective has no data set")]
    NoDataSets,
    /// Two data sets' models name their parameters differently.
    #[error("data set `{set}` has parameters {found:?} but `{first}` has {expected:?}; all sets must share one parameter space")]
    ParameterMismatch {
        set: String,
        first: String,
        expected: Vec<String>,
        found: Vec<String>,
    },
    /// Observations and loading of a data set disagree in length.
    #[error("data set `{set}`: {observed} observations for {samples} loading samples")]
    LengthMismatch {
        set: String,
        observed: usize,
        samples: usize,
    },
    /// An observation is NaN or infinite.
    #[error("data set `{set}`: observation {index} is not finite")]
    NonFiniteObservation { set: String, index: usize },
    /// The loading history of a data set is invalid.
    #[error("data set `{set}`: {reason}")]
    InvalidLoading { set: String, reason: String },
    /// A weight is not a positive finite number.
    #[error("data set `{set}`: weight {weight} must be positive and finite")]
    InvalidWeight { set: String, weight: f64 },
    /// `Normalised` residuals need observations that are not all zero.
    #[error("data set `{set}`: all observations are zero, cannot normalise by their RMS")]
    ZeroObservations { set: String },
    /// A data set keeps no residual (e.g. relative residuals of all-zero data).
    #[error("data set `{set}` contributes no residual")]
    EmptySet { set: String },
    /// A fixed parameter is not in the parameter space.
    #[error("fixed parameter `{name}` is not a parameter of the model (parameters: {known:?})")]
    UnknownParameter { name: String, known: Vec<String> },
    /// A fixed value or starting value lies outside (or on) its bounds.
    #[error(
        "parameter `{name}` = {value} must lie strictly inside ({lower}, {upper}) to start a fit"
    )]
    OutOfBounds {
        name: String,
        value: f64,
        lower: f64,
        upper: f64,
    },
    /// The starting vector has the wrong length.
    #[error("expected {expected} starting values, got {got}")]
    WrongStartLength { expected: usize, got: usize },
    /// Every parameter is fixed: nothing to estimate.
    #[error("every parameter is fixed; nothing to estimate")]
    NothingToFit,
    /// An option is out of range.
    #[error("option `{option}`: {reason}")]
    InvalidOption {
        option: &'static str,
        reason: String,
    },
    /// Trial steps in a row from the point `from` (the physical parameters)
    /// failed to evaluate, the shorter ones too; `last` is the last one's
    /// failure (which names its point and cause).
    #[error("{solver}: {failures} trial steps in a row from theta = {from:?} failed to evaluate, however short; the last: {last}")]
    TrialsFailed {
        solver: &'static str,
        from: Vec<f64>,
        failures: usize,
        #[source]
        last: Box<InverseError>,
    },
    /// The optimiser library reported an error that is not a forward failure.
    #[error("optimiser `{solver}` failed: {reason}")]
    Solver {
        solver: &'static str,
        reason: String,
    },
}
