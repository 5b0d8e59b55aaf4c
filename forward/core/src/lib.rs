//! # palpate-core
//!
//! The vocabulary every palpate crate shares, and nothing more:
//!
//! * [`ForwardModel`] — a shared, immutable description of an experiment's
//!   model; [`Evaluator`] — the per-thread object that owns scratch space and
//!   history and turns parameters plus a [`Loading`] into predictions.
//! * [`ParamSpace`] — named physical parameters with bounds and the transform
//!   to the unbounded space that estimators and samplers move in.
//! * [`Loading`] — the loading history (time and drive samples);
//!   [`Output`] — one of the quantities a model predicts at each sample
//!   (most models have one; [`ForwardModel::outputs`]).
//! * [`Effect`] — the canonical names of unmodelled effects (see `GAP.md`);
//!   [`Enrichable`] — the capability of a model that can add them.
//! * [`Sensitivities`] — the capability of a model that gives the exact
//!   derivatives of its predictions ([`ForwardModel::as_sensitivities`]).
//! * [`fd`] — finite-difference Jacobians (one step rule for every crate).
//! * [`data`] — reading the project's CSV data files with errors naming file,
//!   line and column.
//!
//! Estimators (`palpate-inverse`, `palpate-uq`) depend on this crate only, so
//! a wrong dependency arrow to the FE code fails to compile.

pub mod data;
pub mod effect;
pub mod enrichable;
pub mod error;
pub mod fd;
pub mod loading;
pub mod model;
pub mod param;
pub mod sensitivities;

pub use data::{Column, DataError, Table, TextTable};
pub use effect::Effect;
pub use enrichable::Enrichable;
pub use error::ForwardError;
pub use loading::{Drive, Loading, Observable, Output};
pub use model::{check_output_slots, Evaluator, ForwardModel, ModelExt};
pub use param::{ParamRole, ParamSpace, ParamSpec, Transform};
pub use sensitivities::Sensitivities;
