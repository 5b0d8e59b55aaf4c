//! The posterior of a forward model that states the variance of its own
//! error at each prediction, a variance that depends on the parameters (an
//! emulator whose held-out error varies along the loading, evaluated where
//! the parameters put it: R2 localisation's nodule excess, whose error
//! depends on the wheel's offset from each nodule).
//!
//! With physical parameters x = x(z) (the model's parameters followed by the
//! noise SD sigma),
//!
//!   log p(z | y) = sum_k log p_k(x_k) + g(x) + log |dx/dz|
//!                  - 1/2 sum_i [ ln(2 pi (sigma^2 + v_i(x))) + r_i(x)^2 / (sigma^2 + v_i(x)) ],
//!
//! r_i = y_i - f_i(x) the residuals, v_i(x) the model's error variance
//! ([`ErrorVariance`]), g an optional prior term over several parameters
//! (an ordering constraint, a density no [`Prior`] has), log |dx/dz| the
//! log-Jacobian of palpate-core's bound transforms
//! ([`ParamSpace::log_jacobian`]). The likelihood is
//! [`crate::likelihood::gaussian_log_likelihood_with_model_error`] (the
//! approximation-error model); [`crate::likelihood::Posterior::with_model_error`]
//! is the same with a variance fixed before sampling, this one asks the
//! model for it at every point. A model error (`Err`) or a parameter
//! outside its bounds gives `-inf`. The gradient is by finite differences
//! ([`crate::mcmc::DensityWorker`]'s default).

use crate::likelihood::{gaussian_log_likelihood_with_model_error, LikelihoodError, Prior};
use crate::mcmc::{DensityWorker, LogDensity};
use palpate_core::{Evaluator, ForwardError, ForwardModel, Loading, ParamSpace, ParamSpec};

/// A forward model that states the variance of its own error.
pub trait ErrorVariance: ForwardModel {
    /// The variance (the observable's unit squared, >= 0) of the model's
    /// error at each sample of `loading` for physical parameters `theta`,
    /// written into `out` (`out.len() == loading.len()`).
    fn error_variance_into(
        &self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError>;
}

/// A prior term over several physical parameters (the model's and sigma).
pub type JointPrior<'a> = Box<dyn Fn(&[f64]) -> f64 + Sync + 'a>;

/// The posterior of one data set under a model with its own error variance
/// and independent Gaussian noise of inferred SD (module docs).
pub struct ModelErrorPosterior<'a> {
    model: &'a dyn ErrorVariance,
    loading: Loading,
    observed: Vec<f64>,
    space: ParamSpace,
    priors: Vec<Prior>,
    joint: Option<JointPrior<'a>>,
}

impl<'a> ModelErrorPosterior<'a> {
    /// The posterior of `model`'s parameters and the noise SD given
    /// `observed` at the samples of `loading`: one prior per model
    /// parameter, and the noise SD's bounds and prior (`noise` is its
    /// parameter, last in [`Self::space`]).
    pub fn new(
        model: &'a dyn ErrorVariance,
        loading: Loading,
        observed: Vec<f64>,
        model_priors: Vec<Prior>,
        noise: ParamSpec,
        noise_prior: Prior,
    ) -> Result<Self, LikelihoodError> {
        if observed.is_empty() {
            return Err(LikelihoodError::NoData);
        }
        if observed.len() != loading.len() {
            return Err(LikelihoodError::LengthMismatch {
                name: model.name(),
                observed: observed.len(),
                samples: loading.len(),
            });
        }
        let space = model.space().extended(&[noise]);
        if model_priors.len() + 1 != space.len() {
            return Err(LikelihoodError::PriorCount {
                priors: model_priors.len(),
                params: space.len() - 1,
            });
        }
        let mut priors = model_priors;
        priors.push(noise_prior);
        for (p, spec) in priors.iter().zip(&space.params) {
            p.validate()
                .map_err(|reason| LikelihoodError::InvalidPrior {
                    name: spec.name.clone(),
                    reason,
                })?;
        }
        if let Some(bad) = space
            .params
            .last()
            .filter(|s| s.lower.is_nan() || s.lower < 0.0)
        {
            return Err(LikelihoodError::InvalidNoise {
                name: model.name(),
                reason: format!(
                    "the noise SD `{}` must be bounded below by 0 or more, got {}",
                    bad.name, bad.lower
                ),
            });
        }
        Ok(ModelErrorPosterior {
            model,
            loading,
            observed,
            space,
            priors,
            joint: None,
        })
    }

