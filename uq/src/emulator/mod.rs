//! Gaussian-process emulators of expensive forward models (FE), trained on a
//! space-filling design of model runs, so that a posterior can be sampled on
//! the emulator instead of the model.

pub mod gp;

pub use gp::{halton_design, CurveEmulator, EmulatorError, Validation};
