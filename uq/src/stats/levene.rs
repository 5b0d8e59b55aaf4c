//! Levene's test for equal variances and its Brown-Forsythe (median-centred)
//! variant.
//!
//! With `z_ij = |x_ij - c_i|`, `c_i` the group median (Brown & Forsythe 1974,
//! JASA 69:364 — what Minitab's "Levene's test" uses) or the group mean
//! (Levene 1960), the statistic is the one-way ANOVA F of the `z_ij`:
//!
//! `W = (N - k) sum n_i (zbar_i - zbar)^2 / ((k - 1) sum_ij (z_ij - zbar_i)^2)`
//!
//! with an F(k - 1, N - k) reference distribution (same as
//! `scipy.stats.levene(center='median' | 'mean')`).
//!
//! With two observations per group and median centring, both deviations of a
//! group are equal, the denominator is zero and the test is undefined: that is
//! reported as [`StatsError::ZeroSpread`] rather than an infinite statistic.

use super::{check_finite, StatsError};
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, FisherSnedecor};

/// Which centre the absolute deviations are taken from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LeveneCenter {
    /// Group median: the Brown-Forsythe variant (Minitab's default).
    Median,
    /// Group mean: Levene's original test.
    Mean,
}

/// Result of Levene's test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Levene {
    pub center: LeveneCenter,
    pub statistic: f64,
    pub df1: f64,
    pub df2: f64,
    pub p: f64,
}

fn median(x: &[f64]) -> f64 {
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// Levene's test on `groups` (each needs n >= 2).
pub fn levene(groups: &[Vec<f64>], center: LeveneCenter) -> Result<Levene, StatsError> {
    const TEST: &str = "Levene";
    let k = groups.len();
    if k < 2 {
        return Err(StatsError::TooFewGroups { test: TEST, got: k });
    }
    let mut z: Vec<Vec<f64>> = Vec::with_capacity(k);
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
        let c = match center {
            LeveneCenter::Median => median(x),
            LeveneCenter::Mean => x.iter().sum::<f64>() / x.len() as f64,
        };
        z.push(x.iter().map(|v| (v - c).abs()).collect());
    }
    let n: usize = z.iter().map(Vec::len).sum();
    let zbar = z.iter().flatten().sum::<f64>() / n as f64;
    let mut between = 0.0;
    let mut within = 0.0;
    let mut scale = 0.0f64;
    for zi in &z {
        let m = zi.iter().sum::<f64>() / zi.len() as f64;
        between += zi.len() as f64 * (m - zbar) * (m - zbar);
        within += zi.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
        scale = scale.max(zi.iter().fold(0.0f64, |a, v| a.max(v.abs())));
    }
    // Rounding leaves ~ (eps * scale)^2 per term where the exact value is zero.
    if within <= n as f64 * (1e-12 * scale).powi(2) {
        return Err(StatsError::ZeroSpread {
            test: TEST,
            reason: "the absolute deviations do not vary within any group (e.g. two observations per group with median centring)".into(),
        });
    }
    let (df1, df2) = ((k - 1) as f64, (n - k) as f64);
    let statistic = (df2 * between) / (df1 * within);
    let p = FisherSnedecor::new(df1, df2)
        .map(|d| d.sf(statistic))
        .unwrap_or(f64::NAN);
    Ok(Levene {
        center,
        statistic,
        df1,
        df2,
        p,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn by_hand_with_mean_centring() {
        // z = |x - mean|: group 1 {1, 0, 1}, group 2 {2, 0, 2};
        // zbar_1 = 2/3, zbar_2 = 4/3, zbar = 1; between = 3 (1/9 + 1/9) = 2/3;
        // within = (1/9 + 4/9 + 1/9) + (4/9 + 16/9 + 4/9) = 30/9; W = 4 (2/3) / (30/9) = 0.8.
        let g = vec![vec![1.0, 2.0, 3.0], vec![2.0, 4.0, 6.0]];
        let l = levene(&g, LeveneCenter::Mean).unwrap();
        assert!((l.statistic - 0.8).abs() < 1e-14, "{l:?}");
    }

    #[test]
    fn two_per_group_median_is_undefined() {
        let g = vec![vec![0.98024, 0.97516], vec![0.98931, 0.98562]];
        assert!(matches!(
            levene(&g, LeveneCenter::Median),
            Err(StatsError::ZeroSpread { .. })
        ));
    }
}
