//! Residual arithmetic shared by the stages of the diagnosis, and the AR(1)
//! deviance behind the approximate information criteria.

use super::structure::lag1;

/// Root mean square (0 for an empty slice).
pub(crate) fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// y - f, element-wise.
pub(crate) fn residuals(observed: &[f64], predicted: &[f64]) -> Vec<f64> {
    observed.iter().zip(predicted).map(|(y, f)| y - f).collect()
}

/// Sum of squares.
pub(crate) fn sse(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// -2 log-likelihood of residuals `r` under AR(1) Gaussian errors, the
/// exact likelihood of a stationary AR(1) (Box & Jenkins) evaluated at the
/// lag-1 sample autocorrelation rho (clipped to +-0.99, a moment estimate,
/// not the maximum-likelihood one, so the AIC/BIC built on it are
/// approximate; they only break ties in the ranking) and the innovation
/// variance: e_0 = sqrt(1 - rho^2) r_0,
/// e_i = r_i - rho r_{i-1}, -2 log L = n ln(2 pi s^2) + n - ln(1 - rho^2),
/// s^2 = sum e^2 / n. A misfit that is smooth (rho near 1) is partly absorbed by
/// the correlation, so an extra parameter must remove more than what the
/// correlation already explains.
pub(crate) fn ar1_deviance(r: &[f64]) -> f64 {
    let n = r.len() as f64;
    let rho = lag1(r).clamp(-0.99, 0.99);
    let c = (1.0 - rho * rho).sqrt();
    let mut ss = (c * r[0]).powi(2);
    for w in r.windows(2) {
        ss += (w[1] - rho * w[0]).powi(2);
    }
    let s2 = (ss / n).max(f64::MIN_POSITIVE);
    n * (2.0 * std::f64::consts::PI * s2).ln() + n - (1.0 - rho * rho).ln()
}
