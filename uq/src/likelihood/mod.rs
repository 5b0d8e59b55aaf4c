//! Priors, noise models and the posterior of a forward model's parameters.
//!
//! * [`Prior`]: flat, uniform, normal, log-normal, half-normal.
//! * [`NoiseModel`]: Gaussian noise with known or inferred SD, independent or
//!   AR(1)-correlated (exact likelihood).
//! * [`Posterior`]: data sets + priors as a [`crate::mcmc::LogDensity`] in the
//!   unbounded space, with the transforms' log-Jacobian.
//! * [`fit_and_laplace`]: least-squares fit, Laplace approximation, chain start.
//! * [`thermodynamic_integration`]: evidence by power posteriors.
//! * [`predictive_band`]: posterior predictive bands.
//! * [`RandomEffects`]: the hierarchical posterior of replicates (population
//!   mean and between-test SD of each parameter).

pub mod evidence;
pub mod hierarchical;
pub mod map_start;
pub mod noise;
pub mod posterior;
pub mod predictive;
pub mod prior;

pub use evidence::{thermodynamic_integration, ThermodynamicEvidence};
pub use hierarchical::{HierarchicalPosterior, Population, RandomEffects};
pub use map_start::{fit_and_laplace, PosteriorStart, StartError};
pub use noise::{
    ar1_log_likelihood, gaussian_log_likelihood, gaussian_log_likelihood_with_model_error,
    Correlation, NoiseModel, NoiseSd,
};
pub use posterior::{DataSet, LikelihoodError, Posterior, Tempered};
pub use predictive::{predictive_band, PredictiveBand};
pub use prior::Prior;
