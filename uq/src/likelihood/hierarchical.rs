//! The hierarchical (random-effects) posterior of replicates: each test
//! `i` of a material has its own parameter `theta_i`, drawn from a
//! population `N(mu, tau^2)`; the test's own fit gives `y_i` with standard
//! error `s_i` (the test-level likelihood in its normal approximation,
//! Laplace at each test's optimum). With `theta_i` integrated out exactly,
//!
//! ```text
//! y_i ~ N(mu, tau^2 + s_i^2),   mu flat,   tau ~ half-Cauchy(0, A)
//! ```
//!
//! (the normal-normal model of meta-analysis; Gelman 2006, "Prior
//! distributions for variance parameters in hierarchical models", Bayesian
//! Analysis 1(3), for the half-Cauchy prior), one such model per parameter
//! of the law, sampled in `(mu, ln tau)` with the log-Jacobian `ln tau`.
//! `mu` is the population mean of the parameter and `tau` its
//! between-test SD: on dense records `s_i` is far below the spread of the
//! `y_i`, and `tau` is then the spread of the per-test fits, with the
//! uncertainty ten tests leave on it.

use crate::mcmc::{
    sample_until_converged, summarize, Convergence, FnDensity, NutsSettings, ParamSummary, Sampler,
    Start,
};
use serde::Serialize;

/// Per-test estimates of the parameters of one law.
#[derive(Debug, Clone)]
pub struct RandomEffects {
    /// The parameters' names.
    pub names: Vec<String>,
    /// `estimates[i][j]`: test `i`'s fitted parameter `j`.
    pub estimates: Vec<Vec<f64>>,
    /// Their standard errors (same shape; finite, >= 0).
    pub standard_errors: Vec<Vec<f64>>,
    /// Scale `A_j` of the half-Cauchy prior on each `tau_j` (> 0).
    pub tau_scale: Vec<f64>,
}

/// One parameter's population: `mu`, `tau` and the spread of the estimates.
#[derive(Debug, Clone, Serialize)]
pub struct Population {
    pub name: String,
    /// Posterior of the population mean.
    pub mu: ParamSummary,
    /// Posterior of the between-test SD.
    pub tau: ParamSummary,
    /// Mean and SD (n - 1) of the per-test estimates.
    pub estimates_mean: f64,
    pub estimates_sd: f64,
    /// Mean standard error of the per-test estimates.
    pub mean_standard_error: f64,
}

/// The hierarchical posterior's summary.
#[derive(Debug, Clone, Serialize)]
pub struct HierarchicalPosterior {
    pub tests: usize,
    pub parameters: Vec<Population>,
    /// Largest R-hat of `mu` and `ln tau`, and whether the run converged
    /// (R-hat < 1.01 and bulk ESS >= 400 for every coordinate).
    pub rhat_max: f64,
    pub converged: bool,
    pub draws_per_chain: usize,
    pub chains: usize,
}

impl RandomEffects {
    /// Checks the shapes and values, naming the culprit.
    pub fn check(&self) -> Result<(), String> {
        let p = self.names.len();
        if self.estimates.len() < 2 {
            return Err(format!(
                "{} test; a between-test SD needs two tests at least",
                self.estimates.len()
            ));
        }
        if self.standard_errors.len() != self.estimates.len() || self.tau_scale.len() != p {
            return Err("estimates, standard errors and prior scales differ in shape".into());
        }
        for (i, (y, s)) in self.estimates.iter().zip(&self.standard_errors).enumerate() {
            if y.len() != p || s.len() != p {
                return Err(format!(
                    "test {i}: {} values where the law has {p}",
                    y.len()
                ));
            }
            for j in 0..p {
                if !(y[j].is_finite() && s[j].is_finite() && s[j] >= 0.0) {
                    return Err(format!(
                        "test {i}, {}: estimate {} with standard error {}: both must be finite, the error >= 0",
                        self.names[j], y[j], s[j]
                    ));
                }
            }
        }
        if let Some(j) = self
            .tau_scale
            .iter()
            .position(|a| !(a.is_finite() && *a > 0.0))
        {
            return Err(format!(
                "{}: prior scale of tau {} must be > 0",
                self.names[j], self.tau_scale[j]
            ));
        }
        Ok(())
    }

    /// log p(mu, ln tau | y) of every parameter, at `z = [mu_1, ln tau_1,
    /// mu_2, ln tau_2, ...]`, up to a constant.
    pub fn log_density(&self, z: &[f64]) -> f64 {
        let mut total = 0.0;
        for j in 0..self.names.len() {
            let (mu, log_tau) = (z[2 * j], z[2 * j + 1]);
            let tau = log_tau.exp();
            if !(mu.is_finite() && tau.is_finite() && tau > 0.0) {
                return f64::NEG_INFINITY;
            }
            let a = self.tau_scale[j];
            // half-Cauchy(0, A) on tau, with the Jacobian of tau = exp(ln tau)
            total += -(1.0 + (tau / a) * (tau / a)).ln() + log_tau;
            for (y, s) in self.estimates.iter().zip(&self.standard_errors) {
                let v = tau * tau + s[j] * s[j];
                let r = y[j] - mu;
                total += -0.5 * (v.ln() + r * r / v);
            }
        }
        total
    }

