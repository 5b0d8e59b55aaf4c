//! Veronda-Westmann law.
//!
//! `W = C1 (exp(C2 (I1b - 3)) - 1) - (C1 C2 / 2) (I2b - 3)` (Veronda & Westmann, J. Biomech. 3
//! (1970) 111, as written in FEBio's "Veronda-Westmann" material and used by the phantom database
//! of Dawood et al. 2026, whose parameters `[C1, C2]` (C1 in kPa) are this form: it reproduces the
//! database's fitted curves and SSE, see `docs/validation/laws/README.md`), with `C1 > 0` (MPa)
//! and `C2 > 0`. `dW/dI1 = C1 C2 exp(C2 (I1b - 3))`, `dW/dI2 = -C1 C2 / 2`,
//! `d2W/dI1^2 = C2 dW/dI1`; initial shear modulus `mu0 = 2 (W1 + W2) = C1 C2`.
//!
//! The negative `I2` term makes the law Mooney-Rivlin-like with `C01 = -C10 / 2` at small strain,
//! so it is not Drucker stable in every mode: see [`crate::stability::drucker`].

use crate::InvariantDerivs;

/// Energy and invariant derivatives of the Veronda-Westmann law.
pub fn invariant_derivs(c1: f64, c2: f64, i1: f64, i2: f64) -> InvariantDerivs {
    let z = c2 * (i1 - 3.0);
    let w1 = c1 * c2 * z.exp();
    InvariantDerivs {
        w: c1 * z.exp_m1() - 0.5 * c1 * c2 * (i2 - 3.0),
        w1,
        w2: -0.5 * c1 * c2,
        w11: c2 * w1,
        ..InvariantDerivs::default()
    }
}
