//! The integration tests of `palpate-uq`, one module per file, compiled into
//! one test binary: one link instead of one per file, and `cargo test` runs
//! the files' tests side by side on its threads instead of one binary after
//! another (the CI's test time; see `.ci/run`). Run one file's tests with
//! `cargo test -p palpate-uq --test integration FILE::`.

mod anova_designs;
mod anova_reference;
mod anova_table1;
mod common;
mod mcmc_arviz;
mod mcmc_c1;
mod mcmc_evidence;
mod mcmc_gradient;
mod mcmc_likelihood;
mod mcmc_samplers;
mod mcmc_surrogate;
mod surrogate_units;
