//! Structure of the residuals of a fit against the noise: whole-record
//! tests (chi-square of the misfit, lag-1 autocorrelation, Wald-Wolfowitz
//! runs), windows of significant misfit and a discrepancy band.

use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

fn normal_cdf(z: f64) -> f64 {
    Normal::new(0.0, 1.0).expect("standard normal").cdf(z)
}

/// Upper tail P(X > x) of a chi-square variable with `dof` degrees of freedom.
pub(crate) fn chi2_sf(x: f64, dof: f64) -> f64 {
    if dof <= 0.0 {
        return 1.0;
    }
    ChiSquared::new(dof)
        .map(|d| d.sf(x.max(0.0)))
        .unwrap_or(f64::NAN)
}

/// Quantile of a chi-square variable (upper tail probability `p`).
pub(crate) fn chi2_isf(p: f64, dof: f64) -> f64 {
    ChiSquared::new(dof.max(1e-9))
        .map(|d| d.inverse_cdf(1.0 - p))
        .unwrap_or(f64::INFINITY)
}

/// Whole-record tests of residuals against white noise of a known SD.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WhitenessTests {
    /// RMS of the residuals divided by the noise SD.
    pub rms_over_noise: f64,
    /// z-score of SSE / sigma^2 against its null distribution (chi-square on
    /// n - p degrees of freedom, widened by the uncertainty of the noise estimate).
    pub misfit_z: f64,
    /// One-sided p-value of `misfit_z` (misfit larger than the noise).
    pub misfit_p: f64,
    /// Lag-1 autocorrelation of the residuals.
    pub lag1_autocorrelation: f64,
    /// One-sided p-value of a positive lag-1 autocorrelation (N(-1/n, 1/n) under the null).
    pub lag1_p: f64,
    /// Number of runs of equal sign.
    pub runs: usize,
    /// Runs expected under the null (Wald-Wolfowitz).
    pub runs_expected: f64,
    /// z-score of the runs count.
    pub runs_z: f64,
    /// One-sided p-value of too few runs.
    pub runs_p: f64,
}

/// Wald-Wolfowitz runs test on the signs of `r` (zeros skipped):
/// mu = 2 n+ n- / N + 1, var = 2 n+ n- (2 n+ n- - N) / (N^2 (N - 1)).
pub(crate) fn runs_test(r: &[f64]) -> (usize, f64, f64, f64) {
    let signs: Vec<bool> = r.iter().filter(|v| **v != 0.0).map(|v| *v > 0.0).collect();
    let n = signs.len() as f64;
    let np = signs.iter().filter(|s| **s).count() as f64;
    let nm = n - np;
    if np == 0.0 || nm == 0.0 {
        return (1, 1.0, f64::NEG_INFINITY, 0.0);
    }
    let runs = 1 + signs.windows(2).filter(|w| w[0] != w[1]).count();
    let mu = 2.0 * np * nm / n + 1.0;
    let var = 2.0 * np * nm * (2.0 * np * nm - n) / (n * n * (n - 1.0));
    let z = (runs as f64 - mu) / var.sqrt();
    (runs, mu, z, normal_cdf(z))
}

/// Lag-1 autocorrelation sum r_i r_{i-1} / sum r_i^2.
pub(crate) fn lag1(r: &[f64]) -> f64 {
    let ss: f64 = r.iter().map(|v| v * v).sum();
    if ss == 0.0 {
        return 0.0;
    }
    r.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / ss
}

/// The whole-record tests for residuals `r` of a fit with `p` parameters and
/// a noise SD `sigma` whose square has relative variance `rel_var_sd2`.
pub fn whiteness(r: &[f64], p: usize, sigma: f64, rel_var_sd2: f64) -> WhitenessTests {
    let n = r.len();
    let dof = (n.saturating_sub(p)).max(1) as f64;
    let sse: f64 = r.iter().map(|v| v * v).sum();
    let ratio = sse / (sigma * sigma) / dof;
    let misfit_z = (ratio - 1.0) / (2.0 / dof + rel_var_sd2).sqrt();
    let rho = lag1(r);
    let nf = n as f64;
    let lag1_z = (rho + 1.0 / nf) * nf.sqrt();
    let (runs, runs_expected, runs_z, runs_p) = runs_test(r);
    WhitenessTests {
        rms_over_noise: (sse / nf).sqrt() / sigma,
        misfit_z,
        misfit_p: 1.0 - normal_cdf(misfit_z),
        lag1_autocorrelation: rho,
        lag1_p: 1.0 - normal_cdf(lag1_z),
        runs,
        runs_expected,
        runs_z,
        runs_p,
    }
}

/// A window of the experiment where the misfit is significant (GAP.md `where`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GapWindow {
    /// Axis the window is measured on: `time_s`, or the drive column.
    pub axis: String,
    pub from: f64,
    pub to: f64,
    /// RMS of the residuals in the window (data unit, N for forces).
    pub misfit_rms: f64,
    /// How significant, in words and numbers.
    pub significance: String,
    /// Sample indices [first, last] of the window.
    pub first: usize,
    pub last: usize,
    /// Mean residual in the window (sign: data above the model when positive).
    pub mean_residual: f64,
    /// p-value of the window's misfit (the smaller of the bias and
    /// chi-square tests, before the multiple-testing correction).
    pub p_value: f64,
}

/// Default running-window length for `n` samples: n / 15, within [8, 60].
pub fn default_window(n: usize) -> usize {
    (n / 15).clamp(8, 60).min(n)
}

