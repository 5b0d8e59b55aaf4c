//! Gaussian measurement-noise models: independent, or AR(1)-correlated
//! residuals for densely sampled curves.

use serde::{Deserialize, Serialize};

use super::prior::Prior;

const LN_2PI: f64 = 1.837_877_066_409_345_5;

/// The noise standard deviation of one data set (marginal SD, in the
/// observable's unit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSd {
    /// Known sigma.
    Known(f64),
    /// Inferred as an extra parameter `sigma[_name]` with this prior.
    Inferred(Prior),
}

/// Correlation of successive residuals.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Correlation {
    /// Independent residuals.
    Independent,
    /// AR(1) with a known coefficient phi in (-1, 1).
    Ar1Known(f64),
    /// AR(1) with phi inferred as an extra parameter `phi[_name]` on (-1, 1)
    /// with this prior.
    Ar1Inferred(Prior),
}

/// The noise model of one data set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseModel {
    pub sd: NoiseSd,
    pub correlation: Correlation,
}

impl NoiseModel {
    /// Independent noise of known SD.
    pub fn known(sigma: f64) -> Self {
        NoiseModel {
            sd: NoiseSd::Known(sigma),
            correlation: Correlation::Independent,
        }
    }

    /// Independent noise whose SD is inferred with `prior`.
    pub fn inferred(prior: Prior) -> Self {
        NoiseModel {
            sd: NoiseSd::Inferred(prior),
            correlation: Correlation::Independent,
        }
    }
}

/// log-likelihood of independent N(0, sigma^2) residuals:
/// -n/2 ln(2 pi) - n ln sigma - sum r^2 / (2 sigma^2).
pub fn gaussian_log_likelihood(residuals: &[f64], sigma: f64) -> f64 {
    let n = residuals.len() as f64;
    let ss: f64 = residuals.iter().map(|r| r * r).sum();
    -0.5 * n * LN_2PI - n * sigma.ln() - 0.5 * ss / (sigma * sigma)
}

/// log-likelihood of independent residuals whose variance is the noise
/// variance plus a known model-error variance per sample,
/// r_i ~ N(0, sigma^2 + v_i):
///
///   ln L = -1/2 sum_i [ ln(2 pi (sigma^2 + v_i)) + r_i^2 / (sigma^2 + v_i) ].
///
/// This is the "approximation error" model of Kaipio & Somersalo (2005,
/// *Statistical and Computational Inverse Problems*, Springer, sec. 7.4;
/// Kaipio & Somersalo 2007, *J. Comput. Appl. Math.* 198, 493-504): the
/// difference between the accurate model and a reduced one (here the
/// surrogate) is treated as Gaussian, independent of the parameters and of
/// the noise, with its covariance estimated from runs of both models; here
/// its diagonal, v_i = mean over held-out runs of (surrogate - model)^2 at
/// sample i (the second moment, which keeps any mean error in the variance
/// rather than subtracting it), as Kennedy & O'Hagan (2001, *J. R. Stat.
/// Soc. B* 63, 425-464, sec. 4.2) add the code uncertainty of an emulator
/// to the observation variance.
pub fn gaussian_log_likelihood_with_model_error(
    residuals: &[f64],
    sigma: f64,
    model_variance: &[f64],
) -> f64 {
    let s2 = sigma * sigma;
    residuals
        .iter()
        .zip(model_variance)
        .map(|(r, v)| {
            let t = s2 + v;
            -0.5 * (LN_2PI + t.ln() + r * r / t)
        })
        .sum()
}

/// Exact log-likelihood of a stationary AR(1) residual series with marginal
/// SD sigma and coefficient phi, e_t = phi e_{t-1} + u_t,
/// u_t ~ N(0, sigma^2 (1 - phi^2)) (Box, Jenkins & Reinsel, *Time Series
/// Analysis*, 4th ed., eq. 7.1.13; the first residual keeps its marginal
/// density, so no observation is conditioned away):
///
///   ln L = -n/2 ln(2 pi) - n ln sigma - (n - 1)/2 ln(1 - phi^2)
///          - e_1^2 / (2 sigma^2) - sum_{t>=2} (e_t - phi e_{t-1})^2 / (2 sigma^2 (1 - phi^2)).
///
/// It equals the multivariate normal density with covariance
/// sigma^2 phi^|i-j| (tested against a Cholesky evaluation).
pub fn ar1_log_likelihood(residuals: &[f64], sigma: f64, phi: f64) -> f64 {
    let n = residuals.len();
    if n == 0 {
        return 0.0;
    }
    let one_m = 1.0 - phi * phi;
    let s2 = sigma * sigma;
    let mut q = residuals[0] * residuals[0] / s2;
    for t in 1..n {
        let u = residuals[t] - phi * residuals[t - 1];
        q += u * u / (s2 * one_m);
    }
    let nf = n as f64;
    -0.5 * nf * LN_2PI - nf * sigma.ln() - 0.5 * (nf - 1.0) * one_m.ln() - 0.5 * q
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    #[test]
    fn ar1_matches_dense_multivariate_normal() {
        let r = [0.3, -0.1, 0.5, 0.45, -0.2, 0.05, 0.6];
        let (sigma, phi): (f64, f64) = (0.4, 0.7);
        let n = r.len();
        let cov: DMatrix<f64> = DMatrix::from_fn(n, n, |i, j| {
            sigma * sigma * phi.powi((i as i32 - j as i32).abs())
        });
        let ch = cov.cholesky().unwrap();
        let x = DVector::from_row_slice(&r);
        let sol = ch.solve(&x);
        let log_det: f64 = 2.0 * (0..n).map(|i| ch.l()[(i, i)].ln()).sum::<f64>();
        let dense = -0.5 * n as f64 * LN_2PI - 0.5 * log_det - 0.5 * x.dot(&sol);
        let fast = ar1_log_likelihood(&r, sigma, phi);
        assert!((dense - fast).abs() < 1e-12, "{dense} vs {fast}");
        assert!(
            (ar1_log_likelihood(&r, sigma, 0.0) - gaussian_log_likelihood(&r, sigma)).abs() < 1e-12
        );
    }

    /// With zero model error it is the plain Gaussian; with a model error it
    /// is the Gaussian of the summed variance, sample by sample.
    #[test]
    fn model_error_adds_to_the_noise_variance() {
        let r = [0.3, -0.1, 0.5];
        let plain = gaussian_log_likelihood(&r, 0.4);
        let with = gaussian_log_likelihood_with_model_error(&r, 0.4, &[0.0; 3]);
        assert!((plain - with).abs() < 1e-12);
        let v = [0.09, 0.0, 0.2];
        let direct: f64 = r
            .iter()
            .zip(&v)
            .map(|(r, v)| gaussian_log_likelihood(&[*r], (0.16f64 + v).sqrt()))
            .sum();
        let got = gaussian_log_likelihood_with_model_error(&r, 0.4, &v);
        assert!((direct - got).abs() < 1e-12, "{direct} {got}");
    }
}
