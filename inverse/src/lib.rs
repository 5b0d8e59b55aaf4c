//! # palpate-inverse
//!
//! Calibration of forward models against data: least-squares objectives over
//! one or several data sets sharing one parameter vector ([`Objective`]),
//! Levenberg-Marquardt as an argmin solver ([`LevenbergMarquardt`]), BFGS
//! and L-BFGS through argmin, finite-difference Jacobians computed in
//! parallel over columns (bit-identical to serial), covariance and
//! identifiability at the optimum, all reported in a serialisable
//! [`FitReport`].
//!
//! Depends on `palpate-core` only: estimators see `dyn ForwardModel`.
//!
//! A Levenberg-Marquardt fit of C1 (closed-form neo-Hookean compression)
//! to noise-free data recovers the modulus that made them:
//!
//! ```
//! use palpate_analytic::C1Compression;
//! use palpate_core::{Drive, ForwardModel, Loading};
//! use palpate_inverse::{fit, DataSet, FitOptions, Objective, ResidualKind};
//! use palpate_material::Law;
//! use std::sync::Arc;
//!
//! let model = Arc::new(C1Compression::new(Law::NeoHookean));
//! let loading = Loading::quasi_static(
//!     Drive::DisplacementMm,
//!     (1..=20).map(|i| 0.1 * i as f64).collect(),
//! );
//! let observed = model.predict(&[0.025], &loading)?;
//! let set = DataSet::new("c1", model, loading, observed);
//! let objective = Objective::new(vec![set], ResidualKind::Absolute, &[])?;
//! let report = fit(&objective, &FitOptions::default())?;
//! assert!(report.converged);
//! assert!((report.parameters[0].value - 0.025).abs() < 1e-8);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod boundary_polish;
pub mod covariance;
pub(crate) mod curvature;
pub mod dataset;
pub mod design;
pub mod error;
pub mod fidelity_correction;
pub mod fit;
pub mod jacobian;
pub mod lm;
pub mod objective;
pub mod observer;
pub mod problem;
pub mod report;
pub mod residual;
pub mod run;
pub mod sensitivities;
pub mod staged;
pub mod termination;
pub mod wall_slide;

pub use boundary_polish::{near_bound, POLISH_RELATIVE_DISTANCE};
pub use covariance::{
    covariance, covariance_with_noise, CorrelatedPair, Covariance, Identifiability, MAX_CONDITION,
    MAX_CORRELATION,
};
pub use curvature::MAX_RESETS_IN_A_ROW;
pub use dataset::DataSet;
pub use error::InverseError;
pub use fidelity_correction::{CorrectedModel, FidelityCorrection};
pub use fit::{fit, start_points, statistics, FitOptions, MultiStart};
pub use jacobian::{
    finite_difference_jacobian, jacobian_unbounded, residuals_and_exact_jacobian, FdOptions,
    JacobianEval,
};
pub use lm::{LevenbergMarquardt, LmOptions, LmState};
pub use objective::{sum_of_squares, Evaluators, Objective, ParamMap};
pub use observer::{shared_observer, FitObserver, Progress, SharedObserver};
pub use problem::{EvaluationCount, LeastSquaresProblem, Runs};
pub use report::{BoundSide, FitReport, ParameterEstimate, SetReport};
pub use residual::ResidualKind;
pub use run::{Method, QuasiNewtonOptions};
pub use sensitivities::{ModelSensitivities, Sensitivities};
pub use termination::Termination;
