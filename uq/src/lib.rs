//! # palpate-uq
//!
//! Uncertainty quantification on any forward model (through palpate-core's
//! trait only): MCMC posteriors and their diagnostics, designed experiments
//! and ANOVA, and the sim-to-real gap diagnosis.

pub mod anova;
pub mod doe;
pub mod gap;
pub mod likelihood;
pub mod mcmc;
pub mod stats;
pub mod surrogate;
