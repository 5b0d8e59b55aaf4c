//! The posterior of a forward model's parameters given one or more data sets,
//! as a log-density in the unbounded space of palpate-core's transforms.
//!
//! With physical parameters x = x(z) (the model's parameters followed by the
//! inferred noise parameters of each data set),
//!
//!   log p(z | y) = sum_k log p_k(x_k) + log |dx/dz| + sum_s log L_s(y_s | x)  + const,
//!
//! where L_s is the Gaussian (independent or AR(1)) likelihood of data set s
//! ([`super::noise`]) and log |dx/dz| the log-Jacobian of the bound transforms
//! ([`ParamSpace::log_jacobian`]), so that a sampler moving in z draws from
//! the posterior of x. A forward-model error (a parameter the model rejects,
//! a non-converged solve) gives `-inf`: the point is rejected.

use super::noise::{
    ar1_log_likelihood, gaussian_log_likelihood, gaussian_log_likelihood_with_model_error,
    Correlation, NoiseModel, NoiseSd,
};
use super::prior::Prior;
use crate::mcmc::{fd_value_and_gradient, DensityWorker, LogDensity};
use palpate_core::{Evaluator, ForwardError, ForwardModel, Loading, ParamSpace, ParamSpec};
use palpate_inverse::Sensitivities;
use std::sync::Arc;
use thiserror::Error;

/// Why a posterior could not be set up.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum LikelihoodError {
    #[error("no data set")]
    NoData,
    #[error("data set `{name}`: {observed} observations for {samples} loading samples")]
    LengthMismatch {
        name: String,
        observed: usize,
        samples: usize,
    },
    #[error("data set `{name}`: its model has parameters {got:?}, the first data set's model has {expected:?}")]
    ParameterMismatch {
        name: String,
        expected: Vec<String>,
        got: Vec<String>,
    },
    #[error("{priors} priors given for {params} model parameters")]
    PriorCount { priors: usize, params: usize },
    #[error("prior of `{name}`: {reason}")]
    InvalidPrior { name: String, reason: String },
    #[error("data set `{name}`: {reason}")]
    InvalidNoise { name: String, reason: String },
    #[error("data set `{name}`: model-error variance: {reason}")]
    InvalidModelError { name: String, reason: String },
}

/// One data set: a model of the experiment, its loading, what was observed
/// and the noise model.
#[derive(Clone)]
pub struct DataSet {
    /// Short name, used to name its noise parameters (`sigma_<name>`).
    pub name: String,
    pub model: Arc<dyn ForwardModel>,
    pub loading: Loading,
    pub observed: Vec<f64>,
    pub noise: NoiseModel,
}

#[derive(Debug, Clone, Copy)]
struct NoiseSlots {
    sigma: Option<usize>,
    phi: Option<usize>,
}

/// The posterior of the model parameters (and inferred noise parameters).
pub struct Posterior {
    datasets: Vec<DataSet>,
    space: ParamSpace,
    priors: Vec<Prior>,
    n_model: usize,
    slots: Vec<NoiseSlots>,
    sensitivities: Vec<Option<Arc<dyn Sensitivities>>>,
    model_error: Vec<Option<Vec<f64>>>,
}