    /// Samples the posterior with NUTS until R-hat < 1.01 and bulk ESS >=
    /// 400 (or `max_draws`), from the estimates' mean and SD.
    pub fn sample(&self, seed: u64, max_draws: usize) -> Result<HierarchicalPosterior, String> {
        self.check()?;
        let p = self.names.len();
        let n = self.estimates.len() as f64;
        let column = |j: usize| -> Vec<f64> { self.estimates.iter().map(|y| y[j]).collect() };
        let mut center = Vec::with_capacity(2 * p);
        let mut scale = Vec::with_capacity(2 * p);
        let mut spread = Vec::with_capacity(p);
        for j in 0..p {
            let (m, sd) = mean_sd(&column(j));
            let se = self.standard_errors.iter().map(|s| s[j]).sum::<f64>() / n;
            // a spread of zero still gives a start: the errors, else the prior scale
            let tau0 = [sd, se, self.tau_scale[j]]
                .into_iter()
                .find(|v| *v > 0.0)
                .unwrap_or(1.0);
            center.extend([m, tau0.ln()]);
            scale.extend([tau0 / n.sqrt(), 0.3]);
            spread.push((m, sd, se));
        }
        let density = FnDensity::new(2 * p, |z: &[f64]| self.log_density(z));
        let sampler = Sampler::Nuts(NutsSettings {
            chains: 4,
            tune: 1000,
            draws: 1000,
            ..Default::default()
        });
        let start = Start {
            center,
            scale,
            cholesky: None,
        };
        let convergence = Convergence {
            max_draws: max_draws.max(1000),
            ..Default::default()
        };
        let run = sample_until_converged(
            &sampler,
            &density,
            &start,
            seed,
            &convergence,
            &|z| z.to_vec(),
            None,
            &mut |_| {},
            &mut |_, _| {},
        )
        .map_err(|e| e.to_string())?;
        let names: Vec<String> = (0..p)
            .flat_map(|j| {
                [
                    format!("mu_{}", self.names[j]),
                    format!("ln_tau_{}", self.names[j]),
                ]
            })
            .collect();
        let chains = &run.run.chains;
        let summaries = summarize(chains, &names);
        let rhat_max = summaries.iter().map(|s| s.rhat).fold(0.0, f64::max);
        // tau's own summary, from the draws of exp(ln tau)
        let parameters = (0..p)
            .map(|j| {
                let tau_chains = chains.map(|z| vec![z[2 * j + 1].exp()]);
                let mut tau = summarize(&tau_chains, &[format!("tau_{}", self.names[j])]).remove(0);
                tau.rhat = summaries[2 * j + 1].rhat;
                let (m, sd, se) = spread[j];
                Population {
                    name: self.names[j].clone(),
                    mu: summaries[2 * j].clone(),
                    tau,
                    estimates_mean: m,
                    estimates_sd: sd,
                    mean_standard_error: se,
                }
            })
            .collect();
        Ok(HierarchicalPosterior {
            tests: self.estimates.len(),
            parameters,
            rhat_max,
            converged: run.converged,
            draws_per_chain: chains.n_draws,
            chains: chains.n_chains,
        })
    }
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, var.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Twelve tests whose estimates spread with SD 0.5 around 5 (normal
    /// quantiles, so the sample SD is known), errors 0.01: tau's posterior
    /// holds the spread of the estimates, mu's SD is about tau / sqrt(n),
    /// and the chains converge.
    #[test]
    fn between_test_sd_is_the_spread_of_the_estimates() {
        // standard normal quantiles at (i + 0.5) / 12
        let z = [
            -1.7317, -1.1503, -0.8122, -0.5485, -0.3186, -0.1046, 0.1046, 0.3186, 0.5485, 0.8122,
            1.1503, 1.7317,
        ];
        let estimates: Vec<Vec<f64>> = z.iter().map(|q| vec![5.0 + 0.5 * q, 2.0]).collect();
        // the second parameter does not vary: tau near 0, mu = 2
        let re = RandomEffects {
            names: vec!["a".into(), "b".into()],
            standard_errors: vec![vec![0.01, 0.001]; estimates.len()],
            estimates,
            tau_scale: vec![5.0, 2.0],
        };
        let post = re.sample(7, 16_000).unwrap();
        assert!(post.converged && post.rhat_max < 1.01, "{post:?}");
        let a = &post.parameters[0];
        assert!((a.estimates_mean - 5.0).abs() < 1e-3, "{a:?}");
        assert!(
            a.tau.hdi_3 < a.estimates_sd && a.estimates_sd < a.tau.hdi_97,
            "{a:?}"
        );
        assert!((a.tau.mean / a.estimates_sd - 1.0).abs() < 0.2, "{a:?}");
        assert!((a.mu.mean - 5.0).abs() < 0.05, "{a:?}");
        let n = 12f64;
        assert!(
            (a.mu.sd / (a.estimates_sd / n.sqrt()) - 1.0).abs() < 0.3,
            "{a:?}"
        );
        let b = &post.parameters[1];
        assert!((b.mu.mean - 2.0).abs() < 1e-3, "{b:?}");
        assert!(b.tau.hdi_97 < 0.01, "{b:?}");
    }

    #[test]
    fn bad_input_is_named() {
        let re = |y: Vec<Vec<f64>>, s: Vec<Vec<f64>>| RandomEffects {
            names: vec!["C10".into()],
            estimates: y,
            standard_errors: s,
            tau_scale: vec![1.0],
        };
        let e = re(vec![vec![1.0]], vec![vec![0.1]]).check().unwrap_err();
        assert!(e.contains("1 test; a between-test SD needs two"), "{e}");
        let e = re(vec![vec![1.0], vec![f64::NAN]], vec![vec![0.1], vec![0.1]])
            .check()
            .unwrap_err();
        assert!(e.contains("test 1, C10"), "{e}");
        let e = re(vec![vec![1.0], vec![1.0]], vec![vec![0.1], vec![-0.1]])
            .check()
            .unwrap_err();
        assert!(e.contains("the error >= 0"), "{e}");
    }
}
