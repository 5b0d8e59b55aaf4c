//! Noise level estimated from the data alone, by differences.

use super::GapError;
use serde::{Deserialize, Serialize};

/// A noise estimate and how it was obtained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoiseEstimate {
    /// Estimated standard deviation of the measurement noise (data unit).
    pub sd: f64,
    /// Pseudo-residuals used (after trimming).
    pub used: usize,
    /// Pseudo-residuals dropped as outliers (kinks of the signal).
    pub trimmed: usize,
    /// Approximate relative variance of `sd^2` (for tests that use it):
    /// var(sd^2 / sigma^2) ~ 3.89 / used for Gaussian white noise.
    pub rel_var_sd2: f64,
}

/// Cut-off of the trimming, in robust standard deviations.
const TRIM: f64 = 4.0;
/// E[z^2 | |z| < 4] for a standard normal z: 1 - 8 phi(4) / (2 Phi(4) - 1).
const TRIM_CORRECTION: f64 = 0.998_929;

/// Noise standard deviation from second-order pseudo-residuals
/// (Gasser, Sroka & Jennen-Steinmetz, *Biometrika* 73, 1986):
///
/// e_i = (a_i y_{i-1} + b_i y_{i+1} - y_i) / sqrt(a_i^2 + b_i^2 + 1),
/// a_i = (x_{i+1} - x_i) / (x_{i+1} - x_{i-1}), b_i = 1 - a_i,
///
/// which removes any signal that is locally linear in `x` (for equal spacing
/// e_i = (y_{i-1} - 2 y_i + y_{i+1}) / sqrt 6), so a smooth misfit of the model
/// does not inflate it; E[e_i^2] = sigma^2 for white noise. `x` is the time
/// when it increases strictly around sample i, the sample index otherwise.
/// The few pseudo-residuals that straddle a kink of the signal (the end of a
/// ramp, a reversal) are trimmed at 4 robust SDs (1.4826 x median |e|) and the
/// mean square is corrected for the trimming (factor 0.99893).
///
/// Assumes independent noise of constant variance and a signal that is
/// smooth at the sampling scale; correlated noise biases it (low for
/// positively correlated noise).
pub fn difference_noise_sd(y: &[f64], x: Option<&[f64]>) -> Result<NoiseEstimate, GapError> {
    let n = y.len();
    if n < 8 {
        return Err(GapError::TooFewSamples { got: n, needed: 8 });
    }
    let mut e = Vec::with_capacity(n - 2);
    for i in 1..n - 1 {
        let (a, b) = match x {
            Some(x) if x[i + 1] > x[i] && x[i] > x[i - 1] => {
                let a = (x[i + 1] - x[i]) / (x[i + 1] - x[i - 1]);
                (a, 1.0 - a)
            }
            _ => (0.5, 0.5),
        };
        e.push((a * y[i - 1] + b * y[i + 1] - y[i]) / (a * a + b * b + 1.0).sqrt());
    }
    let mut abs: Vec<f64> = e.iter().map(|v| v.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let robust = 1.4826 * abs[abs.len() / 2];
    let kept: Vec<f64> = if robust > 0.0 {
        e.iter()
            .copied()
            .filter(|v| v.abs() <= TRIM * robust)
            .collect()
    } else {
        e.clone()
    };
    let correction = if robust > 0.0 { TRIM_CORRECTION } else { 1.0 };
    let ms = kept.iter().map(|v| v * v).sum::<f64>() / kept.len() as f64 / correction;
    Ok(NoiseEstimate {
        sd: ms.sqrt(),
        used: kept.len(),
        trimmed: e.len() - kept.len(),
        rel_var_sd2: 3.89 / kept.len() as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    #[test]
    fn recovers_the_noise_of_a_smooth_signal_with_kinks() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let normal = Normal::new(0.0, 0.03).unwrap();
        let t: Vec<f64> = (0..800).map(|i| 0.05 * i as f64).collect();
        // ramp, hold with relaxation, unload: kinks at 5 s and 30 s.
        let signal = |t: f64| {
            if t < 5.0 {
                0.4 * t
            } else if t < 30.0 {
                2.0 - 0.5 * (1.0 - (-(t - 5.0) / 0.8).exp())
            } else {
                1.5 - 0.4 * (t - 30.0)
            }
        };
        let y: Vec<f64> = t
            .iter()
            .map(|&t| signal(t) + normal.sample(&mut rng))
            .collect();
        let est = difference_noise_sd(&y, Some(&t)).unwrap();
        assert!((est.sd / 0.03 - 1.0).abs() < 0.08, "{est:?}");
        // Without the noise the estimate is near zero (the kinks are trimmed).
        let clean: Vec<f64> = t.iter().map(|&t| signal(t)).collect();
        assert!(difference_noise_sd(&clean, Some(&t)).unwrap().sd < 3e-3);
        assert!(difference_noise_sd(&y[..5], None).is_err());
    }
}
