//! Errors of the material crate: every bad input names what was wrong.

use serde::{Deserialize, Serialize};

/// What can go wrong when naming a law, checking its parameters or solving a homogeneous state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, thiserror::Error)]
#[non_exhaustive]
pub enum MaterialError {
    /// The law name is not one of the known spellings.
    #[error("unknown material law `{text}` (expected neo-hookean, mooney-rivlin, reduced-polynomial:N, yeoh, arruda-boyce, ogden:N, gent, veronda-westmann or humphrey)")]
    UnknownLaw {
        /// The text that was parsed.
        text: String,
    },
    /// The order of a series law is outside its allowed range.
    #[error("law `{law}`: order {order} is not allowed (allowed: {allowed})")]
    BadOrder {
        /// The law family, e.g. `reduced-polynomial`.
        law: String,
        /// The order that was asked for.
        order: usize,
        /// The allowed orders, e.g. `1..=6`.
        allowed: String,
    },
    /// The parameter vector has the wrong length.
    #[error("law `{law}` takes {expected} parameters, got {got}")]
    WrongCount {
        /// The canonical law name.
        law: String,
        /// Number of parameters the law takes.
        expected: usize,
        /// Number of parameters given.
        got: usize,
    },
    /// A parameter is NaN or infinite.
    #[error("parameter {name} = {value} is not finite")]
    NotFinite {
        /// The parameter name (commercial convention, e.g. `C10`).
        name: String,
        /// Its value.
        value: f64,
    },
    /// A parameter (or a combination, named as such) breaks a sign or range rule.
    #[error("parameter {name} = {value} is not allowed: {requirement}")]
    OutOfRange {
        /// The parameter name, or the combination (e.g. `C10 + C01`).
        name: String,
        /// Its value.
        value: f64,
        /// The rule it breaks, e.g. `must be > 0`.
        requirement: String,
    },
    /// A deformation outside the domain of a law (Gent's limit) or where its energy overflows.
    #[error("law `{law}` at principal stretches {stretches:?}: {reason}")]
    OutsideDomain {
        /// The canonical law name.
        law: String,
        /// The principal stretches evaluated.
        stretches: [f64; 3],
        /// What is wrong and what would be valid.
        reason: String,
    },
    /// A stretch given to a homogeneous solution is not a positive finite number.
    #[error("stretch {stretch} is not a positive finite number")]
    BadStretch {
        /// The stretch given.
        stretch: f64,
    },
    /// A solve for a homogeneous state did not converge (or found no root to converge to).
    #[error("{what}: no convergence after {iterations} iterations (residual {residual:e})")]
    NoConvergence {
        /// What was being solved.
        what: String,
        /// Iterations done.
        iterations: usize,
        /// The last residual.
        residual: f64,
    },
}
