//! The forward models built on the layer, one [`crate::model::Setup`] each
//! (the reference problems of docs/benchmarks.md) and the models made of them:
//!
//! * [`n1`] — N1, needle indentation of a cylinder (axisymmetric), and
//!   [`cylinder`], the axisymmetric cylinder of an experiment description
//!   (N1's setup with any tool, support, layers and materials), and
//!   `n1_effects`, the effects of the gap diagnosis they offer;
//! * [`n3`] — N3, the same needle on a block in 3D (quarter model);
//! * [`c1`] — C1, compression of a short cylinder between platens;
//! * [`q1`] — Q1, flat-punch ramp-and-hold indentation, and
//!   [`q1::viscous`], Q1 with its Prony weight and time as parameters;
//! * [`r2`] — R2, a wheel rolled over a block with stiff nodules (plane
//!   stress); [`r2_gap`], R2 as a base model of the gap diagnosis;
//!   [`r2_scan`], the force of the wheel rolled past one nodule.

pub mod c1;
pub mod cylinder;
pub mod n1;
mod n1_effects;
pub mod n3;
pub mod q1;
pub mod r2;
pub mod r2_gap;
pub mod r2_scan;
