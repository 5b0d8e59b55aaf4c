//! Why an estimator stopped.

use serde::{Deserialize, Serialize};

/// The stopping reason of a fit.
///
/// The first four are convergence (MINPACK's `info` 1-4 in spirit); the
/// others are not.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// Actual and predicted relative reductions of the SSE are both below `ftol`.
    CostReduction,
    /// The scaled step is below `xtol` relative to the scaled parameters.
    RelativeStep,
    /// The cosine between the residual and every Jacobian column is below `gtol`.
    Gradient,
    /// The residuals vanish (exact fit).
    ZeroResidual,
    /// The evaluation budget was exhausted.
    MaxEvaluations,
    /// The iteration budget was exhausted.
    MaxIterations,
    /// The damping grew without bound: no step reduces the SSE.
    NoProgress,
    /// A quasi-Newton solver's own criterion (argmin's text).
    QuasiNewton(String),
}

impl Termination {
    /// Whether the reason counts as convergence.
    pub fn converged(&self) -> bool {
        match self {
            Termination::CostReduction
            | Termination::RelativeStep
            | Termination::Gradient
            | Termination::ZeroResidual => true,
            Termination::QuasiNewton(text) => text == "Solver converged",
            _ => false,
        }
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Termination::CostReduction => f.write_str("relative SSE reduction below ftol"),
            Termination::RelativeStep => f.write_str("relative step below xtol"),
            Termination::Gradient => f.write_str("gradient cosine below gtol"),
            Termination::ZeroResidual => f.write_str("zero residual"),
            Termination::MaxEvaluations => f.write_str("maximum number of evaluations reached"),
            Termination::MaxIterations => f.write_str("maximum number of iterations reached"),
            Termination::NoProgress => f.write_str("damping overflow: no step reduces the SSE"),
            Termination::QuasiNewton(text) => write!(f, "quasi-Newton: {text}"),
        }
    }
}
