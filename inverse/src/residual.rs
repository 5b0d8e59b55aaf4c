//! How a prediction and an observation make a residual.

use serde::{Deserialize, Serialize};

/// The residual kind of an objective.
///
/// For a data set with weight `w`, observations `y_i` and predictions
/// `f_i(theta)`, residual `i` is `r_i = w * s_i * (f_i - y_i)` with
///
/// * `Absolute`:   `s_i = 1` (residual in the observation's unit);
/// * `Relative`:   `s_i = 1 / y_i`; samples with `y_i == 0` are left out;
/// * `Normalised`: `s_i = 1 / (RMS(y) * sqrt(n))` with
///   `RMS(y) = sqrt(sum_i y_i^2 / n)` over the set's `n` samples, i.e.
///   `s_i = 1 / sqrt(sum_i y_i^2)`. A set's sum of squares is then
///   `w^2 * sum_i (f_i - y_i)^2 / sum_i y_i^2`, dimensionless and independent
///   of the number of samples, so every set weighs equally (for equal `w`)
///   whatever its units and length.
///
/// The objective is `SSE = sum_i r_i^2` over all sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ResidualKind {
    #[default]
    Absolute,
    Relative,
    Normalised,
}

impl ResidualKind {
    /// The kept sample indices and their factors `w * s_i` for one set, or
    /// `None` when `Normalised` is asked of all-zero observations.
    pub fn factors(self, observed: &[f64], weight: f64) -> Option<Vec<(usize, f64)>> {
        match self {
            ResidualKind::Absolute => Some((0..observed.len()).map(|i| (i, weight)).collect()),
            ResidualKind::Relative => Some(
                observed
                    .iter()
                    .enumerate()
                    .filter(|(_, &y)| y != 0.0)
                    .map(|(i, &y)| (i, weight / y))
                    .collect(),
            ),
            ResidualKind::Normalised => {
                let sum_sq: f64 = observed.iter().map(|y| y * y).sum();
                if sum_sq > 0.0 {
                    let s = weight / sum_sq.sqrt();
                    Some((0..observed.len()).map(|i| (i, s)).collect())
                } else {
                    None
                }
            }
        }
    }
}

impl std::fmt::Display for ResidualKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ResidualKind::Absolute => "absolute",
            ResidualKind::Relative => "relative",
            ResidualKind::Normalised => "normalised",
        })
    }
}

impl std::str::FromStr for ResidualKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "absolute" => Ok(ResidualKind::Absolute),
            "relative" => Ok(ResidualKind::Relative),
            "normalised" | "normalized" => Ok(ResidualKind::Normalised),
            _ => Err(format!(
                "unknown residual kind `{s}`; expected absolute, relative or normalised"
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_skips_zero_observations() {
        let f = ResidualKind::Relative
            .factors(&[2.0, 0.0, -4.0], 3.0)
            .unwrap();
        assert_eq!(f, vec![(0, 1.5), (2, -0.75)]);
    }

    #[test]
    fn normalised_set_sum_of_squares_is_relative_error() {
        // A prediction off by 10 % everywhere gives SSE = 0.01 whatever n and the unit.
        for (scale, n) in [(1.0, 5), (1e3, 50)] {
            let y: Vec<f64> = (1..=n).map(|i| scale * i as f64).collect();
            let f = ResidualKind::Normalised.factors(&y, 1.0).unwrap();
            let sse: f64 = f.iter().map(|&(i, s)| (s * 0.1 * y[i]).powi(2)).sum();
            assert!((sse - 0.01).abs() < 1e-15, "{sse}");
        }
        assert!(ResidualKind::Normalised.factors(&[0.0, 0.0], 1.0).is_none());
    }
}