    /// Adds a prior term over several physical parameters (`-inf` where
    /// the prior is zero, e.g. a violated ordering constraint).
    pub fn with_joint_prior(mut self, g: JointPrior<'a>) -> Self {
        self.joint = Some(g);
        self
    }

    /// All parameters: the model's, then the noise SD.
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// Log prior + log-likelihood at physical parameters `x` (no
    /// Jacobian): the posterior density of x, up to the evidence.
    pub fn log_posterior_physical(&self, x: &[f64]) -> f64 {
        self.make_worker().log_physical(x)
    }

    fn make_worker(&self) -> Worker<'_, 'a> {
        let n = self.loading.len();
        Worker {
            post: self,
            evaluator: self.model.evaluator(),
            pred: vec![0.0; n],
            var: vec![0.0; n],
            x: vec![0.0; self.space.len()],
        }
    }
}

struct Worker<'p, 'a> {
    post: &'p ModelErrorPosterior<'a>,
    evaluator: Box<dyn Evaluator + 'p>,
    pred: Vec<f64>,
    var: Vec<f64>,
    x: Vec<f64>,
}

impl Worker<'_, '_> {
    fn log_physical(&mut self, x: &[f64]) -> f64 {
        let post = self.post;
        let mut lp: f64 = post
            .priors
            .iter()
            .zip(x)
            .map(|(p, &v)| p.log_density(v))
            .sum();
        if let Some(g) = &post.joint {
            lp += g(x);
        }
        if !lp.is_finite() {
            return f64::NEG_INFINITY;
        }
        let n = post.space.len() - 1;
        let (theta, sigma) = (&x[..n], x[n]);
        if sigma.is_nan()
            || sigma <= 0.0
            || self
                .evaluator
                .predict_into(theta, &post.loading, &mut self.pred)
                .is_err()
            || post
                .model
                .error_variance_into(theta, &post.loading, &mut self.var)
                .is_err()
        {
            return f64::NEG_INFINITY;
        }
        for (r, o) in self.pred.iter_mut().zip(&post.observed) {
            *r = o - *r;
        }
        lp + gaussian_log_likelihood_with_model_error(&self.pred, sigma, &self.var)
    }
}

impl DensityWorker for Worker<'_, '_> {
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
}

