//! Model evidence by thermodynamic integration over power posteriors.
//!
//! With the power posterior p_beta(x) ∝ p(x) L(x)^beta,
//!
//!   log Z = ∫_0^1 E_{p_beta}[log L] d beta
//!
//! (Friel & Pettitt 2008, "Marginal likelihood estimation via power
//! posteriors", *JRSS B* 70, eq. 5; Lartillot & Philippe 2006). The ladder
//! beta_i = (i / K)^5, i = 0..K puts most rungs near 0 where the integrand
//! changes fastest (Friel & Pettitt section 3); the integral is the
//! trapezoid rule with Friel & Pettitt's (2014, *Stat. Comput.* 24) second-
//! order correction -(dbeta^2 / 12) (V_{i+1} - V_i), V = Var_{p_beta}[log L].
//! Each rung starts from the Laplace approximation of its own power
//! posterior (found from the previous rung's mode), so the samplers' whitened
//! coordinates fit every rung. Every prior must be proper (at beta = 0 the
//! power posterior is the prior).

use super::posterior::Posterior;
use crate::mcmc::{laplace, McmcError, Sampler, Start};
use serde::{Deserialize, Serialize};

/// The thermodynamic-integration estimate and its ingredients.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThermodynamicEvidence {
    pub log_evidence: f64,
    pub betas: Vec<f64>,
    /// E[log L] at each rung.
    pub mean_log_likelihood: Vec<f64>,
    /// Var[log L] at each rung.
    pub var_log_likelihood: Vec<f64>,
    /// Log-density evaluations (Laplace starts, sampling, likelihood re-evaluations).
    pub evaluations: u64,
}

/// Thermodynamic integration with `rungs` + 1 temperatures and `sampler`
/// at each (seeded `seed + rung`), starting from `z0` (e.g. the posterior mode).
pub fn thermodynamic_integration(
    post: &Posterior,
    z0: &[f64],
    rungs: usize,
    sampler: &Sampler,
    seed: u64,
) -> Result<ThermodynamicEvidence, McmcError> {
    if !post.priors_proper() {
        return Err(McmcError::InvalidSettings {
            field: "priors".into(),
            reason: "thermodynamic integration needs a proper prior on every parameter".into(),
        });
    }
    if rungs < 2 {
        return Err(McmcError::InvalidSettings {
            field: "rungs".into(),
            reason: "need at least 2".into(),
        });
    }
    let betas: Vec<f64> = (0..=rungs)
        .rev()
        .map(|i| (i as f64 / rungs as f64).powi(5))
        .collect();
    let mut z = z0.to_vec();
    let mut means = Vec::new();
    let mut vars = Vec::new();
    let mut evaluations = 0;
    // From beta = 1 down to 0, each rung's mode starting the next search.
    for (i, &beta) in betas.iter().enumerate() {
        let tempered = post.tempered(beta);
        let lap = laplace(&tempered, &z)?;
        evaluations += lap.evaluations;
        z = lap.mode.clone();
        let d = z.len();
        let cov = nalgebra::DMatrix::from_fn(d, d, |a, b| lap.covariance[a][b]);
        let cholesky = cov.cholesky().map(|c| {
            (0..d)
                .map(|a| (0..d).map(|b| c.l()[(a, b)]).collect())
                .collect()
        });
        let start = Start {
            center: lap.mode.clone(),
            scale: lap.sd(),
            cholesky,
        };
        let run = sampler.run(&tempered, &start, seed + i as u64, None)?;
        evaluations += run.evaluations;
        let ll: Vec<f64> = run
            .chains
            .points()
            .map(|p| post.log_likelihood(&post.space().from_unbounded(p)))
            .collect();
        evaluations += ll.len() as u64;
        let n = ll.len() as f64;
        let m = ll.iter().sum::<f64>() / n;
        let v = ll.iter().map(|l| (l - m) * (l - m)).sum::<f64>() / (n - 1.0);
        means.push(m);
        vars.push(v);
    }
    // betas descend; integrate over ascending order.
    let mut log_z = 0.0;
    for i in 0..rungs {
        let (b1, b0) = (betas[i], betas[i + 1]);
        let h = b1 - b0;
        log_z += 0.5 * h * (means[i] + means[i + 1]) - h * h / 12.0 * (vars[i] - vars[i + 1]);
    }
    Ok(ThermodynamicEvidence {
        log_evidence: log_z,
        betas,
        mean_log_likelihood: means,
        var_log_likelihood: vars,
        evaluations,
    })
}
