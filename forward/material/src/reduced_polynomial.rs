//! Reduced polynomial law (Yeoh for N = 3).
//!
//! `W = sum_{i=1..N} Ci0 (I1b - 3)^i` (Yeoh 1993; Abaqus Theory Manual, "Hyperelastic material
//! behavior"), so `dW/dI1 = sum i Ci0 (I1b - 3)^(i-1)`, `d2W/dI1^2 = sum i (i-1) Ci0 (I1b - 3)^(i-2)`,
//! initial shear modulus `mu0 = 2 C10`.

use crate::InvariantDerivs;

/// Energy and invariant derivatives of `W = sum_i c[i-1] (I1 - 3)^i`.
pub fn invariant_derivs(c: &[f64], i1: f64) -> InvariantDerivs {
    let x = i1 - 3.0;
    let mut d = InvariantDerivs::default();
    for (k, &ci) in c.iter().enumerate() {
        let i = (k + 1) as i32;
        d.w += ci * x.powi(i);
        d.w1 += f64::from(i) * ci * x.powi(i - 1);
        if i >= 2 {
            d.w11 += f64::from(i * (i - 1)) * ci * x.powi(i - 2);
        }
    }
    d
}
