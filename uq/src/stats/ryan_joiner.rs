//! Ryan-Joiner normality test, with the p-value as Minitab reports it.
//!
//! The statistic is the correlation between the ordered sample `Y_(i)` and
//! Blom's normal scores `b_i` (see [`blom_scores`]):
//!
//! `R_p = sum_i Y_(i) b_i / sqrt(s^2 (n - 1) sum_i b_i^2)`
//!
//! (Minitab, "Methods and formulas for Normality Test"; Ryan & Joiner 1976,
//! *Normal probability plots and tests for normality*, Penn State technical
//! report). Small `R_p` rejects normality. Ryan & Joiner fitted the critical
//! values at alpha = 0.10, 0.05 and 0.01 as functions of `n`:
//!
//! ```text
//! c(0.10) = 1.0071 - 0.1371/sqrt(n) - 0.3682/n + 0.7780/n^2
//! c(0.05) = 1.0063 - 0.1288/sqrt(n) - 0.6118/n + 1.3505/n^2
//! c(0.01) = 0.9963 - 0.0211/sqrt(n) - 1.4106/n + 3.1791/n^2
//! ```
//!
//! Minitab's p-value interpolates linearly in `R_p` between these three
//! points and reports "> 0.100" above c(0.10) and "< 0.010" below c(0.01)
//! (behaviour reproduced to the third decimal on 17 data sets in a public
//! Q&A, "Ryan Joiner normality test p-value", which also gives the worked
//! value n = 40, R = 0.968 used in the tests).

use super::normal_scores::blom_scores;
use super::{check_finite, mean_var, StatsError};
use serde::Serialize;

/// Where a reported p-value lies relative to the interpolation range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PBound {
    /// Interpolated between the tabulated levels: `p` is the value.
    Interpolated,
    /// Above the largest tabulated level: the true p exceeds `p` (0.10).
    Above,
    /// Below the smallest tabulated level: the true p is under `p` (0.01).
    Below,
}

/// Result of the Ryan-Joiner test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RyanJoiner {
    /// Correlation of the ordered sample with its normal scores.
    pub r: f64,
    pub n: usize,
    /// p-value, or the bound it lies beyond (see `p_bound`).
    pub p: f64,
    pub p_bound: PBound,
    /// Critical values at alpha = 0.10, 0.05, 0.01.
    pub critical: [f64; 3],
}

impl RyanJoiner {
    /// The p-value as Minitab prints it: "> 0.100", "0.043", "< 0.010".
    pub fn p_text(&self) -> String {
        match self.p_bound {
            PBound::Above => format!("> {:.3}", self.p),
            PBound::Below => format!("< {:.3}", self.p),
            PBound::Interpolated => format!("{:.3}", self.p),
        }
    }
}

/// Ryan & Joiner's critical values of `R_p` at alpha = 0.10, 0.05, 0.01 for a
/// sample of size `n` (equations in the module documentation).
pub fn ryan_joiner_critical(n: usize) -> [f64; 3] {
    let n = n as f64;
    let (s, n2) = (n.sqrt(), n * n);
    [
        1.0071 - 0.1371 / s - 0.3682 / n + 0.7780 / n2,
        1.0063 - 0.1288 / s - 0.6118 / n + 1.3505 / n2,
        0.9963 - 0.0211 / s - 1.4106 / n + 3.1791 / n2,
    ]
}

/// Minitab's p-value for a Ryan-Joiner correlation `r` at sample size `n`:
/// linear interpolation in `r` between the critical values at 0.10, 0.05 and
/// 0.01, clipped to the bounds 0.10 (above) and 0.01 (below).
pub fn ryan_joiner_p(r: f64, n: usize) -> (f64, PBound) {
    let critical = ryan_joiner_critical(n);
    let alphas = [0.10, 0.05, 0.01];
    if r >= critical[0] {
        (0.10, PBound::Above)
    } else if r <= critical[2] {
        (0.01, PBound::Below)
    } else {
        let k = if r >= critical[1] { 0 } else { 1 };
        let t = (r - critical[k + 1]) / (critical[k] - critical[k + 1]);
        (
            alphas[k + 1] + t * (alphas[k] - alphas[k + 1]),
            PBound::Interpolated,
        )
    }
}

