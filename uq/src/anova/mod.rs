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
//!
//! A replicated 2 x 2 design in which only factor `a` acts (it adds 4 to
//! the response) and the replicates differ by +-0.1:
//!
//! ```
//! use palpate_uq::anova::{anova, FactorColumn};
//!
//! let a = FactorColumn::from_names("a", &["lo", "lo", "hi", "hi", "lo", "lo", "hi", "hi"]);
//! let b = FactorColumn::from_names("b", &["lo", "hi", "lo", "hi", "lo", "hi", "lo", "hi"]);
//! let y = [10.1, 10.1, 14.1, 14.1, 9.9, 9.9, 13.9, 13.9];
//! let table = anova("y", &[a, b], &y, 2)?;
//! // SS_a = 8 x 2^2 = 32 on 1 df; the residual SS 8 x 0.01 on 4 df gives F = 1600.
//! let row = table.term("a").unwrap();
//! assert_eq!(row.df, 1);
//! assert!((row.ss - 32.0).abs() < 1e-9);
//! assert!((row.f.unwrap() - 1600.0).abs() < 1e-6 && row.p.unwrap() < 1e-5);
//! assert!(table.term("b").unwrap().ss < 1e-12 && table.term("a:b").unwrap().ss < 1e-12);
//! # Ok::<(), palpate_uq::anova::AnovaError>(())
//! ```

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
