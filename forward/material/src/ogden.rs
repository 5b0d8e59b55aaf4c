//! Ogden law in principal stretches.
//!
//! `W = sum_{i=1..N} 2 mu_i / alpha_i^2 (l1^a_i + l2^a_i + l3^a_i - 3)` (Ogden 1972, in the
//! Abaqus convention of the Abaqus Theory Manual, "Hyperelastic material behavior"), so
//! `dW/dl_a = sum_i 2 mu_i / alpha_i l_a^(a_i - 1)`,
//! `d2W/dl_a^2 = sum_i 2 mu_i (a_i - 1) / a_i l_a^(a_i - 2)` and no mixed terms;
//! initial shear modulus `mu0 = sum mu_i`.

use crate::PrincipalDerivs;

/// Energy and principal derivatives for the terms `terms = [mu1, alpha1, mu2, alpha2, ...]`.
pub fn principal_derivs(terms: &[f64], lam: [f64; 3]) -> PrincipalDerivs {
    let mut d = PrincipalDerivs::default();
    for pair in terms.chunks_exact(2) {
        let (mu, alpha) = (pair[0], pair[1]);
        let c = 2.0 * mu / (alpha * alpha);
        let mut sum = -3.0;
        for (a, &l) in lam.iter().enumerate() {
            let la = l.powf(alpha);
            sum += la;
            d.dw[a] += c * alpha * la / l;
            d.d2w[a][a] += c * alpha * (alpha - 1.0) * la / (l * l);
        }
        d.w += c * sum;
    }
    d
}
