//! # palpate-uq
//!
//! Uncertainty quantification on any forward model (through palpate-core's
//! trait only): MCMC posteriors and their diagnostics, designed experiments
//! and ANOVA, and the sim-to-real gap diagnosis; the posterior of a model
//! that states its own error variance (`model_error`).

pub mod anova;
pub mod doe;
pub mod gap;
pub mod likelihood;
pub mod mcmc;
pub mod model_error;
pub mod stats;
pub mod surrogate;
