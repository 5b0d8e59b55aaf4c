//! Bartlett's test for equal variances across groups (normal theory).
//!
//! With `k` groups of sizes `n_i`, sample variances `s_i^2`, `N = sum n_i`
//! and the pooled variance `s_p^2 = sum (n_i - 1) s_i^2 / (N - k)`:
//!
//! ```text
//! T = [(N - k) ln s_p^2 - sum (n_i - 1) ln s_i^2] / C
//! C = 1 + (sum 1/(n_i - 1) - 1/(N - k)) / (3 (k - 1))
//! ```
//!
//! `T` is approximately chi-square with `k - 1` degrees of freedom under
//! equal variances (Bartlett 1937, Proc. R. Soc. A 160:268; NIST/SEMATECH
//! e-Handbook 1.3.5.7; the same statistic as `scipy.stats.bartlett`).

use super::{check_finite, mean_var, StatsError};
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Result of Bartlett's test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bartlett {
    pub statistic: f64,
    pub df: f64,
    pub p: f64,
}

/// Bartlett's test on `groups` (each needs n >= 2 and a non-zero variance).
pub fn bartlett(groups: &[Vec<f64>]) -> Result<Bartlett, StatsError> {
    const TEST: &str = "Bartlett";
    let k = groups.len();
    if k < 2 {
        return Err(StatsError::TooFewGroups { test: TEST, got: k });
    }
    let mut total = 0.0;
    let mut pooled = 0.0;
    let mut sum_log = 0.0;
    let mut sum_inv = 0.0;
    for (g, x) in groups.iter().enumerate() {
        check_finite(x, TEST)?;
        if x.len() < 2 {
            return Err(StatsError::TooFew {
                test: TEST,
                needed: 2,
                got: x.len(),
                group: Some(g),
            });
        }
        let (_, v) = mean_var(x);
        if v <= 0.0 {
            return Err(StatsError::ZeroSpread {
                test: TEST,
                reason: format!("group {g} has zero variance"),
            });
        }
        let dfi = x.len() as f64 - 1.0;
        total += dfi;
        pooled += dfi * v;
        sum_log += dfi * v.ln();
        sum_inv += 1.0 / dfi;
    }
    let kf = k as f64;
    let sp2 = pooled / total;
    let c = 1.0 + (sum_inv - 1.0 / total) / (3.0 * (kf - 1.0));
    let statistic = (total * sp2.ln() - sum_log) / c;
    let df = kf - 1.0;
    let p = ChiSquared::new(df)
        .map(|d| d.sf(statistic))
        .unwrap_or(f64::NAN);
    Ok(Bartlett { statistic, df, p })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_spreads_give_zero_statistic() {
        let g = vec![vec![1.0, 2.0, 3.0], vec![11.0, 12.0, 13.0]];
        let b = bartlett(&g).unwrap();
        assert!(
            b.statistic.abs() < 1e-12 && (b.p - 1.0).abs() < 1e-9,
            "{b:?}"
        );
    }

    #[test]
    fn two_groups_by_hand() {
        // s1^2 = 1, s2^2 = 4, n = 3 each: sp2 = 2.5, C = 1 + (1/2 + 1/2 - 1/4)/3 = 1.25,
        // T = (4 ln 2.5 - 2 ln 1 - 2 ln 4) / 1.25.
        let g = vec![vec![1.0, 2.0, 3.0], vec![2.0, 4.0, 6.0]];
        let b = bartlett(&g).unwrap();
        let want = (4.0 * 2.5f64.ln() - 2.0 * 4.0f64.ln()) / 1.25;
        assert!((b.statistic - want).abs() < 1e-14, "{b:?}");
        assert!(bartlett(&g[..1]).is_err());
        assert!(bartlett(&[vec![1.0, 1.0], vec![1.0, 2.0]]).is_err());
    }
}