impl LogDensity for ModelErrorPosterior<'_> {
    fn dim(&self) -> usize {
        self.space.len()
    }
    fn worker(&self) -> Box<dyn DensityWorker + '_> {
        Box::new(self.make_worker())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_core::{Drive, Observable};

    /// f_i = a d_i, error variance (b d_i)^2 with b a second parameter.
    struct Line(ParamSpace);
    struct Eval;
    impl Evaluator for Eval {
        fn predict_into(
            &mut self,
            t: &[f64],
            l: &Loading,
            o: &mut [f64],
        ) -> Result<(), ForwardError> {
            if t[0] > 4.0 {
                return Err(ForwardError::InvalidParameter {
                    name: "a".into(),
                    value: t[0],
                    reason: "above 4".into(),
                });
            }
            for (o, d) in o.iter_mut().zip(&l.drive) {
                *o = t[0] * d;
            }
            Ok(())
        }
    }
    impl ForwardModel for Line {
        fn name(&self) -> String {
            "line".into()
        }
        fn space(&self) -> &ParamSpace {
            &self.0
        }
        fn observable(&self) -> Observable {
            Observable::ForceN
        }
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(Eval)
        }
    }
    impl ErrorVariance for Line {
        fn error_variance_into(
            &self,
            t: &[f64],
            l: &Loading,
            o: &mut [f64],
        ) -> Result<(), ForwardError> {
            for (o, d) in o.iter_mut().zip(&l.drive) {
                *o = (t[1] * d).powi(2);
            }
            Ok(())
        }
    }

    fn line() -> Line {
        Line(ParamSpace::new(vec![
            ParamSpec::new("a", "N/mm", 0.0, 5.0, 1.0),
            ParamSpec::new("b", "N/mm", 0.0, 1.0, 0.1),
        ]))
    }

    /// The density is the Gaussian of sigma^2 + v_i(x), sample by sample,
    /// plus the priors, the joint term and the transforms' Jacobian; `-inf`
    /// where the model fails or the joint prior is zero.
    #[test]
    fn density_is_the_gaussian_of_noise_plus_model_variance() {
        let m = line();
        let loading = Loading::quasi_static(Drive::PositionMm, vec![1.0, 2.0, 3.0]);
        let y = vec![1.1, 1.9, 3.3];
        let post = ModelErrorPosterior::new(
            &m,
            loading,
            y.clone(),
            vec![
                Prior::Normal { mean: 1.0, sd: 0.5 },
                Prior::Uniform {
                    lower: 0.0,
                    upper: 1.0,
                },
            ],
            ParamSpec::new("sigma", "N", 0.01, 2.0, 0.1),
            Prior::Flat,
        )
        .unwrap()
        .with_joint_prior(Box::new(|x: &[f64]| {
            if x[1] < x[2] {
                -x[1]
            } else {
                f64::NEG_INFINITY
            }
        }));
        assert_eq!(post.space().names(), ["a", "b", "sigma"]);
        let x = [1.05, 0.1, 0.2];
        let mut want = Prior::Normal { mean: 1.0, sd: 0.5 }.log_density(1.05) - 0.1;
        for (i, d) in [1.0, 2.0, 3.0].iter().enumerate() {
            let v = 0.04 + (0.1 * d) * (0.1 * d);
            let r = y[i] - 1.05 * d;
            want += -0.5 * ((2.0 * std::f64::consts::PI * v).ln() + r * r / v);
        }
        let got = post.log_posterior_physical(&x);
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        let z = post.space().to_unbounded(&x);
        let with_jac = post.worker().log_density(&z);
        assert!((with_jac - got - post.space().log_jacobian(&z)).abs() < 1e-12);
        // the joint prior's zero, and the model's failure
        assert_eq!(
            post.log_posterior_physical(&[1.05, 0.3, 0.2]),
            f64::NEG_INFINITY
        );
        assert_eq!(
            post.log_posterior_physical(&[4.5, 0.1, 0.2]),
            f64::NEG_INFINITY
        );
    }

    #[test]
    fn bad_inputs_are_named() {
        let m = line();
        let loading = Loading::quasi_static(Drive::PositionMm, vec![1.0, 2.0]);
        let sigma = ParamSpec::new("sigma", "N", 0.01, 2.0, 0.1);
        let priors = vec![Prior::Flat, Prior::Flat];
        let e = ModelErrorPosterior::new(
            &m,
            loading.clone(),
            vec![1.0],
            priors.clone(),
            sigma.clone(),
            Prior::Flat,
        )
        .err()
        .unwrap();
        assert!(matches!(e, LikelihoodError::LengthMismatch { .. }), "{e}");
        let e = ModelErrorPosterior::new(
            &m,
            loading.clone(),
            vec![1.0, 2.0],
            vec![Prior::Flat],
            sigma.clone(),
            Prior::Flat,
        )
        .err()
        .unwrap();
        assert_eq!(e.to_string(), "1 priors given for 2 model parameters");
        let e = ModelErrorPosterior::new(
            &m,
            loading,
            vec![1.0, 2.0],
            priors,
            ParamSpec::new("sigma", "N", -1.0, 2.0, 0.1),
            Prior::Flat,
        )
        .err()
        .unwrap();
        assert!(
            e.to_string().contains("`sigma` must be bounded below"),
            "{e}"
        );
    }
}
