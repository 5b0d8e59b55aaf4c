//! Analysis of variance of factorial experiments.
//!
//! * [`FactorColumn`] — one factor's level names per run; [`RunsTable`] reads
//!   them (and the response) from a CSV whose factor columns hold level names.
//! * [`anova`] — the ANOVA table (SS, df, MS, F, p, eta^2, partial eta^2),
//!   R^2 and adjusted R^2, coefficients, fitted values and residuals, from the
//!   regression formulation with sum-to-zero contrasts and sequential
//!   (Type I) sums of squares (see [`table`] for why that equals Type III on
//!   balanced designs).
//! * [`standardised_effects`] and [`Pareto`] — effects for a Pareto chart;
//!   [`lenth`] — Lenth's pseudo standard error for unreplicated two-level designs.
//! * [`main_effect_means`], [`interaction_means`] — data of the main-effects
//!   and interaction plots.
//! * [`analyse`] — all of the above plus the residual checks of
//!   [`crate::stats`], as one serialisable [`Analysis`].

mod analysis;
mod coding;
mod effects;
mod error;
mod lenth;
mod means;
mod qr;
mod runs_table;
pub mod table;
mod terms;

pub use analysis::{analyse, Analysis, AnovaOptions};
pub use coding::{cells, FactorColumn};
pub use effects::{standardised_effects, Pareto, StandardisedEffect};
pub use error::AnovaError;
pub use lenth::{lenth, Lenth};
pub use means::{interaction_means, main_effect_means, InteractionMeans, MainEffectMeans};
pub use runs_table::{RunsTable, RunsTableError};
pub use table::{anova, AnovaTable, Residual, TermRow, Total};
pub use terms::{hierarchical_terms, Term};
