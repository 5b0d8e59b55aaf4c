//! Surrogates of expensive forward models (finite elements) for posteriors:
//! parameters -> every output of a model on one loading history, trained
//! once on a space-filling design inside a stated box, its error measured on
//! held-out runs and added to the likelihood, stored as JSON under a key that
//! hashes everything defining it.
//!
//! The one surrogate of palpate: `palpate sample --benchmark N1|N3|Q1` and
//! `palpate localize` both use it (through `palpate_studies::run::surrogate`,
//! which adds the on-disk cache). How to put a new model behind it:
//! docs/architecture.md, "a surrogate for a new FE model".
//!
//! ```
//! use palpate_core::{Drive, Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamSpace, ParamSpec};
//! use palpate_uq::surrogate::{ParamBox, Surrogate, SurrogateOptions, SurrogateRequest};
//!
//! // A stand-in for an FE model: F(d) = k d + c d^3.
//! struct Spring(ParamSpace);
//! struct Eval;
//! impl Evaluator for Eval {
//!     fn predict_into(&mut self, t: &[f64], l: &Loading, o: &mut [f64]) -> Result<(), ForwardError> {
//!         for (o, d) in o.iter_mut().zip(&l.drive) { *o = t[0] * d + t[1] * d * d * d; }
//!         Ok(())
//!     }
//! }
//! impl ForwardModel for Spring {
//!     fn name(&self) -> String { "spring".into() }
//!     fn space(&self) -> &ParamSpace { &self.0 }
//!     fn observable(&self) -> Observable { Observable::ForceN }
//!     fn evaluator(&self) -> Box<dyn Evaluator + '_> { Box::new(Eval) }
//! }
//! let model = Spring(ParamSpace::new(vec![
//!     ParamSpec::new("k", "N/mm", 0.0, f64::INFINITY, 1.0),
//!     ParamSpec::new("c", "N/mm3", 0.0, f64::INFINITY, 0.1),
//! ]));
//! let loading = Loading::quasi_static(Drive::DisplacementMm, (1..=20).map(|i| 0.1 * i as f64).collect());
//! let request = SurrogateRequest {
//!     model: &model,
//!     loading: &loading,
//!     bounds: ParamBox::new(model.space(), &[0.5, 0.0], &[2.0, 0.5])?,
//!     options: SurrogateOptions::for_dimension(2),
//!     description: "spring, doc example".into(),
//! };
//! let s = Surrogate::build(&request, None)?;
//! assert!(s.validation().max_relative_error < 1e-3);
//! // It is a forward model on its box ...
//! let f = s.predict(&[1.0, 0.2], &loading)?;
//! assert!((f[19] - (2.0 + 0.2 * 8.0)).abs() < 1e-3);
//! // ... and refuses outside it.
//! assert!(s.predict(&[3.0, 0.2], &loading).unwrap_err().to_string().contains("trained box"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod design;
pub mod gp;
pub mod model;

pub use design::{halton_design, ParamBox};
pub use model::{
    cpu_seconds, FailedRun, Surrogate, SurrogateOptions, SurrogateRequest, Validation,
    SURROGATE_FORMAT,
};

use thiserror::Error;

/// Why a surrogate could not be built or asked.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum SurrogateError {
    /// The training box is malformed.
    #[error("surrogate box, parameter {name}: {reason}")]
    InvalidBox { name: String, reason: String },
    /// A parameter outside the trained box: the surrogate does not extrapolate.
    #[error("{name} = {value} is outside the surrogate's trained box [{lower}, {upper}]: it does not extrapolate (train it on a wider box)")]
    OutsideBox {
        name: String,
        value: f64,
        lower: f64,
        upper: f64,
    },
    /// Bad design sizes or tolerance.
    #[error("surrogate options: {0}")]
    InvalidOptions(String),
    /// Too many model runs of the design failed.
    #[error("{failed} of {total} model runs of the design failed (first at {theta:?}: {reason}); narrow the box")]
    TooManyFailures {
        failed: usize,
        total: usize,
        theta: Vec<f64>,
        reason: String,
    },
    /// No GP fit was possible.
    #[error("the Gaussian-process fit failed (kernel matrix not positive definite)")]
    Singular,
}
