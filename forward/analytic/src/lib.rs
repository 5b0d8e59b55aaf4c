//! # palpate-analytic
//!
//! Closed-form (homogeneous-deformation) forward models, and the
//! enrichments of C1 that change the model itself (`GAP.md`):
//!
//! * [`Homogeneous`] — uniaxial, equibiaxial and planar (pure-shear) nominal
//!   stress of any incompressible law, driven by the principal stretch.
//! * [`GeneralBiaxial`] — both in-plane stretches and both nominal stresses
//!   of a sheet (Kawabata's general biaxial tests).
//! * [`SimpleShear`] — nominal shear stress against the amount of shear,
//!   optionally superposed on an axial stretch (Budday's brain tests).
//! * [`ViscousUniaxial`] — finite-strain viscoelastic uniaxial tension and
//!   compression (Prony series on the isochoric second Piola stress).
//! * [`C1Compression`] — benchmark C1 (38 x 9 mm cylinder between lubricated
//!   platens): homogeneous uniaxial compression, force against platen travel.
//! * [`Compressible`] — C1 with a finite bulk modulus (`compressibility`),
//!   zero ("off") at D1 = 0.
//!
//! The enrichments that wrap any model (zero offset, tool compliance,
//! quasi-linear viscoelasticity, the richer law) live in `palpate-enrich`.
//! Every model implements palpate-core's [`ForwardModel`](palpate_core::ForwardModel)
//! and [`Enrichable`](palpate_core::Enrichable).
//!
//! ```
//! use palpate_analytic::C1Compression;
//! use palpate_core::{Drive, ForwardModel, Loading};
//! use palpate_material::Law;
//!
//! // C1 of a neo-Hookean with C10 = 0.03 MPa: F = -2 C10 (l - l^-2) A, l = 1 - d / 9 mm.
//! let model = C1Compression::new(Law::NeoHookean);
//! let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.9]);
//! let force = model.predict(&[0.03], &loading)?;
//! let l: f64 = 0.9;
//! let area = std::f64::consts::PI * 0.25 * 38.0 * 38.0;
//! assert_eq!(force[0], 0.0);
//! assert!((force[1] - (-2.0 * 0.03 * (l - l.powi(-2)) * area)).abs() < 1e-9 * force[1].abs());
//! // A parameter outside its bounds is an error, not a clamp.
//! assert!(model.predict(&[-1.0], &loading).is_err());
//! # Ok::<(), palpate_core::ForwardError>(())
//! ```

mod c1;
mod compressible;
mod convert;
mod general_biaxial;
mod homogeneous;
mod mode;
mod simple_shear;
mod viscous_uniaxial;

pub use c1::{c1_area_mm2, C1Compression, C1Geometry};
pub use compressible::{lateral_stress_free, Compressible};
pub use general_biaxial::GeneralBiaxial;
pub use homogeneous::Homogeneous;
pub use mode::Mode;
pub use simple_shear::SimpleShear;
pub use viscous_uniaxial::ViscousUniaxial;
