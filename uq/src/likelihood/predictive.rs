//! Posterior predictive bands: quantiles of the model curve over posterior
//! draws, and of the curve plus measurement noise.

use super::posterior::Posterior;
use crate::mcmc::rng::{chain_rng, std_normal};
use crate::mcmc::{diagnostics::quantile, Chains};
use palpate_core::ForwardError;
use serde::{Deserialize, Serialize};

/// Pointwise bands of one data set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PredictiveBand {
    /// Drive samples of the data set.
    pub drive: Vec<f64>,
    /// Median model prediction.
    pub median: Vec<f64>,
    /// Central `prob` interval of the model prediction (parameter uncertainty).
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// Central `prob` interval of a new observation (prediction + noise).
    pub lower_observed: Vec<f64>,
    pub upper_observed: Vec<f64>,
    pub prob: f64,
}

/// Bands of data set `s` from `n` draws spread evenly through `draws`
/// (physical parameters); noise is drawn AR(1)/independent with the draw's
/// sigma and phi from `seed`'s stream. Draws where the model fails are skipped.
pub fn predictive_band(
    post: &Posterior,
    s: usize,
    draws: &Chains,
    n: usize,
    prob: f64,
    seed: u64,
) -> Result<PredictiveBand, ForwardError> {
    let total = draws.n_chains * draws.n_draws;
    let n = n.min(total).max(1);
    let mut rng = chain_rng(seed, 0);
    let mut curves = Vec::with_capacity(n);
    let mut noisy = Vec::with_capacity(n);
    let mut last_err = None;
    for i in 0..n {
        let idx = i * total / n;
        let x = draws.point(idx / draws.n_draws, idx % draws.n_draws);
        match post.predict(s, x) {
            Ok(y) => {
                let (sigma, phi) = post.noise_at(s, x);
                let mut e = sigma * std_normal(&mut rng);
                let inno = sigma * (1.0 - phi * phi).sqrt();
                let yn: Vec<f64> = y
                    .iter()
                    .enumerate()
                    .map(|(t, v)| {
                        if t > 0 {
                            e = phi * e + inno * std_normal(&mut rng);
                        }
                        v + e
                    })
                    .collect();
                curves.push(y);
                noisy.push(yn);
            }
            Err(e) => last_err = Some(e),
        }
    }
    if curves.is_empty() {
        return Err(last_err.unwrap_or(ForwardError::InvalidLoading("no draws".into())));
    }
    let m = curves[0].len();
    let col = |set: &Vec<Vec<f64>>, t: usize| -> Vec<f64> { set.iter().map(|c| c[t]).collect() };
    let (a, b) = (0.5 - prob / 2.0, 0.5 + prob / 2.0);
    let mut band = PredictiveBand {
        drive: post.datasets()[s].loading.drive.clone(),
        median: Vec::with_capacity(m),
        lower: Vec::with_capacity(m),
        upper: Vec::with_capacity(m),
        lower_observed: Vec::with_capacity(m),
        upper_observed: Vec::with_capacity(m),
        prob,
    };
    for t in 0..m {
        let c = col(&curves, t);
        band.median.push(quantile(&c, 0.5));
        band.lower.push(quantile(&c, a));
        band.upper.push(quantile(&c, b));
        let c = col(&noisy, t);
        band.lower_observed.push(quantile(&c, a));
        band.upper_observed.push(quantile(&c, b));
    }
    Ok(band)
}
