//! # palpate-analytic
//!
//! Closed-form (homogeneous-deformation) forward models and the enrichments
//! that the sim-to-real gap diagnosis switches on (`GAP.md`):
//!
//! * [`Homogeneous`] — uniaxial, equibiaxial and planar (pure-shear) nominal
//!   stress of any incompressible law, driven by the principal stretch.
//! * [`C1Compression`] — benchmark C1 (38 x 9 mm cylinder between lubricated
//!   platens): homogeneous uniaxial compression, force against platen travel.
//! * [`Viscoelastic`] — quasi-linear viscoelasticity (Fung) with a Prony
//!   series wrapped around any model, by the exact recursive convolution.
//! * [`ZeroOffset`], [`ToolCompliance`], [`Compressible`] and
//!   [`MaterialForm`] — the other enrichments of C1, each zero ("off") at a
//!   reachable parameter value, so a score test can differentiate there.
//!
//! Every model implements palpate-core's [`ForwardModel`](palpate_core::ForwardModel)
//! and declares the effects it can be enriched with.

mod c1;
mod compressible;
mod convert;
mod homogeneous;
mod material_form;
mod mode;
mod tool_compliance;
mod viscoelastic;
mod wrap;
mod zero_offset;

pub use c1::{c1_area_mm2, C1Compression, C1Geometry};
pub use compressible::{lateral_stress_free, Compressible};
pub use homogeneous::Homogeneous;
pub use material_form::{richer_law, MaterialForm, RicherLaw};
pub use mode::Mode;
pub use tool_compliance::ToolCompliance;
pub use viscoelastic::{qlv_convolve, Viscoelastic};
pub use zero_offset::ZeroOffset;
