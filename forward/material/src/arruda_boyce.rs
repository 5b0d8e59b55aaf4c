//! Arruda-Boyce (eight-chain) law, 5-term series form.
//!
//! `W = mu sum_{i=1..5} C_i / lambda_m^(2i-2) (I1b^i - 3^i)` with
//! `C = 1/2, 1/20, 11/1050, 19/7000, 519/673750` (Arruda & Boyce 1993, series of the inverse
//! Langevin function as in the Abaqus Theory Manual, "Hyperelastic material behavior"; see
//! `docs/benchmarks.md`). The initial shear modulus is
//! `mu0 = 2 dW/dI1 (I1 = 3) = mu (1 + 3/(5 lm^2) + 99/(175 lm^4) + 513/(875 lm^6) + 42039/(67375 lm^8))`.

use crate::InvariantDerivs;

/// The series coefficients `C_1..C_5`.
pub const SERIES: [f64; 5] = [
    0.5,
    1.0 / 20.0,
    11.0 / 1050.0,
    19.0 / 7000.0,
    519.0 / 673_750.0,
];

/// Energy and invariant derivatives of the 5-term Arruda-Boyce energy.
pub fn invariant_derivs(mu: f64, lambda_m: f64, i1: f64) -> InvariantDerivs {
    let beta = 1.0 / (lambda_m * lambda_m);
    let mut d = InvariantDerivs::default();
    for (k, &ci) in SERIES.iter().enumerate() {
        let i = (k + 1) as i32;
        let a = mu * ci * beta.powi(i - 1);
        d.w += a * (i1.powi(i) - 3f64.powi(i));
        d.w1 += a * f64::from(i) * i1.powi(i - 1);
        if i >= 2 {
            d.w11 += a * f64::from(i * (i - 1)) * i1.powi(i - 2);
        }
    }
    d
}

/// Initial shear modulus `mu0 = 2 dW/dI1` at `I1 = 3`.
pub fn initial_shear_modulus(mu: f64, lambda_m: f64) -> f64 {
    2.0 * invariant_derivs(mu, lambda_m, 3.0).w1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn initial_shear_modulus_matches_closed_form() {
        // Abaqus Theory Manual: mu0 = mu (1 + 3/(5 lm^2) + 99/(175 lm^4) + 513/(875 lm^6) + 42039/(67375 lm^8)).
        for lm in [1.01, 1.05, 3.0, 7.0] {
            let b: f64 = 1.0 / (lm * lm);
            let closed = 1.0
                + 3.0 / 5.0 * b
                + 99.0 / 175.0 * b.powi(2)
                + 513.0 / 875.0 * b.powi(3)
                + 42039.0 / 67375.0 * b.powi(4);
            let got = initial_shear_modulus(2.0, lm);
            assert!(
                (got - 2.0 * closed).abs() < 1e-12 * got,
                "{got} vs {}",
                2.0 * closed
            );
        }
    }
}
