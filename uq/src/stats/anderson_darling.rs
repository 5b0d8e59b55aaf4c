//! Anderson-Darling test of normality with estimated mean and variance.
//!
//! With `z_i = (Y_(i) - mean) / s` (ordered sample, `s` with divisor n - 1)
//! and `Phi` the standard normal CDF:
//!
//! `A^2 = -n - (1/n) sum_{i=1}^n (2i - 1) [ln Phi(z_i) + ln(1 - Phi(z_{n+1-i}))]`
//!
//! The small-sample adjustment and the p-value are those of D'Agostino &
//! Stephens (1986), *Goodness-of-Fit Techniques*, Table 4.9 (case 3, both
//! parameters estimated), as Minitab and statsmodels' `normal_ad` use them:
//!
//! ```text
//! A*^2 = A^2 (1 + 0.75/n + 2.25/n^2)
//! A*^2 <  0.200: p = 1 - exp(-13.436 + 101.14 A*^2 - 223.73 A*^4)
//! A*^2 <  0.340: p = 1 - exp(-8.318 + 42.796 A*^2 - 59.938 A*^4)
//! A*^2 <  0.600: p = exp(0.9177 - 4.279 A*^2 - 1.38 A*^4)
//! A*^2 <= 13   : p = exp(1.2937 - 5.709 A*^2 + 0.0186 A*^4)
//! otherwise    : p = 0 (below 5e-31)
//! ```
//!
//! `ln(1 - Phi(z))` is evaluated as `ln(sf(z))` to keep the upper tail accurate.

use super::{check_finite, mean_var, StatsError};
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, Normal};

/// Result of the Anderson-Darling normality test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AndersonDarling {
    /// The unadjusted statistic `A^2` (what Minitab prints as "AD").
    pub a2: f64,
    /// The small-sample adjusted statistic `A*^2` the p-value is computed from.
    pub a2_adjusted: f64,
    pub p: f64,
    pub n: usize,
}

/// Anderson-Darling normality test of `x` (any order). Needs n >= 3 and a non-zero spread.
pub fn anderson_darling(x: &[f64]) -> Result<AndersonDarling, StatsError> {
    const TEST: &str = "Anderson-Darling";
    check_finite(x, TEST)?;
    let n = x.len();
    if n < 3 {
        return Err(StatsError::TooFew {
            test: TEST,
            needed: 3,
            got: n,
            group: None,
        });
    }
    let (mean, var) = mean_var(x);
    if var <= 0.0 {
        return Err(StatsError::ZeroSpread {
            test: TEST,
            reason: "all values are equal".into(),
        });
    }
    let s = var.sqrt();
    let mut z: Vec<f64> = x.iter().map(|v| (v - mean) / s).collect();
    z.sort_by(f64::total_cmp);
    let phi = Normal::standard();
    let nf = n as f64;
    let sum: f64 = (0..n)
        .map(|i| (2.0 * i as f64 + 1.0) * (phi.cdf(z[i]).ln() + phi.sf(z[n - 1 - i]).ln()))
        .sum();
    let a2 = -nf - sum / nf;
    let a = a2 * (1.0 + 0.75 / nf + 2.25 / (nf * nf));
    let p = if a < 0.2 {
        1.0 - (-13.436 + 101.14 * a - 223.73 * a * a).exp()
    } else if a < 0.34 {
        1.0 - (-8.318 + 42.796 * a - 59.938 * a * a).exp()
    } else if a < 0.6 {
        (0.9177 - 4.279 * a - 1.38 * a * a).exp()
    } else if a <= 13.0 {
        (1.2937 - 5.709 * a + 0.0186 * a * a).exp()
    } else {
        0.0
    };
    Ok(AndersonDarling {
        a2,
        a2_adjusted: a,
        p,
        n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::blom_scores;

    #[test]
    fn normal_scores_fit_well_and_exponential_growth_does_not() {
        let ad = anderson_darling(&blom_scores(20)).unwrap();
        assert!(ad.a2 < 0.2 && ad.p > 0.9, "{ad:?}");
        let x: Vec<f64> = (0..30).map(|i| (i as f64 * 0.3).exp()).collect();
        let ad = anderson_darling(&x).unwrap();
        assert!(ad.p < 0.005, "{ad:?}");
    }

    #[test]
    fn adjustment_follows_the_formula() {
        let ad = anderson_darling(&[1.0, 2.0, 4.0, 8.0]).unwrap();
        assert!((ad.a2_adjusted - ad.a2 * (1.0 + 0.75 / 4.0 + 2.25 / 16.0)).abs() < 1e-15);
    }
}
