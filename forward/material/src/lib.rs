//! # palpate-material
//!
//! Pointwise isotropic hyperelastic laws, knowing no element (STYLE.md, point 4):
//!
//! * [`Law`] — neo-Hookean, Mooney-Rivlin, reduced polynomial (Yeoh), Arruda-Boyce (5-term
//!   series), Ogden, Gent, Veronda-Westmann, Humphrey; parsing, parameters with bounds ([`MaterialParam`]), checks, initial shear modulus.
//! * [`Law::isochoric_principal`] — `W` and its first and second derivatives in the principal
//!   stretches; [`Law::stress_tangent`] — energy, first Piola stress and `dP/dF` of
//!   `W(J^{-1/3} F) + U(J)` for finite elements ([`kinematics`]).
//! * [`Volumetric`] — `U = (J - 1)^2 / D1` or incompressible.
//! * [`homogeneous`] — closed-form nominal stresses of the classical modes.
//! * [`stability`] — Drucker stability ranges.
//!
//! Units: MPa for moduli and stresses, stretches dimensionless. Conventions follow the Abaqus
//! Theory Manual ("Hyperelastic material behavior").

pub mod arruda_boyce;
pub mod error;
pub mod gent;
pub mod homogeneous;
pub mod humphrey;
pub mod invariant_kinematics;
pub mod invariants;
pub mod kinematics;
pub mod law;
pub mod mooney_rivlin;
pub mod neo_hookean;
pub mod ogden;
pub mod reduced_polynomial;
pub mod stability;
pub mod veronda_westmann;
pub mod volumetric;

pub use error::MaterialError;
pub use invariants::InvariantDerivs;
pub use kinematics::{PrincipalDerivs, StressTangent};
pub use law::{Law, MaterialParam, EXPONENT_BOUND, GENT_JM_BOUND, OGDEN_ALPHA_BOUND};
pub use volumetric::Volumetric;