impl Posterior {
    /// A posterior from data sets whose models share one parameter space, and
    /// one prior per model parameter (noise priors are in the noise models).
    pub fn new(
        datasets: Vec<DataSet>,
        model_priors: Vec<Prior>,
    ) -> Result<Posterior, LikelihoodError> {
        let first = datasets.first().ok_or(LikelihoodError::NoData)?;
        let base = first.model.space().clone();
        if model_priors.len() != base.len() {
            return Err(LikelihoodError::PriorCount {
                priors: model_priors.len(),
                params: base.len(),
            });
        }
        let mut specs = base.params.clone();
        let mut priors = model_priors;
        for (p, spec) in priors.iter().zip(&specs) {
            p.validate()
                .map_err(|reason| LikelihoodError::InvalidPrior {
                    name: spec.name.clone(),
                    reason,
                })?;
        }
        let single = datasets.len() == 1;
        let mut slots = Vec::new();
        for ds in &datasets {
            if ds.model.space().names() != base.names() {
                return Err(LikelihoodError::ParameterMismatch {
                    name: ds.name.clone(),
                    expected: base.names(),
                    got: ds.model.space().names(),
                });
            }
            if ds.observed.len() != ds.loading.len() {
                return Err(LikelihoodError::LengthMismatch {
                    name: ds.name.clone(),
                    observed: ds.observed.len(),
                    samples: ds.loading.len(),
                });
            }
            let suffix = if single {
                String::new()
            } else {
                format!("_{}", ds.name)
            };
            let bad = |reason: String| LikelihoodError::InvalidNoise {
                name: ds.name.clone(),
                reason,
            };
            let unit = match ds.model.observable() {
                palpate_core::Observable::ForceN => "N",
                palpate_core::Observable::NominalStressMPa => "MPa",
            };
            let scale = ds
                .observed
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()))
                .max(1e-300);
            let sigma = match ds.noise.sd {
                NoiseSd::Known(s) if s.is_finite() && s > 0.0 => None,
                NoiseSd::Known(s) => {
                    return Err(bad(format!("noise SD must be positive, got {s}")))
                }
                NoiseSd::Inferred(p) => {
                    p.validate().map_err(bad)?;
                    specs.push(ParamSpec::new(
                        format!("sigma{suffix}"),
                        unit,
                        0.0,
                        f64::INFINITY,
                        0.02 * scale,
                    ));
                    priors.push(p);
                    Some(specs.len() - 1)
                }
            };
            let phi = match ds.noise.correlation {
                Correlation::Independent => None,
                Correlation::Ar1Known(f) if f > -1.0 && f < 1.0 => None,
                Correlation::Ar1Known(f) => {
                    return Err(bad(format!(
                        "AR(1) coefficient must lie in (-1, 1), got {f}"
                    )))
                }
                Correlation::Ar1Inferred(p) => {
                    p.validate().map_err(bad)?;
                    specs.push(ParamSpec::new(format!("phi{suffix}"), "1", -1.0, 1.0, 0.0));
                    priors.push(p);
                    Some(specs.len() - 1)
                }
            };
            slots.push(NoiseSlots { sigma, phi });
        }
        Ok(Posterior {
            sensitivities: vec![None; datasets.len()],
            model_error: vec![None; datasets.len()],
            n_model: base.len(),
            datasets,
            space: ParamSpace::new(specs),
            priors,
            slots,
        })
    }

    /// Exact model sensitivities for data set `s` (palpate-inverse's hook,
    /// STYLE.md 3). When every data set has them and every noise model is
    /// independent, the log-density gradient is exact (one model evaluation
    /// with its Jacobian instead of 2 d + 1 evaluations):
    ///
    ///   d log p / dz_k = (d log p_k / dx_k + dlogL / dx_k) dx_k/dz_k + d log|dx_k/dz_k| / dz_k,
    ///   dlogL / dtheta_j = sum_i r_i (d f_i / d theta_j) / sigma^2,
    ///   dlogL / dsigma = -n / sigma + sum_i r_i^2 / sigma^3.
    ///
    /// Otherwise the gradient falls back to finite differences.
    pub fn with_sensitivities(mut self, s: usize, sensitivities: Arc<dyn Sensitivities>) -> Self {
        if s < self.sensitivities.len() {
            self.sensitivities[s] = Some(sensitivities);
        }
        self
    }

    /// A known model-error variance per observation of data set `s` (e.g. a
    /// surrogate's held-out error, [`crate::surrogate::Surrogate::error_variance`]),
    /// added to the noise variance: r_i ~ N(0, sigma^2 + v_i)
    /// ([`super::noise::gaussian_log_likelihood_with_model_error`], the
    /// approximation-error model of Kaipio & Somersalo 2005, sec. 7.4).
    /// Independent noise only; the error names the data set.
    pub fn with_model_error(
        mut self,
        s: usize,
        variance: Vec<f64>,
    ) -> Result<Self, LikelihoodError> {
        let Some(ds) = self.datasets.get(s) else {
            return Err(LikelihoodError::NoData);
        };
        let bad = |reason: String| LikelihoodError::InvalidModelError {
            name: ds.name.clone(),
            reason,
        };
        if variance.len() != ds.observed.len() {
            return Err(bad(format!(
                "{} variances for {} observations",
                variance.len(),
                ds.observed.len()
            )));
        }
        if let Some(v) = variance.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(bad(format!("{v} is not a variance (finite, >= 0)")));
        }
        if !matches!(ds.noise.correlation, Correlation::Independent) {
            return Err(bad(
                "only with independent noise (no AR(1) correlation)".into()
            ));
        }
        self.model_error[s] = Some(variance);
        Ok(self)
    }

    /// The model-error variances of data set `s`, if any.
    pub fn model_error(&self, s: usize) -> Option<&[f64]> {
        self.model_error.get(s).and_then(|v| v.as_deref())
    }

    fn exact_gradient(&self) -> bool {
        self.model_error.iter().all(Option::is_none)
            && self.sensitivities.iter().all(Option::is_some)
            && self
                .datasets
                .iter()
                .all(|d| matches!(d.noise.correlation, Correlation::Independent))
    }

    /// All parameters: the model's, then each data set's inferred sigma and phi.
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// Number of model parameters (the first entries of a parameter vector).
    pub fn n_model(&self) -> usize {
        self.n_model
    }

    /// Parameter names.
    pub fn names(&self) -> Vec<String> {
        self.space.names()
    }

    /// The data sets.
    pub fn datasets(&self) -> &[DataSet] {
        &self.datasets
    }

    /// Priors of all parameters, in the order of [`Posterior::space`].
    pub fn priors(&self) -> &[Prior] {
        &self.priors
    }

    /// Whether every prior is proper (the evidence is then meaningful).
    pub fn priors_proper(&self) -> bool {
        self.priors.iter().all(Prior::is_proper)
    }

    /// Noise SD and AR(1) coefficient of data set `s` at parameters `x`.
    pub fn noise_at(&self, s: usize, x: &[f64]) -> (f64, f64) {
        let ds = &self.datasets[s];
        let sigma = match (ds.noise.sd, self.slots[s].sigma) {
            (NoiseSd::Known(v), _) => v,
            (_, Some(i)) => x[i],
            _ => f64::NAN,
        };
        let phi = match (ds.noise.correlation, self.slots[s].phi) {
            (Correlation::Ar1Known(f), _) => f,
            (_, Some(i)) => x[i],
            _ => 0.0,
        };
        (sigma, phi)
    }

    /// Model predictions of data set `s` at physical parameters `x`.
    pub fn predict(&self, s: usize, x: &[f64]) -> Result<Vec<f64>, ForwardError> {
        let ds = &self.datasets[s];
        ds.model.predict(&x[..self.n_model], &ds.loading)
    }

    /// The power posterior prior x likelihood^beta (in the unbounded space,
    /// with the log-Jacobian), used by thermodynamic integration.
    pub fn tempered(&self, beta: f64) -> Tempered<'_> {
        Tempered { post: self, beta }
    }

    /// log-likelihood of all data sets at physical `x` (`-inf` if the model fails).
    pub fn log_likelihood(&self, x: &[f64]) -> f64 {
        self.make_worker(1.0).log_likelihood(x)
    }

    fn make_worker(&self, beta: f64) -> PosteriorWorker<'_> {
        PosteriorWorker {
            beta,
            post: self,
            evaluators: self.datasets.iter().map(|d| d.model.evaluator()).collect(),
            pred: self
                .datasets
                .iter()
                .map(|d| vec![0.0; d.loading.len()])
                .collect(),
            x: vec![0.0; self.space.len()],
        }
    }
}

