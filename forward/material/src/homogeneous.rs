//! Homogeneous deformations in principal stretches: nominal (first Piola) stress along the loading
//! direction, in MPa.
//!
//! Incompressible (`l1 l2 l3 = 1`): the Cauchy stresses are `sigma_a = l_a dW/dl_a - p`, the
//! pressure `p` fixed by a stress-free direction `f`, so the nominal stress along 1 is
//! `P_1 = (l_1 W_1 - l_f W_f) / l_1` (Holzapfel 2000, sec. 7.1; Ogden 1984, sec. 7.2).
//! E.g. neo-Hookean uniaxial: `P = 2 C10 (l - l^-2)`; Ogden uniaxial:
//! `P = sum 2 mu_i / alpha_i (l^(a_i - 1) - l^(-a_i/2 - 1))`.
//!
//! A stretch that is not a positive finite number gives NaN (the `f64` functions) or
//! [`MaterialError::BadStretch`].

use nalgebra::Matrix3;

use crate::{Law, MaterialError, Volumetric};

fn nominal(law: &Law, p: &[f64], lam: [f64; 3], free: usize) -> f64 {
    if !(lam[0] > 0.0 && lam[0].is_finite()) {
        return f64::NAN;
    }
    let d = law.isochoric_principal(p, lam);
    (lam[0] * d.dw[0] - lam[free] * d.dw[free]) / lam[0]
}

/// Uniaxial tension/compression: `l1 = s`, `l2 = l3 = s^-1/2`, lateral stress free.
pub fn uniaxial(law: &Law, p: &[f64], stretch: f64) -> f64 {
    let t = 1.0 / stretch.sqrt();
    nominal(law, p, [stretch, t, t], 2)
}

/// Equibiaxial tension: `l1 = l2 = s`, `l3 = s^-2`, thickness stress free.
pub fn equibiaxial(law: &Law, p: &[f64], stretch: f64) -> f64 {
    nominal(law, p, [stretch, stretch, 1.0 / (stretch * stretch)], 2)
}

/// Planar tension (pure shear): `l1 = s`, `l2 = 1`, `l3 = 1/s`, thickness stress free.
pub fn planar(law: &Law, p: &[f64], stretch: f64) -> f64 {
    nominal(law, p, [stretch, 1.0, 1.0 / stretch], 2)
}

/// Maximum Newton iterations of [`uniaxial_compressible`].
const MAX_NEWTON: usize = 60;

/// Uniaxial stress of the compressible material `Psi = W(J^{-1/3} F) + U(J)`:
/// `F = diag(s, t, t)` with the lateral stretch `t` solved from `P_22(t) = 0` by damped Newton
/// (`dP_22/dt = A_2222 + A_2233`, from [`Law::stress_tangent`]), started at `t = s^-1/2`.
///
/// Returns `(P_11, t)`. With [`Volumetric::Incompressible`] it returns the incompressible limit
/// `(uniaxial(s), s^-1/2)` (an isochoric energy alone has no lateral-stress-free state other than a
/// pure dilation).
pub fn uniaxial_compressible(
    law: &Law,
    p: &[f64],
    vol: Volumetric,
    stretch: f64,
) -> Result<(f64, f64), MaterialError> {
    if !(stretch > 0.0 && stretch.is_finite()) {
        return Err(MaterialError::BadStretch { stretch });
    }
    law.check(p)?;
    vol.check()?;
    if vol == Volumetric::Incompressible {
        return Ok((uniaxial(law, p, stretch), 1.0 / stretch.sqrt()));
    }
    let scale = law.shear_modulus(p).abs().max(f64::MIN_POSITIVE);
    let mut t = 1.0 / stretch.sqrt();
    let mut residual = f64::INFINITY;
    for _ in 0..MAX_NEWTON {
        let st = law.stress_tangent(p, vol, &Matrix3::from_diagonal(&[stretch, t, t].into()));
        residual = st.p[(1, 1)];
        if residual.abs() <= 1e-12 * scale {
            return Ok((st.p[(0, 0)], t));
        }
        let slope = st.a[(4, 4)] + st.a[(4, 8)];
        let mut step = -residual / slope;
        if !step.is_finite() {
            break;
        }
        // Keep the stretch positive: never move more than half way to zero.
        if t + step <= 0.5 * t {
            step = -0.5 * t;
        }
        t += step;
        if step.abs() <= 1e-15 * t {
            let st = law.stress_tangent(p, vol, &Matrix3::from_diagonal(&[stretch, t, t].into()));
            return Ok((st.p[(0, 0)], t));
        }
    }
    Err(MaterialError::NoConvergence {
        what: format!("uniaxial lateral stretch of {law} at stretch {stretch}"),
        iterations: MAX_NEWTON,
        residual,
    })
}
