//! The hierarchical posterior of replicates (`palpate sample
//! --hierarchical`): each record fitted alone, then the population mean and
//! the between-test SD of each parameter sampled over those fits.

use super::{analyse, sig4, Replicates};
use crate::model::calibration::{calibrate, Request};
use crate::records::TestData;
use anyhow::Context;
use palpate_material::Law;
use palpate_uq::likelihood::{HierarchicalPosterior, RandomEffects};

/// The hierarchical posterior of replicates' parameters: each record
/// fitted alone, then the population mean `mu` and between-test SD `tau`
/// of each parameter sampled ([`RandomEffects`]; prior scale of `tau`: the
/// largest |estimate| of the parameter).
pub fn hierarchical(
    law: Law,
    records: &[TestData],
    seed: u64,
    max_draws: usize,
) -> anyhow::Result<(Replicates, HierarchicalPosterior)> {
    let fitted = |fitted: &[TestData]| calibrate(Request::least_squares(law, fitted));
    let pooled = fitted(records).context("the pooled fit")?;
    let reps = analyse(law, records, &pooled)?;
    let estimates: Vec<Vec<f64>> = reps.fits.iter().map(|f| f.values.clone()).collect();
    let standard_errors: Vec<Vec<f64>> = reps
        .fits
        .iter()
        .map(|f| f.standard_errors.iter().map(|s| s.unwrap_or(0.0)).collect())
        .collect();
    let tau_scale = (0..reps.names.len())
        .map(|j| {
            estimates
                .iter()
                .map(|y| y[j].abs())
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE)
        })
        .collect();
    let model = RandomEffects {
        names: reps.names.clone(),
        estimates,
        standard_errors,
        tau_scale,
    };
    let post = model
        .sample(seed, max_draws)
        .map_err(|e| anyhow::anyhow!("the hierarchical posterior: {e}"))?;
    Ok((reps, post))
}

/// The hierarchical posterior as a table: per parameter the population
/// mean and between-test SD (posterior mean, 94 % HDI, R-hat) beside the
/// per-record fits' mean and SD.
pub fn hierarchical_table(law: Law, post: &HierarchicalPosterior) -> String {
    let mut out = format!(
        "\nhierarchical posterior of {law} over {} records (theta_i ~ N(mu, tau^2); each record's fit with its standard error):\n",
        post.tests
    );
    out.push_str(&format!(
        "{:<10} {:>12} {:>25} {:>12} {:>25} {:>12} {:>12} {:>8}\n",
        "parameter", "mu", "mu 94% HDI", "tau", "tau 94% HDI", "fits mean", "fits SD", "R-hat"
    ));
    for p in &post.parameters {
        out.push_str(&format!(
            "{:<10} {:>12} {:>25} {:>12} {:>25} {:>12} {:>12} {:>8.4}\n",
            p.name,
            sig4(p.mu.mean),
            format!("[{}, {}]", sig4(p.mu.hdi_3), sig4(p.mu.hdi_97)),
            sig4(p.tau.mean),
            format!("[{}, {}]", sig4(p.tau.hdi_3), sig4(p.tau.hdi_97)),
            sig4(p.estimates_mean),
            sig4(p.estimates_sd),
            p.mu.rhat.max(p.tau.rhat)
        ));
    }
    out.push_str(&format!(
        "{} chains x {} draws, max R-hat {:.4}{}\n",
        post.chains,
        post.draws_per_chain,
        post.rhat_max,
        if post.converged {
            ""
        } else {
            " (NOT CONVERGED: the cap of draws was reached)"
        }
    ));
    out
}