struct PosteriorWorker<'a> {
    beta: f64,
    post: &'a Posterior,
    evaluators: Vec<Box<dyn Evaluator + 'a>>,
    pred: Vec<Vec<f64>>,
    x: Vec<f64>,
}

impl PosteriorWorker<'_> {
    fn log_physical(&mut self, x: &[f64]) -> f64 {
        let lp = self.log_prior(x);
        if !lp.is_finite() {
            return f64::NEG_INFINITY;
        }
        lp + self.beta * self.log_likelihood(x)
    }

    fn log_prior(&self, x: &[f64]) -> f64 {
        self.post
            .priors
            .iter()
            .zip(x)
            .map(|(p, &v)| p.log_density(v))
            .sum()
    }

    fn log_likelihood(&mut self, x: &[f64]) -> f64 {
        let post = self.post;
        let mut ll = 0.0;
        for s in 0..post.datasets.len() {
            let ds = &post.datasets[s];
            let pred = &mut self.pred[s];
            if self.evaluators[s]
                .predict_into(&x[..post.n_model], &ds.loading, pred)
                .is_err()
            {
                return f64::NEG_INFINITY;
            }
            for (r, o) in pred.iter_mut().zip(&ds.observed) {
                *r = o - *r;
            }
            let (sigma, phi) = post.noise_at(s, x);
            if sigma.is_nan() || sigma <= 0.0 || phi.is_nan() || phi.abs() >= 1.0 {
                return f64::NEG_INFINITY;
            }
            ll += match (ds.noise.correlation, &post.model_error[s]) {
                (Correlation::Independent, Some(v)) => {
                    gaussian_log_likelihood_with_model_error(pred, sigma, v)
                }
                (Correlation::Independent, None) => gaussian_log_likelihood(pred, sigma),
                _ => ar1_log_likelihood(pred, sigma, phi),
            };
        }
        ll
    }
}

