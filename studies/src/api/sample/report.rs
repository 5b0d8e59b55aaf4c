//! The summary of a sampled posterior: the table `palpate sample` prints
//! and the JSON its `--json` writes.

use palpate_uq::likelihood::{Posterior, PosteriorStart};
use palpate_uq::mcmc::{Chains, ConvergedRun, ParamSummary, SampleRun};
use serde_json::{json, Map, Value};

use super::SampleOptions;

/// What [`table`] shows.
pub(super) struct TableInput<'a> {
    pub options: &'a SampleOptions,
    pub post: &'a Posterior,
    pub converged: &'a ConvergedRun,
    /// The draws in physical units.
    pub chains: &'a Chains,
    pub summary: &'a [ParamSummary],
    pub correlation: &'a [Vec<f64>],
    pub laplace_mean: &'a [f64],
    pub laplace_sd: &'a [f64],
}

/// The table of the posterior: the run, one line per parameter (mean, SD,
/// 94 % HDI, R-hat, ESS, the Laplace approximation), the AR(1)
/// coefficients with `ar1`, the correlation matrix.
pub(super) fn table(t: &TableInput) -> String {
    use std::fmt::Write;
    let (post, x, names) = (t.post, t.chains, t.post.names());
    let mut s = String::new();
    let c = t.converged;
    let _ = writeln!(
        s,
        "{} on {} ({} chains x {} draws, {} evaluations, {:.2} s{})",
        c.run.sampler,
        post.datasets()[0].model.name(),
        x.n_chains,
        x.n_draws,
        c.evaluations,
        c.wall_time_s,
        if c.history.len() > 1 {
            format!(", {} runs to converge", c.history.len())
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        s,
        "{:<10} {:>12} {:>11} {:>12} {:>12} {:>7} {:>8} {:>8} {:>12} {:>11}",
        "param",
        "mean",
        "sd",
        "hdi_3%",
        "hdi_97%",
        "r_hat",
        "ess_bulk",
        "ess_tail",
        "laplace",
        "laplace_sd"
    );
    let (lap_mean, lap_sd) = (t.laplace_mean, t.laplace_sd);
    for (k, p) in t.summary.iter().enumerate() {
        let _ = writeln!(
            s,
            "{:<10} {:>12.5e} {:>11.3e} {:>12.5e} {:>12.5e} {:>7.4} {:>8.0} {:>8.0} {:>12.5e} {:>11.3e}",
            p.name, p.mean, p.sd, p.hdi_3, p.hdi_97, p.rhat, p.ess_bulk, p.ess_tail, lap_mean[k], lap_sd[k]
        );
    }
    if t.options.ar1 {
        // The AR(1) coefficient of each data set: the correlation of
        // successive residuals, and the SD of the innovations it leaves.
        for (k, p) in t.summary.iter().enumerate() {
            let Some(set) = p.name.strip_prefix("phi") else {
                continue;
            };
            let set = set.strip_prefix('_').unwrap_or(&post.datasets()[0].name);
            let sigma = names
                .iter()
                .position(|n| n == &format!("sigma{}", &p.name[3..]))
                .map(|j| lap_mean[j])
                .or(t.options.sigma);
            // Near 1, the distance to 1 is what tells values apart.
            let shown = |v: f64| {
                if v > 0.999 {
                    format!("1 - {:.3e}", 1.0 - v)
                } else {
                    format!("{v:.4}")
                }
            };
            let phi = lap_mean[k];
            let _ = writeln!(
                s,
                "between-sample correlation of `{set}` (AR(1) phi): {} [{}, {}]{}",
                shown(p.mean),
                shown(p.hdi_3),
                shown(p.hdi_97),
                match sigma {
                    Some(sd) => format!(
                        "; innovation SD sigma sqrt(1 - phi^2) {} at the Laplace mode",
                        crate::steps::replicates::sig4(sd * (1.0 - phi * phi).max(0.0).sqrt())
                    ),
                    None => String::new(),
                }
            );
        }
    }
    if names.len() > 1 {
        s.push_str("posterior correlation:\n");
        for (i, row) in t.correlation.iter().enumerate() {
            let cells: Vec<String> = row.iter().map(|c| format!("{c:>7.3}")).collect();
            let _ = writeln!(s, "  {:<10}{}", names[i], cells.join(" "));
        }
    }
    s
}

/// The summary `--json` writes (without the convergence, surrogate and
/// evidence sections, which [`super::run`] adds).
#[allow(clippy::too_many_arguments)]
pub(super) fn json(
    o: &SampleOptions,
    post: &Posterior,
    run: &SampleRun,
    summary: &[ParamSummary],
    corr: &[Vec<f64>],
    lap_mean: &[f64],
    lap_sd: &[f64],
    start: &PosteriorStart,
) -> Value {
    let mut params = Map::new();
    let x = run.chains.map(|z| post.space().from_unbounded(z));
    for (k, s) in summary.iter().enumerate() {
        let spec = &post.space().params[k];
        let iat = palpate_uq::mcmc::diagnostics::integrated_autocorrelation_time(&x.param(k));
        params.insert(
            s.name.clone(),
            json!({
                "unit": spec.unit,
                "prior": post.priors()[k].to_string(),
                "mean": s.mean, "sd": s.sd, "hdi_3": s.hdi_3, "hdi_97": s.hdi_97,
                "rhat": s.rhat, "ess_bulk": s.ess_bulk, "ess_tail": s.ess_tail, "mcse_mean": s.mcse_mean,
                "laplace_mean": lap_mean[k], "laplace_sd": lap_sd[k],
                "autocorrelation_time": iat,
            }),
        );
    }
    json!({
        "law": o.law,
        "experiment": o.experiment,
        "model": post.datasets()[0].model.name(),
        "data": o.data,
        "sampler": run.sampler,
        "seed": o.seed,
        "chains": run.chains.n_chains,
        "draws_per_chain": run.chains.n_draws,
        "params": params,
        "correlation": { "names": post.names(), "matrix": corr },
        "evaluations": run.evaluations,
        "wall_time_s": run.wall_time_s,
        "acceptance_mean": run.acceptance.iter().sum::<f64>() / run.acceptance.len().max(1) as f64,
        "acceptance": run.acceptance,
        "divergences": run.divergences,
        "step_size": run.step_size,
        "laplace": {
            "log_evidence": start.laplace.log_evidence,
            "evidence_meaningful": post.priors_proper(),
            "note": "Laplace estimate of log p(data); comparable between models only with proper priors on every parameter",
        },
        "least_squares": start.fit.parameters.iter().map(|p| json!({
            "name": p.name, "value": p.value, "standard_error": p.standard_error,
        })).collect::<Vec<_>>(),
    })
}
