//! Humphrey (exponential in `I1`) law.
//!
//! `W = C1 (exp(C2 (I1b - 3)) - 1)` (Humphrey & Yin, Biophys. J. 52 (1987) 563, the isotropic
//! term of their myocardium law; the "Humphrey" model of the phantom database of Dawood et al.
//! 2026, whose parameters `[C1, C2]` (C1 in kPa) are this form: it reproduces the database's
//! fitted curves and SSE, see `docs/validation/laws/README.md`), with `C1 > 0` (MPa) and
//! `C2 > 0`. `dW/dI1 = C1 C2 exp(C2 (I1b - 3))`, `d2W/dI1^2 = C2 dW/dI1`; initial shear modulus
//! `mu0 = 2 C1 C2`.

use crate::InvariantDerivs;

/// Energy and invariant derivatives of `W = C1 (exp(C2 (I1 - 3)) - 1)`.
pub fn invariant_derivs(c1: f64, c2: f64, i1: f64) -> InvariantDerivs {
    let z = c2 * (i1 - 3.0);
    let w1 = c1 * c2 * z.exp();
    InvariantDerivs {
        // exp_m1 keeps W accurate near the reference state.
        w: c1 * z.exp_m1(),
        w1,
        w11: c2 * w1,
        ..InvariantDerivs::default()
    }
}
