//! The forward-model trait.
//!
//! A [`ForwardModel`] is a shared, immutable, object-safe description
//! (studies hold `Box<dyn ForwardModel>`); [`ForwardModel::evaluator`] makes a
//! per-thread [`Evaluator`] that owns scratch space, factorisations and
//! history variables (STYLE.md 2). Estimators see nothing else.

use crate::{Effect, ForwardError, Loading, Observable, ParamSpace};

/// A per-thread evaluator. It may keep state between calls (a symbolic
/// factorisation, a mesh) but every call starts the loading history afresh,
/// so results do not depend on call order.
pub trait Evaluator {
    /// Predictions at each sample of `loading`, written into `out`
    /// (`out.len() == loading.len()`), for physical parameters `theta`.
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError>;
}

/// A forward model: parameters + loading history -> predicted observations.
pub trait ForwardModel: Send + Sync {
    /// A short human-readable name, e.g. `C1 compression, neo-Hookean`.
    fn name(&self) -> String;

    /// The parameters, in the order `theta` uses.
    fn space(&self) -> &ParamSpace;

    /// What the predictions are (force in N, nominal stress in MPa).
    fn observable(&self) -> Observable;

    /// A fresh evaluator for one thread.
    fn evaluator(&self) -> Box<dyn Evaluator + '_>;

    /// Effects (GAP.md) for which [`ForwardModel::enrich`] gives an enriched
    /// model. Default: none.
    fn effects(&self) -> Vec<Effect> {
        Vec::new()
    }

    /// The model with `effect` added. The enriched model's parameters are this
    /// model's parameters followed by (or, for `material_form`, replacing the
    /// law's with) the effect's own; [`ForwardModel::embed`] maps a parameter
    /// vector of this model to the enriched model's "effect off" point.
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        Err(ForwardError::InvalidConfig {
            field: "effect".into(),
            reason: format!("`{effect}` does not apply to {}", self.name()),
        })
    }

    /// For an enriched model: the parameter vector that reproduces the base
    /// model with parameters `base_theta` (the effect switched off).
    /// Default: `base_theta` followed by the initial values of the remaining
    /// parameters.
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        v.extend(
            self.space()
                .params
                .iter()
                .skip(base_theta.len())
                .map(|p| p.initial),
        );
        v
    }

    /// Whether one prediction is expensive (a nonlinear finite-element
    /// solve taking seconds rather than microseconds). Estimators may then
    /// choose cheaper strategies, e.g. the gap diagnosis cross-validates by
    /// a linearised refit instead of one refit per left-out block. A
    /// property of the model, not a timing, so that results do not depend on
    /// the machine. Default: `false`.
    fn expensive(&self) -> bool {
        false
    }

    /// Predictions for one parameter vector (convenience: makes an evaluator).
    fn predict(&self, theta: &[f64], loading: &Loading) -> Result<Vec<f64>, ForwardError> {
        let mut out = vec![0.0; loading.len()];
        self.evaluator().predict_into(theta, loading, &mut out)?;
        Ok(out)
    }
}

/// Conveniences on any forward model.
pub trait ModelExt: ForwardModel {
    /// Finite-difference sensitivities d prediction / d theta (central
    /// differences with a relative step), column-major: `jac[j][i]` is
    /// d out_i / d theta_j. Steps stay inside the bounds (one-sided there).
    fn fd_jacobian(&self, theta: &[f64], loading: &Loading) -> Result<Vec<Vec<f64>>, ForwardError> {
        let mut ev = self.evaluator();
        let n = loading.len();
        let mut plus = vec![0.0; n];
        let mut minus = vec![0.0; n];
        let mut cols = Vec::with_capacity(theta.len());
        for (j, spec) in self.space().params.iter().enumerate() {
            let h = 1e-6 * theta[j].abs().max(1e-3 * spec.initial.abs()).max(1e-12);
            let mut tp = theta.to_vec();
            let mut tm = theta.to_vec();
            let (up, down) = (theta[j] + h <= spec.upper, theta[j] - h >= spec.lower);
            if up {
                tp[j] += h;
            }
            if down {
                tm[j] -= h;
            }
            ev.predict_into(&tp, loading, &mut plus)?;
            ev.predict_into(&tm, loading, &mut minus)?;
            let span = tp[j] - tm[j];
            cols.push(
                plus.iter()
                    .zip(&minus)
                    .map(|(a, b)| (a - b) / span)
                    .collect(),
            );
        }
        Ok(cols)
    }
}

impl<T: ForwardModel + ?Sized> ModelExt for T {}
