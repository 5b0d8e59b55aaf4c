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

/// `F`, its inverse, `C`, `b`, the invariants and the derivatives of the
/// modified invariants `dIb/dF` (module doc), computed once per point and
/// shared by the stress, the tangent entries and (in palpate-fe) the 2D
/// element's five-component restriction.
#[derive(Debug, Clone, PartialEq)]
pub struct InvariantKinematics {
    pub j: f64,
    pub f: Matrix3<f64>,
    pub finv: Matrix3<f64>,
    /// `F^-T`.
    pub fit: Matrix3<f64>,
    pub c: Matrix3<f64>,
    pub b: Matrix3<f64>,
    pub i1: f64,
    pub i2: f64,
    /// `J^{-2/3}`, `J^{-4/3}`.
    pub a1: f64,
    pub a2: f64,
    /// `dI1/dF`, `dI2/dF`.
    pub di1: Matrix3<f64>,
    pub di2: Matrix3<f64>,
    /// `dI1b/dF`, `dI2b/dF`.
    pub g1: Matrix3<f64>,
    pub g2: Matrix3<f64>,
}

const K1: f64 = 2.0 / 3.0;
const K2: f64 = 4.0 / 3.0;

impl InvariantKinematics {
    /// `None` when `det F <= 0` or `F` is not finite or not invertible.
    pub fn new(f: &Matrix3<f64>) -> Option<Self> {
        let j = f.determinant();
        if !(j > 0.0 && j.is_finite()) {
            return None;
        }
        let finv = f.try_inverse()?;
        let fit = finv.transpose();
        let c = f.transpose() * f;
        let b = f * f.transpose();
        let i1 = c.trace();
        let i2 = 0.5 * (i1 * i1 - c.norm_squared());
        let (a1, a2) = (j.powf(-K1), j.powf(-K2));
        let di1 = f * 2.0;
        let di2 = (f * i1 - f * c) * 2.0;
        let g1 = (di1 - fit * (K1 * i1)) * a1;
        let g2 = (di2 - fit * (K2 * i2)) * a2;
        Some(InvariantKinematics {
            j,
            f: *f,
            finv,
            fit,
            c,
            b,
            i1,
            i2,
            a1,
            a2,
            di1,
            di2,
            g1,
            g2,
        })
    }

    /// `(I1b, I2b)`.
    pub fn modified(&self) -> (f64, f64) {
        (self.a1 * self.i1, self.a2 * self.i2)
    }

    /// Isochoric first Piola stress `W1 dI1b/dF + W2 dI2b/dF`.
    pub fn iso_stress(&self, d: &InvariantDerivs) -> Matrix3<f64> {
        self.g1 * d.w1 + self.g2 * d.w2
    }

    /// `F^-1_Jk F^-1_Li` (the derivative of `F^-T_iJ` with respect to
    /// `F_kL`, up to sign).
    pub fn cross(&self, i: usize, jj: usize, k: usize, l: usize) -> f64 {
        self.finv[(jj, k)] * self.finv[(l, i)]
    }

    /// Isochoric tangent entry `A_iJkL` (module doc, without the `U` terms).
    pub fn iso_tangent(&self, d: &InvariantDerivs, i: usize, jj: usize, k: usize, l: usize) -> f64 {
        let (f, fit, c, b) = (&self.f, &self.fit, &self.c, &self.b);
        let (di1, di2, g1, g2) = (&self.di1, &self.di2, &self.g1, &self.g2);
        let (i1, i2) = (self.i1, self.i2);
        let delta = |x: usize, y: usize| if x == y { 1.0 } else { 0.0 };
        let cross = self.cross(i, jj, k, l);
        let ff = fit[(i, jj)] * fit[(k, l)];
        let d2i1 = 2.0 * delta(i, k) * delta(jj, l);
        let d2i2 = 4.0 * f[(i, jj)] * f[(k, l)] + 2.0 * i1 * delta(i, k) * delta(jj, l)
            - 2.0 * delta(i, k) * c[(l, jj)]
            - 2.0 * f[(i, l)] * f[(k, jj)]
            - 2.0 * b[(i, k)] * delta(jj, l);
        let h1 = self.a1
            * (d2i1 - K1 * (di1[(i, jj)] * fit[(k, l)] + fit[(i, jj)] * di1[(k, l)])
                + K1 * K1 * i1 * ff
                + K1 * i1 * cross);
        let h2 = self.a2
            * (d2i2 - K2 * (di2[(i, jj)] * fit[(k, l)] + fit[(i, jj)] * di2[(k, l)])
                + K2 * K2 * i2 * ff
                + K2 * i2 * cross);
        d.w11 * g1[(i, jj)] * g1[(k, l)]
            + d.w12 * (g1[(i, jj)] * g2[(k, l)] + g2[(i, jj)] * g1[(k, l)])
            + d.w22 * g2[(i, jj)] * g2[(k, l)]
            + d.w1 * h1
            + d.w2 * h2
    }
}

/// Stress and tangent of `W(I1b, I2b) + U(J)` for an energy given by `inv(I1b, I2b)` (module doc).
/// NaN entries when `det F <= 0` or `F` is not finite.
pub fn stress_tangent(
    inv: impl Fn(f64, f64) -> InvariantDerivs,
    vol: Volumetric,
    f: &Matrix3<f64>,
) -> StressTangent {
    let Some(kin) = InvariantKinematics::new(f) else {
        return StressTangent::nan();
    };
    let (i1b, i2b) = kin.modified();
    let d = inv(i1b, i2b);
    let j = kin.j;
    let (du, d2u) = (vol.du(j), vol.d2u(j));
    let p = kin.iso_stress(&d) + kin.fit * (du * j);
    let kvol = d2u * j * j + du * j;
    let mut a = SMatrix::<f64, 9, 9>::zeros();
    // A is symmetric (A_iJkL = A_kLiJ, every term is): fill the upper triangle, mirror.
    for r in 0..9 {
        let (i, jj) = (r / 3, r % 3);
        for s in r..9 {
            let (k, l) = (s / 3, s % 3);
            a[(r, s)] = kin.iso_tangent(&d, i, jj, k, l)
                + kvol * kin.fit[(i, jj)] * kin.fit[(k, l)]
                - du * j * kin.cross(i, jj, k, l);
            a[(s, r)] = a[(r, s)];
        }
    }
    StressTangent {
        psi: d.w + vol.u(j),
        p,
        a,
    }
}