impl DensityWorker for PosteriorWorker<'_> {
    fn log_density(&mut self, z: &[f64]) -> f64 {
        let post = self.post;
        for (k, (p, &v)) in post.space.params.iter().zip(z).enumerate() {
            self.x[k] = p.from_unbounded(v);
            if !p.contains(self.x[k]) {
                return f64::NEG_INFINITY;
            }
        }
        let x = std::mem::take(&mut self.x);
        let lp = self.log_physical(&x) + post.space.log_jacobian(z);
        self.x = x;
        lp
    }

    fn value_and_gradient(&mut self, z: &[f64], grad: &mut [f64]) -> (f64, u64) {
        let post = self.post;
        if !post.exact_gradient() {
            return fd_value_and_gradient(&mut |z| self.log_density(z), z, grad);
        }
        let x = post.space.from_unbounded(z);
        if post
            .space
            .params
            .iter()
            .zip(&x)
            .any(|(p, &v)| !p.contains(v))
        {
            return (f64::NEG_INFINITY, 0);
        }
        let mut gx: Vec<f64> = post
            .priors
            .iter()
            .zip(&x)
            .map(|(p, &v)| p.d_log_density(v))
            .collect();
        let mut lp = self.log_prior(&x) + post.space.log_jacobian(z);
        if !lp.is_finite() {
            return (f64::NEG_INFINITY, 0);
        }
        for (s, ds) in post.datasets.iter().enumerate() {
            let Some(sens) = &post.sensitivities[s] else {
                return (f64::NEG_INFINITY, 0);
            };
            let Ok((pred, cols)) = sens.predict_with_jacobian(&x[..post.n_model], &ds.loading)
            else {
                return (f64::NEG_INFINITY, 1);
            };
            let r: Vec<f64> = ds.observed.iter().zip(&pred).map(|(o, f)| o - f).collect();
            let (sigma, _) = post.noise_at(s, &x);
            if sigma.is_nan() || sigma <= 0.0 {
                return (f64::NEG_INFINITY, 1);
            }
            lp += self.beta * gaussian_log_likelihood(&r, sigma);
            let s2 = sigma * sigma;
            for (j, col) in cols.iter().enumerate().take(post.n_model) {
                gx[j] += self.beta * r.iter().zip(col).map(|(ri, c)| ri * c).sum::<f64>() / s2;
            }
            if let Some(k) = post.slots[s].sigma {
                let ss: f64 = r.iter().map(|v| v * v).sum();
                gx[k] += self.beta * (-(r.len() as f64) / sigma + ss / (s2 * sigma));
            }
        }
        for (k, p) in post.space.params.iter().enumerate() {
            let dlogjac = match p.transform() {
                palpate_core::Transform::Identity => 0.0,
                palpate_core::Transform::LogShift | palpate_core::Transform::NegLogShift => 1.0,
                palpate_core::Transform::Logit => 1.0 - 2.0 / (1.0 + (-z[k]).exp()),
            };
            grad[k] = gx[k] * p.dx_dz(z[k]) + dlogjac;
        }
        (lp, 1)
    }
}

impl LogDensity for Posterior {
    fn dim(&self) -> usize {
        self.space.len()
    }
    fn worker(&self) -> Box<dyn DensityWorker + '_> {
        Box::new(self.make_worker(1.0))
    }
}

/// A power posterior p(x) L(x)^beta as a log-density in the unbounded space.
pub struct Tempered<'a> {
    post: &'a Posterior,
    beta: f64,
}

impl LogDensity for Tempered<'_> {
    fn dim(&self) -> usize {
        self.post.space.len()
    }
    fn worker(&self) -> Box<dyn DensityWorker + '_> {
        Box::new(self.post.make_worker(self.beta))
    }
}
