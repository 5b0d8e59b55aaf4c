//! Stress and tangent of `Psi(F) = W(I1b, I2b) + U(J)` directly from the invariants, without an
//! eigen-decomposition: the fast path of [`crate::Law::stress_tangent`] for the laws written in
//! invariants (neo-Hookean, Mooney-Rivlin, reduced polynomial, Arruda-Boyce).
//!
//! With `C = F^T F`, `b = F F^T`, `I1 = tr C`, `I2 = (I1^2 - C:C) / 2`, `J = det F` and the
//! modified invariants `Ib = J^{-k} I` (`k = 2/3` for `I1`, `4/3` for `I2`), (Holzapfel,
//! *Nonlinear Solid Mechanics*, 2000, sec. 6.4-6.6, written for `F` instead of `C`):
//!
//! * `dI1/dF = 2 F`, `dI2/dF = 2 (I1 F - F C)`, `dJ/dF = J F^-T`, `dF^-1_Ji/dF_kL = -F^-1_Jk F^-1_Li`;
//! * `dIb/dF = J^{-k} (dI/dF - k I F^-T)`;
//! * `d2Ib/dF_iJ dF_kL = J^{-k} [d2I - k (dI (x) F^-T + F^-T (x) dI) + k^2 I F^-T (x) F^-T
//!   + k I F^-1_Jk F^-1_Li]`;
//! * `d2I1 = 2 d_ik d_JL`,
//!   `d2I2 = 4 F_iJ F_kL + 2 I1 d_ik d_JL - 2 d_ik C_LJ - 2 F_iL F_kJ - 2 b_ik d_JL`;
//! * `P = W1 dI1b + W2 dI2b + U' J F^-T`,
//!   `A = W11 dI1b (x) dI1b + W12 (dI1b (x) dI2b + dI2b (x) dI1b) + W22 dI2b (x) dI2b
//!   + W1 d2I1b + W2 d2I2b + (U'' J^2 + U' J) F^-T (x) F^-T - U' J F^-1_Jk F^-1_Li`.

use nalgebra::{Matrix3, SMatrix};

use crate::{InvariantDerivs, StressTangent, Volumetric};

/// Stress and tangent of `W(I1b, I2b) + U(J)` for an energy given by `inv(I1b, I2b)` (module doc).
/// NaN entries when `det F <= 0` or `F` is not finite.
pub fn stress_tangent(
    inv: impl Fn(f64, f64) -> InvariantDerivs,
    vol: Volumetric,
    f: &Matrix3<f64>,
) -> StressTangent {
    let j = f.determinant();
    if !(j > 0.0 && j.is_finite()) {
        return StressTangent::nan();
    }
    let Some(finv) = f.try_inverse() else {
        return StressTangent::nan();
    };
    let fit = finv.transpose();
    let c = f.transpose() * f;
    let b = f * f.transpose();
    let i1 = c.trace();
    let i2 = 0.5 * (i1 * i1 - c.norm_squared());
    let (k1, k2) = (2.0 / 3.0, 4.0 / 3.0);
    let (a1, a2) = (j.powf(-k1), j.powf(-k2));
    let d = inv(a1 * i1, a2 * i2);

    let di1 = f * 2.0;
    let di2 = (f * i1 - f * c) * 2.0;
    let g1 = (di1 - fit * (k1 * i1)) * a1;
    let g2 = (di2 - fit * (k2 * i2)) * a2;
    let (du, d2u) = (vol.du(j), vol.d2u(j));
    let p = g1 * d.w1 + g2 * d.w2 + fit * (du * j);

    let delta = |x: usize, y: usize| if x == y { 1.0 } else { 0.0 };
    let kvol = d2u * j * j + du * j;
    let mut a = SMatrix::<f64, 9, 9>::zeros();
    for i in 0..3 {
        for jj in 0..3 {
            let r = 3 * i + jj;
            // A is symmetric (A_iJkL = A_kLiJ, every term above is): fill the upper triangle, mirror.
            for s in r..9 {
                let (k, l) = (s / 3, s % 3);
                {
                    let cross = finv[(jj, k)] * finv[(l, i)];
                    let ff = fit[(i, jj)] * fit[(k, l)];
                    let d2i1 = 2.0 * delta(i, k) * delta(jj, l);
                    let d2i2 = 4.0 * f[(i, jj)] * f[(k, l)] + 2.0 * i1 * delta(i, k) * delta(jj, l)
                        - 2.0 * delta(i, k) * c[(l, jj)]
                        - 2.0 * f[(i, l)] * f[(k, jj)]
                        - 2.0 * b[(i, k)] * delta(jj, l);
                    let h1 = a1
                        * (d2i1 - k1 * (di1[(i, jj)] * fit[(k, l)] + fit[(i, jj)] * di1[(k, l)])
                            + k1 * k1 * i1 * ff
                            + k1 * i1 * cross);
                    let h2 = a2
                        * (d2i2 - k2 * (di2[(i, jj)] * fit[(k, l)] + fit[(i, jj)] * di2[(k, l)])
                            + k2 * k2 * i2 * ff
                            + k2 * i2 * cross);
                    a[(r, s)] = d.w11 * g1[(i, jj)] * g1[(k, l)]
                        + d.w12 * (g1[(i, jj)] * g2[(k, l)] + g2[(i, jj)] * g1[(k, l)])
                        + d.w22 * g2[(i, jj)] * g2[(k, l)]
                        + d.w1 * h1
                        + d.w2 * h2
                        + kvol * ff
                        - du * j * cross;
                    a[(s, r)] = a[(r, s)];
                }
            }
        }
    }
    StressTangent {
        psi: d.w + vol.u(j),
        p,
        a,
    }
}
