//! Mooney-Rivlin law.
//!
//! `W = C10 (I1b - 3) + C01 (I2b - 3)` (Mooney 1940, Rivlin 1948; Abaqus Theory Manual,
//! "Hyperelastic material behavior"), initial shear modulus `mu0 = 2 (C10 + C01)`.

use crate::InvariantDerivs;

/// Energy and invariant derivatives of `W = C10 (I1 - 3) + C01 (I2 - 3)`.
pub fn invariant_derivs(c10: f64, c01: f64, i1: f64, i2: f64) -> InvariantDerivs {
    InvariantDerivs {
        w: c10 * (i1 - 3.0) + c01 * (i2 - 3.0),
        w1: c10,
        w2: c01,
        ..InvariantDerivs::default()
    }
}
