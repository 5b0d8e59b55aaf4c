//! Why a statistical test could not be computed.

use thiserror::Error;

/// Why a test statistic is undefined for the given data.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum StatsError {
    /// Too few observations (in total or in one group).
    #[error("{test}: needs at least {needed} observations{}, got {got}", group.map(|g| format!(" in group {g}")).unwrap_or_default())]
    TooFew {
        test: &'static str,
        needed: usize,
        got: usize,
        group: Option<usize>,
    },
    /// A value is NaN or infinite.
    #[error("{what}: value {index} is NaN or infinite")]
    NotFinite { what: &'static str, index: usize },
    /// The statistic divides by a spread that is zero.
    #[error("{test}: undefined because {reason}")]
    ZeroSpread { test: &'static str, reason: String },
    /// Fewer than two groups to compare.
    #[error("{test}: needs at least 2 groups, got {got}")]
    TooFewGroups { test: &'static str, got: usize },
}
