//! Markov chain Monte Carlo on a slice-based log-density.
//!
//! * [`LogDensity`] / [`DensityWorker`]: what samplers move on (any
//!   `Fn(&[f64]) -> f64` through [`FnDensity`]; a posterior of a forward
//!   model through [`crate::likelihood::Posterior`]).
//! * Samplers: [`sample_ensemble`] (Goodman-Weare stretch move, as emcee),
//!   [`sample_demc`] (DE-MCz population sampler for black-box models),
//!   [`sample_nuts`] (multinomial NUTS with adaptation). Chains run in
//!   parallel, each with its own stream from one seed ([`chain_rng`]), so a
//!   seed gives bit-identical draws whatever the thread count.
//! * [`diagnostics`]: R-hat, bulk/tail ESS, MCSE, autocorrelation time, as ArviZ.
//! * [`summary`]: mean, SD, HDI, correlation.
//! * [`laplace()`]: mode, Hessian covariance and Laplace evidence.
//! * [`units`]: a run's chains (populations, ensembles) one at a time, for
//!   studies that spread them over processes.

// Index loops over coordinates mirror the equations (x_i, L_ij) more
// plainly than zipped iterators in this numerical code.
#![allow(clippy::needless_range_loop)]

pub mod chains;
pub mod converge;
pub mod demc;
pub mod density;
pub mod diagnostics;
pub mod ensemble;
pub mod error;
pub mod laplace;
pub mod nuts;
pub mod rng;
mod standardized;
pub mod start;
pub mod summary;
pub mod units;

pub use chains::{Chains, SampleRun};
pub use converge::{sample_until_converged, ConvergedRun, Convergence, Worst};
pub use demc::{sample_demc, DemcSettings};
pub use density::{fd_value_and_gradient, DensityWorker, FnDensity, GradFnDensity, LogDensity};
pub use ensemble::{sample_ensemble, EnsembleSettings};
pub use error::McmcError;
pub use laplace::{laplace, Laplace};
pub use nuts::{sample_nuts, NutsSettings};
pub use rng::{chain_rng, ChainRng};
pub use start::Start;
pub use summary::{correlation, hdi, summarize, ParamSummary};
pub use units::UnitRun;

/// Which sampler to run, with its settings.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampler {
    Ensemble(EnsembleSettings),
    Demc(DemcSettings),
    Nuts(NutsSettings),
}

impl Sampler {
    /// Runs the chosen sampler.
    pub fn run(
        &self,
        density: &dyn LogDensity,
        start: &Start,
        seed: u64,
        progress: Option<&(dyn Fn(u64) + Sync)>,
    ) -> Result<SampleRun, McmcError> {
        match self {
            Sampler::Ensemble(s) => sample_ensemble(density, start, s, seed, progress),
            Sampler::Demc(s) => sample_demc(density, start, s, seed, progress),
            Sampler::Nuts(s) => sample_nuts(density, start, s, seed, progress),
        }
    }

    /// Total iterations (warm-up included) summed over parallel units, for progress bars.
    pub fn total_iterations(&self) -> u64 {
        match self {
            Sampler::Ensemble(s) => (s.ensembles * (s.tune + s.draws * s.thin)) as u64,
            Sampler::Demc(s) => (s.populations * (s.tune + s.draws * s.thin)) as u64,
            Sampler::Nuts(s) => (s.chains * (s.tune + s.draws)) as u64,
        }
    }
}
