//! Gent law (limiting chain extensibility).
//!
//! `W = -(mu Jm / 2) ln(1 - (I1b - 3) / Jm)` (Gent, Rubber Chem. Technol. 69 (1996) 59-61;
//! the form of Horgan & Saccomandi, Math. Mech. Solids 7 (2002) 353, and of the Abaqus and FEBio
//! "Gent" materials), with `mu > 0` the initial shear modulus and `Jm > 0` the limiting value of
//! `I1b - 3`. With `x = I1b - 3` and `r = 1 - x / Jm`:
//! `dW/dI1 = mu / (2 r)`, `d2W/dI1^2 = mu / (2 Jm r^2)`; `Jm -> inf` is neo-Hookean with
//! `C10 = mu / 2`. Not in the phantom database (`hyperelastic_parameters.json`).
//!
//! The energy is defined only for `x < Jm` (it tends to `+inf` at the limit): beyond it every
//! derivative is NaN here, never the finite but meaningless values the formula gives past the
//! pole, and [`crate::Law::check_stretches`] names the limit.

use crate::InvariantDerivs;

/// Energy and invariant derivatives of the Gent law; all NaN when `I1 - 3 >= Jm`.
pub fn invariant_derivs(mu: f64, jm: f64, i1: f64) -> InvariantDerivs {
    let x = i1 - 3.0;
    let r = 1.0 - x / jm;
    if r.is_nan() || r <= 0.0 {
        return InvariantDerivs {
            w: f64::NAN,
            w1: f64::NAN,
            w2: f64::NAN,
            w11: f64::NAN,
            w12: f64::NAN,
            w22: f64::NAN,
        };
    }
    InvariantDerivs {
        // ln_1p keeps W accurate near the reference state (x -> 0).
        w: -0.5 * mu * jm * (-x / jm).ln_1p(),
        w1: 0.5 * mu / r,
        w11: 0.5 * mu / (jm * r * r),
        ..InvariantDerivs::default()
    }
}