/// Windows of significant misfit: a window of `w` samples slides by w/2;
/// each is tested for a bias (sum z)^2 / w ~ chi2(1) and for excess scatter
/// sum z^2 ~ chi2(w), z = r / sigma, at level `alpha` divided by the number of
/// tests (Bonferroni); overlapping or touching flagged windows are merged and
/// each merged window is reported with its own statistics.
pub fn significant_windows(
    r: &[f64],
    axis_name: &str,
    axis: &[f64],
    sigma: f64,
    w: usize,
    alpha: f64,
) -> Vec<GapWindow> {
    let n = r.len();
    if n < 2 || w < 2 || w > n {
        return Vec::new();
    }
    let step = (w / 2).max(1);
    let mut starts: Vec<usize> = (0..=n - w).step_by(step).collect();
    if *starts.last().unwrap_or(&0) != n - w {
        starts.push(n - w);
    }
    let tests = 2.0 * starts.len() as f64;
    let level = alpha / tests;
    let window_p = |a: usize, b: usize| {
        let z: Vec<f64> = r[a..=b].iter().map(|v| v / sigma).collect();
        let m = z.len() as f64;
        let bias = z.iter().sum::<f64>().powi(2) / m;
        let scatter = z.iter().map(|v| v * v).sum::<f64>();
        let (pb, ps) = (chi2_sf(bias, 1.0), chi2_sf(scatter, m));
        (pb.min(ps), bias, scatter, m)
    };
    let mut flagged: Vec<(usize, usize)> = Vec::new();
    for &s in &starts {
        let (p, ..) = window_p(s, s + w - 1);
        if p < level {
            match flagged.last_mut() {
                Some(last) if s <= last.1 + 1 => last.1 = s + w - 1,
                _ => flagged.push((s, s + w - 1)),
            }
        }
    }
    flagged
        .into_iter()
        .map(|(a, b)| {
            let (p, bias, scatter, m) = window_p(a, b);
            let rms = (r[a..=b].iter().map(|v| v * v).sum::<f64>() / m).sqrt();
            let mean = r[a..=b].iter().sum::<f64>() / m;
            GapWindow {
                axis: axis_name.to_string(),
                from: axis[a],
                to: axis[b],
                misfit_rms: rms,
                significance: format!(
                    "{} samples, RMS/noise = {:.2}, bias chi2(1) = {:.1}, scatter chi2({}) = {:.1}, p = {:.2e} \
                     (flagged below {:.1e} = {alpha:.0e} / {tests} tests, bias and scatter per window)",
                    m,
                    rms / sigma,
                    bias,
                    m,
                    scatter,
                    p,
                    level
                ),
                first: a,
                last: b,
                mean_residual: mean,
                p_value: p,
            }
        })
        .collect()
}

/// Discrepancy band: centred running mean of the residuals over `w` samples
/// (the systematic part of the misfit) and its +-2 sigma / sqrt(w) band under
/// white noise. Returns (mean, lower, upper).
pub fn discrepancy_band(r: &[f64], sigma: f64, w: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = r.len();
    let half = w / 2;
    let mut mean = Vec::with_capacity(n);
    let mut lo = Vec::with_capacity(n);
    let mut hi = Vec::with_capacity(n);
    for i in 0..n {
        let a = i.saturating_sub(half);
        let b = (i + half).min(n - 1);
        let m = (b - a + 1) as f64;
        let mu = r[a..=b].iter().sum::<f64>() / m;
        let half_width = 2.0 * sigma / m.sqrt();
        mean.push(mu);
        lo.push(mu - half_width);
        hi.push(mu + half_width);
    }
    (mean, lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    #[test]
    fn white_noise_passes_and_a_bump_is_located() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let r: Vec<f64> = (0..600).map(|_| normal.sample(&mut rng)).collect();
        let x: Vec<f64> = (0..600).map(|i| i as f64 * 0.1).collect();
        let white = whiteness(&r, 1, 1.0, 3.89 / 600.0);
        assert!(
            white.misfit_p > 1e-3 && white.runs_p > 1e-3 && white.lag1_p > 1e-3,
            "{white:?}"
        );
        assert!(significant_windows(&r, "time_s", &x, 1.0, 40, 1e-3).is_empty());
        // A bump of 0.8 sigma between samples 300 and 360.
        let bumped: Vec<f64> = r
            .iter()
            .enumerate()
            .map(|(i, v)| v + if (300..360).contains(&i) { 0.8 } else { 0.0 })
            .collect();
        let w = significant_windows(&bumped, "time_s", &x, 1.0, 40, 1e-3);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].from >= 26.0 && w[0].to <= 40.0, "{w:?}");
        // The whole-record tests move towards structure (the window test is the sharper one).
        let t = whiteness(&bumped, 1, 1.0, 3.89 / 600.0);
        assert!(
            t.runs_p < white.runs_p && t.lag1_p < white.lag1_p && t.misfit_z > white.misfit_z,
            "{t:?}"
        );
    }

    #[test]
    fn runs_count_matches_a_hand_count() {
        let (runs, mu, ..) = runs_test(&[1.0, 2.0, -1.0, -1.0, 3.0, -2.0]);
        assert_eq!(runs, 4);
        // n+ = 3, n- = 3: mu = 2*9/6 + 1 = 4.
        assert!((mu - 4.0).abs() < 1e-12);
    }
}
