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

use crate::stability::Mode;
use crate::{Law, MaterialError, Volumetric};

fn nominal(law: &Law, p: &[f64], lam: [f64; 3], free: usize) -> f64 {
    if !(lam[0] > 0.0 && lam[0].is_finite()) {
        return f64::NAN;
    }
    // Laws written in invariants: sigma_a - sigma_b = 2 (l_a^2 - l_b^2)(W1 + l_c^2 W2) for an
    // incompressible principal state (c the third direction), from
    // l_i dW/dl_i = 2 W1 l_i^2 + 2 W2 (l_i^2 I1 - l_i^4) with I2 = (I1^2 - sum l^4)/2.
    // Only first derivatives are needed, so the principal Hessian is not built (this path is
    // the whole cost of the analytic forward models). Ogden keeps the principal path.
    if p.len() == law.param_count() {
        let (i1, i2) = crate::invariants::invariants(lam);
        if let Some(d) = law.invariant_derivs(p, i1, i2) {
            let third = 3 - free;
            return 2.0
                * (lam[0] * lam[0] - lam[free] * lam[free])
                * (d.w1 + lam[third] * lam[third] * d.w2)
                / lam[0];
        }
    }
    let d = law.isochoric_principal(p, lam);
    (lam[0] * d.dw[0] - lam[free] * d.dw[free]) / lam[0]
}

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

/// The nominal stress of `mode` (uniaxial, equibiaxial or planar) at `stretch`, with every
/// input checked: the stretch, the parameters ([`Law::check`]) and the law's domain at the
/// mode's stretches ([`Law::check_stretches`]: Gent's limit `I1 - 3 < Jm`, an exponential that
/// overflows). The `f64` functions above give NaN or infinity there instead of an error.
pub fn checked(law: &Law, p: &[f64], mode: Mode, stretch: f64) -> Result<f64, MaterialError> {
    if !(stretch > 0.0 && stretch.is_finite()) {
        return Err(MaterialError::BadStretch { stretch });
    }
    law.check(p)?;
    law.check_stretches(p, mode.stretches(stretch))?;
    let stress = match mode {
        Mode::Uniaxial => uniaxial(law, p, stretch),
        Mode::Biaxial => equibiaxial(law, p, stretch),
        Mode::Planar => planar(law, p, stretch),
    };
    if stress.is_finite() {
        Ok(stress)
    } else {
        Err(MaterialError::OutsideDomain {
            law: law.to_string(),
            stretches: mode.stretches(stretch),
            reason: format!("the {mode:?} stress is not finite"),
        })
    }
}

/// Maximum safeguarded-Newton iterations of [`uniaxial_compressible`].
const MAX_NEWTON: usize = 200;
/// Maximum doublings/halvings of the lateral stretch while bracketing the root.
const MAX_BRACKET: usize = 60;

/// Uniaxial stress of the compressible material `Psi = W(J^{-1/3} F) + U(J)`:
/// `F = diag(s, t, t)` with the lateral stretch `t` solved from `P_22(t) = 0`.
///
/// Solver: the root is first bracketed, starting at the incompressible `t = s^-1/2` and
/// halving/doubling `t` (`P_22 -> -inf` as `t -> 0` for the laws here, `P_22 > 0` for large `t`),
/// then Newton steps (`dP_22/dt = A_2222 + A_2233` from [`Law::stress_tangent`]) are taken inside
/// the bracket, falling back to bisection whenever a step would leave it (`rtsafe`, Press et al.,
/// *Numerical Recipes*, 3rd ed., sec. 9.4; hand-written because it is 30 lines on a scalar).
///
/// The bracket grows outwards from `s^-1/2`, so the root found is the nearest one on the side the
/// residual points to. With a small bulk modulus and strong compression `U = (J - 1)^2 / D1`
/// (bounded as `J -> 0`) allows a near-collapse root (`t ~ s`, e.g. neo-Hookean with `K = 3 mu0`
/// at `s = 0.1`): that is the law's answer, not a solver artefact.
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
    let state =
        |t: f64| law.stress_tangent(p, vol, &Matrix3::from_diagonal(&[stretch, t, t].into()));
    let lateral = |t: f64| state(t).p[(1, 1)];
    let fail = |what: &str, iterations: usize, residual: f64| MaterialError::NoConvergence {
        what: format!("{what} the uniaxial lateral stretch of {law} at stretch {stretch}"),
        iterations,
        residual,
    };

    // Bracket: lo with P22 < 0, hi with P22 > 0.
    let t0 = 1.0 / stretch.sqrt();
    let r0 = lateral(t0);
    if r0 == 0.0 {
        return Ok((state(t0).p[(0, 0)], t0));
    }
    let (mut lo, mut hi) = (t0, t0);
    let mut found = false;
    for _ in 0..MAX_BRACKET {
        if r0 > 0.0 {
            lo *= 0.5;
            if lateral(lo) < 0.0 {
                found = true;
                break;
            }
            hi = lo;
        } else {
            hi *= 2.0;
            if lateral(hi) > 0.0 {
                found = true;
                break;
            }
            lo = hi;
        }
    }
    if !found {
        return Err(fail(
            "no sign change of P22 found (no lateral-stress-free state?) bracketing",
            MAX_BRACKET,
            r0,
        ));
    }

    let scale = law.shear_modulus(p).abs().max(f64::MIN_POSITIVE);
    let mut t = 0.5 * (lo + hi);
    let mut residual = f64::NAN;
    for _ in 0..MAX_NEWTON {
        let st = state(t);
        residual = st.p[(1, 1)];
        if residual.abs() <= 1e-12 * scale || (hi - lo) <= 1e-15 * t {
            return Ok((st.p[(0, 0)], t));
        }
        if residual < 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let newton = t - residual / (st.a[(4, 4)] + st.a[(4, 8)]);
        t = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
    }
    Err(fail("safeguarded Newton on", MAX_NEWTON, residual))
}
