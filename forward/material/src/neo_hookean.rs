//! Neo-Hookean law.
//!
//! `W = C10 (I1b - 3)` (Abaqus Theory Manual, "Hyperelastic material behavior"; Treloar 1943),
//! initial shear modulus `mu0 = 2 C10`.

use crate::InvariantDerivs;

/// Energy and invariant derivatives of `W = C10 (I1 - 3)`.
pub fn invariant_derivs(c10: f64, i1: f64) -> InvariantDerivs {
    InvariantDerivs {
        w: c10 * (i1 - 3.0),
        w1: c10,
        ..InvariantDerivs::default()
    }
}
