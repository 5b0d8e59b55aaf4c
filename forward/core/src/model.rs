//! The forward-model trait.
//!
//! A [`ForwardModel`] is a shared, immutable, object-safe description
//! (studies hold `Box<dyn ForwardModel>`); [`ForwardModel::evaluator`] makes a
//! per-thread [`Evaluator`] that owns scratch space, factorisations and
//! history variables (STYLE.md 2). Estimators see nothing else.

use crate::fd::{fd_jacobian, FdRule};
use crate::{Enrichable, ForwardError, Loading, Observable, ParamSpace};

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

    /// The [`Enrichable`] capability (effects for the gap diagnosis), when
    /// the model has it. Default: `None`; a model that implements
    /// [`Enrichable`] returns `Some(self)`.
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        None
    }

    /// Whether one prediction is expensive (a nonlinear finite-element
    /// solve taking seconds rather than microseconds). Estimators may then
    /// choose cheaper strategies, e.g. the gap diagnosis cross-validates by
    /// a linearised refit instead of one refit per left-out block. A
    /// property of the model, not a timing, so that results do not depend on
    /// the machine. Default: `false`.
    ///
    /// This stays on the base trait (unlike [`Enrichable`]) because it is a
    /// hint every estimator may read, about any model, and wrappers must
    /// forward it: it is a property of cost, not an optional capability with
    /// methods of its own.
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
    /// Finite-difference sensitivities d prediction / d theta by
    /// [`crate::fd`] with `rule` (steps relative to
    /// [`crate::fd::param_scale`], kept inside the bounds, one-sided there),
    /// column-major: `jac[j][i]` is d out_i / d theta_j.
    fn fd_jacobian(
        &self,
        theta: &[f64],
        loading: &Loading,
        rule: &FdRule,
    ) -> Result<Vec<Vec<f64>>, ForwardError> {
        self.space().check(theta)?;
        let mut ev = self.evaluator();
        let steps: Vec<_> = self
            .space()
            .params
            .iter()
            .zip(theta)
            .map(|(spec, &x)| rule.param_step(spec, x))
            .collect();
        let mut f = |t: &[f64], out: &mut [f64]| ev.predict_into(t, loading, out);
        Ok(fd_jacobian(&mut f, theta, &steps, None, loading.len())?.0)
    }
}

impl<T: ForwardModel + ?Sized> ModelExt for T {}
