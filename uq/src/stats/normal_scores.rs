//! Normal scores (expected normal order statistics) by Blom's approximation.

use statrs::distribution::{ContinuousCDF, Normal};

/// Blom's normal scores of a sample of size `n`, in increasing order:
///
/// `b_i = Phi^{-1}((i - 3/8) / (n + 1/4))`, i = 1..n
///
/// (Blom 1958, *Statistical estimates and transformed beta-variables*; the
/// scores Minitab's Ryan-Joiner test and normal probability plots use).
pub fn blom_scores(n: usize) -> Vec<f64> {
    let z = Normal::standard();
    let nf = n as f64;
    (1..=n)
        .map(|i| z.inverse_cdf((i as f64 - 0.375) / (nf + 0.25)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_are_antisymmetric_and_match_the_formula() {
        let b = blom_scores(5);
        // Phi^{-1}((1 - 0.375)/5.25) = Phi^{-1}(0.119047...) = -1.17976...
        assert!((b[0] + 1.179761).abs() < 1e-5, "{b:?}");
        assert!(b[2].abs() < 1e-14);
        for i in 0..5 {
            assert!((b[i] + b[4 - i]).abs() < 1e-12);
        }
    }
}
