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
    let index: Vec<f64>;
    let x = match x {
        Some(x) => x,
        None => {
            index = (0..n).map(|i| i as f64).collect();
            &index
        }
    };
    let all: Vec<usize> = (0..n).collect();
    pooled(&pseudo_residuals(y, x, &all))
}

/// The loading paths of a record: which path (and output) each sample
/// belongs to, and where along its path it lies. A record that interleaves
/// several paths (general biaxial data: a stress along each direction,
/// paths at fixed lambda1 with lambda2 varied) has neighbouring samples on
/// different paths, and second differences across them measure the jump
/// between the paths, not the noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NoisePaths {
    /// The path of each sample (any labels; samples of a path need not be
    /// contiguous, they are taken in record order).
    pub path: Vec<usize>,
    /// Each sample's position along its path (the quantity varied on it:
    /// time, or the stretch that changes along the path).
    pub along: Vec<f64>,
}

/// [`difference_noise_sd`] within each path of `paths`: the second-order
/// pseudo-residuals of neighbouring samples of the same path (a path of
/// fewer than 3 samples contributes none), pooled, trimmed and corrected
/// as for a single path.
pub fn path_noise_sd(y: &[f64], paths: &NoisePaths) -> Result<NoiseEstimate, GapError> {
    let n = y.len();
    if paths.path.len() != n || paths.along.len() != n {
        return Err(GapError::InvalidOption {
            option: "paths",
            reason: format!(
                "{} path labels and {} positions for {n} samples; give one of each per sample",
                paths.path.len(),
                paths.along.len()
            ),
        });
    }
    let mut labels: Vec<usize> = paths.path.clone();
    labels.sort_unstable();
    labels.dedup();
    let mut e = Vec::new();
    for label in labels {
        let members: Vec<usize> = (0..n).filter(|&i| paths.path[i] == label).collect();
        e.extend(pseudo_residuals(y, &paths.along, &members));
    }
    if e.len() < 6 {
        return Err(GapError::TooFewSamples {
            got: e.len() + 2,
            needed: 8,
        });
    }
    pooled(&e)
}

/// Pseudo-residuals of the samples `members` (in that order) of `y` at
/// abscissae `x`: equal weights where `x` does not increase strictly.
fn pseudo_residuals(y: &[f64], x: &[f64], members: &[usize]) -> Vec<f64> {
    members
        .windows(3)
        .map(|w| {
            let (h, i, j) = (w[0], w[1], w[2]);
            let (a, b) = if x[j] > x[i] && x[i] > x[h] {
                let a = (x[j] - x[i]) / (x[j] - x[h]);
                (a, 1.0 - a)
            } else {
                (0.5, 0.5)
            };
            (a * y[h] + b * y[j] - y[i]) / (a * a + b * b + 1.0).sqrt()
        })
        .collect()
}

/// The noise SD from pseudo-residuals `e`: trimmed at 4 robust SDs, the
/// mean square corrected for the trimming.
fn pooled(e: &[f64]) -> Result<NoiseEstimate, GapError> {
    let mut abs: Vec<f64> = e.iter().map(|v| v.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let robust = 1.4826 * abs[abs.len() / 2];
    let kept: Vec<f64> = if robust > 0.0 {
        e.iter()
            .copied()
            .filter(|v| v.abs() <= TRIM * robust)
            .collect()
    } else {
        e.to_vec()
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

    #[test]
    fn interleaved_paths_are_differenced_within_each_path() {
        // Two outputs per row on 12 paths of 8 rows: along each path a
        // smooth curve, the paths far apart; interleaved, neighbouring
        // samples jump between outputs and paths.
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let normal = Normal::new(0.0, 0.002).unwrap();
        let (mut y, mut path, mut along) = (Vec::new(), Vec::new(), Vec::new());
        for p in 0..12 {
            for r in 0..8 {
                let l2 = 0.95 + 0.02 * r as f64 + 0.003 * (r % 3) as f64;
                let l1 = 1.0 + 0.1 * p as f64;
                for (k, v) in [l1 * l1 - 1.0 / l2, l2 * l2 - 1.0 / l1]
                    .into_iter()
                    .enumerate()
                {
                    y.push(v + normal.sample(&mut rng));
                    path.push(2 * p + k);
                    along.push(l2);
                }
            }
        }
        let across = difference_noise_sd(&y, None).unwrap();
        assert!(across.sd > 0.05, "{across:?}");
        let within = path_noise_sd(&y, &NoisePaths { path, along }).unwrap();
        assert!((within.sd / 0.002 - 1.0).abs() < 0.15, "{within:?}");
        assert_eq!(within.used + within.trimmed, 24 * 6);
        let bad = NoisePaths {
            path: vec![0; 3],
            along: vec![0.0; 3],
        };
        assert!(matches!(
            path_noise_sd(&y, &bad),
            Err(GapError::InvalidOption {
                option: "paths",
                ..
            })
        ));
    }
}