/// The Ryan-Joiner test of `x` (any order). Needs n >= 3 and a non-zero spread.
pub fn ryan_joiner(x: &[f64]) -> Result<RyanJoiner, StatsError> {
    const TEST: &str = "Ryan-Joiner";
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
    let (_, var) = mean_var(x);
    if var <= 0.0 {
        return Err(StatsError::ZeroSpread {
            test: TEST,
            reason: "all values are equal".into(),
        });
    }
    let mut y = x.to_vec();
    y.sort_by(f64::total_cmp);
    let b = blom_scores(n);
    // The scores sum to zero, so sum Y b is the centred cross product.
    let num: f64 = y.iter().zip(&b).map(|(y, b)| y * b).sum();
    let bb: f64 = b.iter().map(|b| b * b).sum();
    let r = num / (var * (n as f64 - 1.0) * bb).sqrt();
    let critical = ryan_joiner_critical(n);
    let (p, p_bound) = ryan_joiner_p(r, n);
    Ok(RyanJoiner {
        r,
        n,
        p,
        p_bound,
        critical,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn critical_values_match_the_published_worked_example() {
        // Worked example (n = 40): 0.97670384, 0.97148399, 0.95968573.
        let c = ryan_joiner_critical(40);
        let want = [0.97670384, 0.97148399, 0.95968573];
        for k in 0..3 {
            assert!((c[k] - want[k]).abs() < 5e-9, "{c:?}");
        }
    }

    #[test]
    fn p_value_interpolates_like_the_worked_example() {
        // n = 40, R = 0.968 lies between c(0.01) and c(0.05):
        // p = 0.01 + 0.04 (0.968 - 0.95968573) / (0.97148399 - 0.95968573) = 0.03819.
        let (p, b) = ryan_joiner_p(0.968, 40);
        assert_eq!(b, PBound::Interpolated);
        assert!((p - 0.038188).abs() < 2e-6, "{p}");
        // Minitab printed p = 0.040 for the R it displayed as 0.968: the
        // unrounded R (< 0.9685) gives a p within the printed rounding.
        let (p_hi, _) = ryan_joiner_p(0.96849, 40);
        assert!(p_hi < 0.0405 && p_hi > 0.0395, "{p_hi}");
        assert_eq!(ryan_joiner_p(0.95, 40).1, PBound::Below);
    }

    #[test]
    fn perfectly_normal_scores_give_r_one() {
        let b = blom_scores(12);
        let rj = ryan_joiner(&b).unwrap();
        assert!((rj.r - 1.0).abs() < 1e-14);
        assert_eq!(rj.p_bound, PBound::Above);
        assert_eq!(rj.p_text(), "> 0.100");
    }

    #[test]
    fn skewed_sample_is_rejected() {
        let x: Vec<f64> = (0..30).map(|i| (i as f64 * 0.3).exp()).collect();
        let rj = ryan_joiner(&x).unwrap();
        assert_eq!(rj.p_bound, PBound::Below, "{rj:?}");
    }

    #[test]
    fn too_few_or_constant_is_an_error() {
        assert!(matches!(
            ryan_joiner(&[1.0, 2.0]),
            Err(StatsError::TooFew { .. })
        ));
        assert!(matches!(
            ryan_joiner(&[1.0; 5]),
            Err(StatsError::ZeroSpread { .. })
        ));
        assert!(matches!(
            ryan_joiner(&[1.0, f64::NAN, 2.0]),
            Err(StatsError::NotFinite { .. })
        ));
    }
}
