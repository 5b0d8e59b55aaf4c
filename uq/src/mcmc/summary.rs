//! Posterior summaries as `arviz.summary` reports them (mean, sd, 94 % HDI,
//! MCSE, ESS, R-hat) plus the posterior correlation matrix.

use super::chains::Chains;
use super::diagnostics;
use serde::{Deserialize, Serialize};

/// One parameter's summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamSummary {
    pub name: String,
    pub mean: f64,
    /// Standard deviation over all draws (ddof 1).
    pub sd: f64,
    /// Lower end of the 94 % highest-density interval.
    pub hdi_3: f64,
    /// Upper end of the 94 % highest-density interval.
    pub hdi_97: f64,
    pub mcse_mean: f64,
    pub ess_bulk: f64,
    pub ess_tail: f64,
    pub rhat: f64,
}

/// Highest-density interval of probability `prob` of a unimodal sample: the
/// shortest interval [x_(i), x_(i + floor(prob n))] of the sorted draws
/// (Chen & Shao 1999; `arviz.hdi`).
pub fn hdi(x: &[f64], prob: f64) -> (f64, f64) {
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    let inc = (prob * n as f64).floor() as usize;
    if n == 0 || inc >= n {
        return (f64::NAN, f64::NAN);
    }
    let mut best = 0;
    let mut width = f64::INFINITY;
    for i in 0..n - inc {
        let w = s[i + inc] - s[i];
        if w < width {
            width = w;
            best = i;
        }
    }
    (s[best], s[best + inc])
}

/// Mean and SD (ddof 1).
pub fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
    (m, v.sqrt())
}

/// Summaries of every parameter of `chains` (draws in the units to report).
pub fn summarize(chains: &Chains, names: &[String]) -> Vec<ParamSummary> {
    (0..chains.dim)
        .map(|k| {
            let p = chains.param(k);
            let flat: Vec<f64> = p.iter().flatten().copied().collect();
            let (mean, sd) = mean_sd(&flat);
            let (hdi_3, hdi_97) = hdi(&flat, 0.94);
            ParamSummary {
                name: names.get(k).cloned().unwrap_or_else(|| format!("x{k}")),
                mean,
                sd,
                hdi_3,
                hdi_97,
                mcse_mean: diagnostics::mcse_mean(&p),
                ess_bulk: diagnostics::ess_bulk(&p),
                ess_tail: diagnostics::ess_tail(&p),
                rhat: diagnostics::rhat(&p),
            }
        })
        .collect()
}

/// Posterior correlation matrix of all draws, row-major `dim x dim`.
pub fn correlation(chains: &Chains) -> Vec<Vec<f64>> {
    let d = chains.dim;
    let n = (chains.n_chains * chains.n_draws) as f64;
    let mut mean = vec![0.0; d];
    for p in chains.points() {
        for k in 0..d {
            mean[k] += p[k] / n;
        }
    }
    let mut cov = vec![vec![0.0; d]; d];
    for p in chains.points() {
        for i in 0..d {
            for j in 0..d {
                cov[i][j] += (p[i] - mean[i]) * (p[j] - mean[j]);
            }
        }
    }
    (0..d)
        .map(|i| {
            (0..d)
                .map(|j| cov[i][j] / (cov[i][i] * cov[j][j]).sqrt())
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hdi_of_uniform_grid_and_skewed_sample() {
        let x: Vec<f64> = (0..100).map(|i| i as f64).collect();
        let (lo, hi) = hdi(&x, 0.94);
        assert_eq!(hi - lo, 94.0);
        // Exponential-like sample: the HDI starts at the minimum.
        let y: Vec<f64> = (1..1000).map(|i| -(1.0 - i as f64 / 1000.0).ln()).collect();
        let (lo, hi) = hdi(&y, 0.9);
        assert_eq!(lo, y[0]);
        assert!((hi - (10.0f64).ln()).abs() < 0.02, "{hi}");
    }

    #[test]
    fn correlation_of_linear_pair_is_one() {
        let pts: Vec<Vec<f64>> = (0..50)
            .map(|i| vec![i as f64, -2.0 * i as f64 + 1.0])
            .collect();
        let c = correlation(&Chains::from_nested(&[pts]));
        assert!((c[0][1] + 1.0).abs() < 1e-12 && (c[0][0] - 1.0).abs() < 1e-12);
    }
}
