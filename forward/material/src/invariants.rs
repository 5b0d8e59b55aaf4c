//! Energies written in the invariants `I1`, `I2` and their conversion to principal-stretch derivatives.
//!
//! With principal stretches `l_a` (treated as independent):
//! `I1 = l1^2 + l2^2 + l3^2`, `I2 = l1^2 l2^2 + l2^2 l3^2 + l3^2 l1^2`,
//! `dI1/dl_a = 2 l_a`, `d2I1/dl_a dl_b = 2 delta_ab`,
//! `dI2/dl_a = 2 l_a (I1 - l_a^2)`, `d2I2/dl_a dl_b = 4 l_a l_b (a != b)`, `2 (I1 - l_a^2) (a == b)`,
//! and the chain rule `W_a = W_1 I1_a + W_2 I2_a`,
//! `W_ab = W_11 I1_a I1_b + W_12 (I1_a I2_b + I2_a I1_b) + W_22 I2_a I2_b + W_1 I1_ab + W_2 I2_ab`
//! (Holzapfel, *Nonlinear Solid Mechanics*, 2000, sec. 6.4).

use serde::{Deserialize, Serialize};

use crate::PrincipalDerivs;

/// Energy `W(I1, I2)` and its first and second derivatives with respect to the invariants.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct InvariantDerivs {
    /// `W`.
    pub w: f64,
    /// `dW/dI1`.
    pub w1: f64,
    /// `dW/dI2`.
    pub w2: f64,
    /// `d2W/dI1^2`.
    pub w11: f64,
    /// `d2W/dI1 dI2`.
    pub w12: f64,
    /// `d2W/dI2^2`.
    pub w22: f64,
}

/// `(I1, I2)` of the principal stretches `lam`.
pub fn invariants(lam: [f64; 3]) -> (f64, f64) {
    let x = lam.map(|l| l * l);
    (x[0] + x[1] + x[2], x[0] * x[1] + x[1] * x[2] + x[2] * x[0])
}

impl InvariantDerivs {
    /// Derivatives with respect to the principal stretches `lam` (chain rule in the module doc).
    pub fn to_principal(&self, lam: [f64; 3]) -> PrincipalDerivs {
        let (i1, _) = invariants(lam);
        let mut d_i1 = [0.0; 3];
        let mut d_i2 = [0.0; 3];
        for a in 0..3 {
            d_i1[a] = 2.0 * lam[a];
            d_i2[a] = 2.0 * lam[a] * (i1 - lam[a] * lam[a]);
        }
        let mut dw = [0.0; 3];
        let mut d2w = [[0.0; 3]; 3];
        for a in 0..3 {
            dw[a] = self.w1 * d_i1[a] + self.w2 * d_i2[a];
            for b in 0..3 {
                let (d2_i1, d2_i2) = if a == b {
                    (2.0, 2.0 * (i1 - lam[a] * lam[a]))
                } else {
                    (0.0, 4.0 * lam[a] * lam[b])
                };
                d2w[a][b] = self.w11 * d_i1[a] * d_i1[b]
                    + self.w12 * (d_i1[a] * d_i2[b] + d_i2[a] * d_i1[b])
                    + self.w22 * d_i2[a] * d_i2[b]
                    + self.w1 * d2_i1
                    + self.w2 * d2_i2;
            }
        }
        PrincipalDerivs { w: self.w, dw, d2w }
    }
}
