//! Where a posterior run starts: a least-squares fit (palpate-inverse's
//! Levenberg-Marquardt), then the Laplace approximation around the posterior
//! mode, whose mode and standard deviations seed the chains.

use super::noise::{Correlation, NoiseSd};
use super::posterior::Posterior;
use crate::mcmc::{laplace, Laplace, McmcError, Start};
use palpate_inverse::{
    fit, DataSet as FitSet, FitOptions, FitReport, InverseError, Objective, ResidualKind,
};
use thiserror::Error;

/// Why the start could not be found.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum StartError {
    #[error("least-squares fit: {0}")]
    Fit(#[from] InverseError),
    #[error(transparent)]
    Laplace(#[from] McmcError),
    /// The least-squares value of a parameter lies outside its prior's
    /// support and the posterior mode sits on the prior's edge.
    #[error("the least-squares fit gives {name} = {value:.4e}, outside the support [{lo}, {hi}] of its prior {prior}; the posterior piles up at the prior's edge ({laplace}): widen the prior to contain the data's value, or check its units")]
    OutsidePrior {
        name: String,
        value: f64,
        lo: f64,
        hi: f64,
        prior: String,
        laplace: McmcError,
    },
}

/// The least-squares fit, the Laplace approximation of the posterior and the
/// chains' start derived from it.
#[derive(Debug, Clone)]
pub struct PosteriorStart {
    /// The least-squares fit (weights 1 / sigma for known noise SDs); its
    /// standard errors are the Gauss-Newton Laplace approximation
    /// sigma^2 (J^T J)^-1 of the model parameters.
    pub fit: FitReport,
    /// Physical starting vector: fitted model parameters, then each inferred
    /// sigma (RMS residual) and phi (lag-1 residual autocorrelation).
    pub theta: Vec<f64>,
    /// Laplace approximation of the full posterior in the unbounded space.
    pub laplace: Laplace,
    /// Start for the samplers: the Laplace mode and SDs.
    pub start: Start,
}

impl PosteriorStart {
    /// Laplace mean and SD of every parameter in physical units (delta
    /// method through the bound transforms: x(z*), |dx/dz| sd_z).
    pub fn laplace_physical(&self, post: &Posterior) -> (Vec<f64>, Vec<f64>) {
        let sd = self.laplace.sd();
        let mut mean = Vec::new();
        let mut sdx = Vec::new();
        for (k, p) in post.space().params.iter().enumerate() {
            let z = self.laplace.mode[k];
            mean.push(p.from_unbounded(z));
            sdx.push(p.dx_dz(z).abs() * sd[k]);
        }
        (mean, sdx)
    }
}

/// Fits, then builds the Laplace approximation of `post` at its mode.
pub fn fit_and_laplace(post: &Posterior) -> Result<PosteriorStart, StartError> {
    let sets: Vec<FitSet> = post
        .datasets()
        .iter()
        .map(|d| {
            let w = match d.noise.sd {
                NoiseSd::Known(s) => 1.0 / s,
                NoiseSd::Inferred(_) => 1.0,
            };
            FitSet::new(
                d.name.clone(),
                d.model.clone(),
                d.loading.clone(),
                d.observed.clone(),
            )
            .with_weight(w)
        })
        .collect();
    let objective = Objective::new(sets, ResidualKind::Absolute, &[])?;
    let report = fit(&objective, &FitOptions::default())?;
    // A fitted value on a bound maps to an infinite unbounded coordinate, so
    // restart such a parameter inside the bounds, a hundredth of the way
    // from the bound to its initial value (the posterior mode in the
    // unbounded space lies inside, where the log-Jacobian balances the fit).
    let mut theta: Vec<f64> = report
        .parameters
        .iter()
        .zip(&post.space().params)
        .map(|(p, spec)| match p.at_bound {
            Some(palpate_inverse::BoundSide::Lower) => {
                spec.lower + 0.01 * (spec.initial - spec.lower)
            }
            Some(palpate_inverse::BoundSide::Upper) => {
                spec.upper - 0.01 * (spec.upper - spec.initial)
            }
            None => p.value,
        })
        .collect();
    // The fit ignores the priors: a value outside a prior's support (a
    // uniform prior that excludes the least-squares value) starts just
    // inside it, where the log-density is finite.
    let mut outside = None;
    for (k, (x, prior)) in theta.iter_mut().zip(post.priors()).enumerate() {
        let y = prior.nearest_inside(*x);
        if y != *x && outside.is_none() {
            outside = Some((k, *x, *prior));
        }
        *x = y;
    }
    for (s, d) in post.datasets().iter().enumerate() {
        let r = &report.sets[s].residuals;
        if let NoiseSd::Inferred(_) = d.noise.sd {
            let rms = (r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64).sqrt();
            theta.push(rms.max(1e-12));
        }
        if let Correlation::Ar1Inferred(_) = d.noise.correlation {
            let num: f64 = r.windows(2).map(|w| w[0] * w[1]).sum();
            let den: f64 = r.iter().map(|v| v * v).sum::<f64>().max(1e-300);
            theta.push((num / den).clamp(-0.9, 0.9));
        }
    }
    let z0 = post.space().to_unbounded(&theta);
    let lap = match (laplace(post, &z0), outside) {
        (Ok(l), _) => l,
        (Err(e), Some((k, value, prior))) => {
            let (lo, hi) = prior.support();
            return Err(StartError::OutsidePrior {
                name: post.space().params[k].name.clone(),
                value,
                lo,
                hi,
                prior: prior.to_string(),
                laplace: e,
            });
        }
        (Err(e), None) => return Err(e.into()),
    };
    let d = lap.mode.len();
    let cov = nalgebra::DMatrix::from_fn(d, d, |i, j| lap.covariance[i][j]);
    let cholesky = cov.cholesky().map(|c| {
        (0..d)
            .map(|i| (0..d).map(|j| c.l()[(i, j)]).collect())
            .collect()
    });
    let start = Start {
        center: lap.mode.clone(),
        scale: lap.sd(),
        cholesky,
    };
    Ok(PosteriorStart {
        fit: report,
        theta,
        laplace: lap,
        start,
    })
}
