//! The forward-model trait.
//!
//! A [`ForwardModel`] is a shared, immutable, object-safe description
//! (studies hold `Box<dyn ForwardModel>`); [`ForwardModel::evaluator`] makes a
//! per-thread [`Evaluator`] that owns scratch space, factorisations and
//! history variables (STYLE.md 2). Estimators see nothing else.
//!
//! A model predicts one or more [`Output`]s at each sample (e.g. the vertical
//! and the horizontal force on a wheel). [`Evaluator::predict_into`] gives the
//! first, which is all a one-output consumer (estimators, studies, the gap
//! diagnosis) sees; [`Evaluator::predict_outputs_into`] gives every output,
//! samples x outputs, row-major.
//!
//! ```
//! use palpate_core::{Drive, Evaluator, ForwardError, ForwardModel, Loading};
//! use palpate_core::{Observable, Output, ParamSpace, ParamSpec};
//!
//! /// A spring pushed down at 30 degrees from the vertical: the vertical
//! /// force along the drive and the horizontal force.
//! struct Slanted(ParamSpace);
//! struct Eval;
//! impl Evaluator for Eval {
//!     /// The first output only.
//!     fn predict_into(&mut self, t: &[f64], l: &Loading, o: &mut [f64]) -> Result<(), ForwardError> {
//!         for (o, d) in o.iter_mut().zip(&l.drive) { *o = t[0] * d; }
//!         Ok(())
//!     }
//!     /// Both outputs, one row per sample.
//!     fn predict_outputs_into(&mut self, t: &[f64], l: &Loading, o: &mut [f64]) -> Result<(), ForwardError> {
//!         palpate_core::check_output_slots(o.len(), l.len(), 2)?;
//!         for (row, d) in o.chunks_mut(2).zip(&l.drive) {
//!             row[0] = t[0] * d;
//!             row[1] = t[0] * d * 30f64.to_radians().tan();
//!         }
//!         Ok(())
//!     }
//! }
//! impl ForwardModel for Slanted {
//!     fn name(&self) -> String { "slanted spring".into() }
//!     fn space(&self) -> &ParamSpace { &self.0 }
//!     fn observable(&self) -> Observable { Observable::ForceN }
//!     fn outputs(&self) -> Vec<Output> {
//!         vec![Output::new("force_N", Observable::ForceN), Output::new("force_x_N", Observable::ForceN)]
//!     }
//!     fn evaluator(&self) -> Box<dyn Evaluator + '_> { Box::new(Eval) }
//! }
//!
//! let m = Slanted(ParamSpace::new(vec![ParamSpec::new("k", "N/mm", 0.0, 10.0, 1.0)]));
//! let loading = Loading::quasi_static(Drive::DisplacementMm, vec![1.0, 2.0]);
//! // One column per output ...
//! let columns = m.predict_outputs(&[3.0], &loading)?;
//! assert_eq!(columns.len(), 2);
//! assert_eq!(columns[0], [3.0, 6.0]);
//! assert!((columns[1][1] - 6.0 / 3f64.sqrt()).abs() < 1e-12);
//! // ... the first is what every one-output consumer sees ...
//! assert_eq!(m.predict(&[3.0], &loading)?, columns[0]);
//! // ... and the evaluator writes one row per sample.
//! let mut rows = [0.0; 4];
//! m.evaluator().predict_outputs_into(&[3.0], &loading, &mut rows)?;
//! assert_eq!([rows[0], rows[2]], [3.0, 6.0]);
//! assert!(m.evaluator().predict_outputs_into(&[3.0], &loading, &mut [0.0; 3]).is_err());
//! # Ok::<(), ForwardError>(())
//! ```
//!
//! A model with one output implements neither `outputs` nor
//! `predict_outputs_into`: the defaults give one output named by its
//! [`Observable`], and its `predict_into`.

use crate::fd::{fd_jacobian, FdRule};
use crate::{Enrichable, ForwardError, Loading, Observable, Output, ParamSpace, Sensitivities};

/// A per-thread evaluator. It may keep state between calls (a symbolic
/// factorisation, a mesh) but every call starts the loading history afresh,
/// so results do not depend on call order.
pub trait Evaluator {
    /// Predictions at each sample of `loading`, written into `out`
    /// (`out.len() == loading.len()`), for physical parameters `theta`.
    /// For a model with several outputs, the first ([`Output`]).
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError>;

    /// Every output ([`ForwardModel::outputs`]) at each sample of `loading`,
    /// samples x outputs, row-major: output `j` at sample `i` is
    /// `out[i * outputs + j]` (`out.len() == loading.len() * outputs`). The
    /// first column equals [`Evaluator::predict_into`]. A
    /// [`ForwardError::NotConverged`] from here carries the converged rows
    /// (samples x outputs) in `completed`.
    ///
    /// Default: for one output (`out.len() == loading.len()`),
    /// [`Evaluator::predict_into`]; otherwise an error saying that the model
    /// must implement this method. A model with more than one output, and a
    /// wrapper around one, implements it.
    fn predict_outputs_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        if out.len() == loading.len() {
            return self.predict_into(theta, loading, out);
        }
        Err(ForwardError::InvalidLoading(format!(
            "output has {} slots for {} samples: a model with more than one \
             output must implement Evaluator::predict_outputs_into",
            out.len(),
            loading.len()
        )))
    }
}

/// Checks that `out_len` slots hold `samples` x `outputs` values, with an
/// error naming the three numbers (for implementations of
/// [`Evaluator::predict_outputs_into`]).
pub fn check_output_slots(
    out_len: usize,
    samples: usize,
    outputs: usize,
) -> Result<(), ForwardError> {
    if out_len == samples * outputs {
        Ok(())
    } else {
        Err(ForwardError::InvalidLoading(format!(
            "output has {out_len} slots for {samples} samples x {outputs} outputs"
        )))
    }
}

/// A forward model: parameters + loading history -> predicted observations.
pub trait ForwardModel: Send + Sync {
    /// A short human-readable name, e.g. `C1 compression, neo-Hookean`.
    fn name(&self) -> String;

    /// The parameters, in the order `theta` uses.
    fn space(&self) -> &ParamSpace;

    /// What the predictions are (force in N, nominal stress in MPa); for a
    /// model with several outputs, what the first is.
    fn observable(&self) -> Observable;

    /// What the model predicts at each sample, in the order of
    /// [`Evaluator::predict_outputs_into`]; never empty, and the first has
    /// [`ForwardModel::observable`] (the conventions are at [`Output`]).
    /// Default: one output, named by [`Observable::column`]. A wrapper
    /// passes on the wrapped model's.
    fn outputs(&self) -> Vec<Output> {
        vec![Output::from(self.observable())]
    }

    /// A fresh evaluator for one thread.
    fn evaluator(&self) -> Box<dyn Evaluator + '_>;

    /// The [`Enrichable`] capability (effects for the gap diagnosis), when
    /// the model has it. Default: `None`; a model that implements
    /// [`Enrichable`] returns `Some(self)`.
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        None
    }

    /// The [`Sensitivities`] capability (exact derivatives of the
    /// predictions with respect to the parameters), when the model has it.
    /// Default: `None`, and estimators difference the model; a wrapper
    /// that changes the predictions must not pass on the wrapped model's.
    fn as_sensitivities(&self) -> Option<&dyn Sensitivities> {
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

    /// Every output for one parameter vector (convenience: makes an
    /// evaluator), one column per output in the order of
    /// [`ForwardModel::outputs`]: `columns[j][i]` is output `j` at sample
    /// `i`, and `columns[0]` equals [`ForwardModel::predict`].
    fn predict_outputs(
        &self,
        theta: &[f64],
        loading: &Loading,
    ) -> Result<Vec<Vec<f64>>, ForwardError> {
        let (n, k) = (loading.len(), self.outputs().len());
        let mut rows = vec![0.0; n * k];
        self.evaluator()
            .predict_outputs_into(theta, loading, &mut rows)?;
        Ok((0..k)
            .map(|j| (0..n).map(|i| rows[i * k + j]).collect())
            .collect())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Drive, ParamSpec};

    struct Spring(ParamSpace);
    struct Eval;
    impl Evaluator for Eval {
        fn predict_into(
            &mut self,
            t: &[f64],
            l: &Loading,
            o: &mut [f64],
        ) -> Result<(), ForwardError> {
            for (o, d) in o.iter_mut().zip(&l.drive) {
                *o = t[0] * d;
            }
            Ok(())
        }
    }
    impl ForwardModel for Spring {
        fn name(&self) -> String {
            "spring".into()
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

    /// A one-output model implements neither `outputs` nor
    /// `predict_outputs_into` and has both.
    #[test]
    fn one_output_models_get_the_defaults() {
        let m = Spring(ParamSpace::new(vec![ParamSpec::new(
            "k", "N/mm", 0.0, 10.0, 1.0,
        )]));
        assert_eq!(m.outputs(), [Output::new("force_N", Observable::ForceN)]);
        let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.5, 1.0, 2.0]);
        let columns = m.predict_outputs(&[2.0], &loading).unwrap();
        assert_eq!(columns, [m.predict(&[2.0], &loading).unwrap()]);
        let err = m
            .evaluator()
            .predict_outputs_into(&[2.0], &loading, &mut [0.0; 6])
            .unwrap_err();
        assert!(
            err.to_string().contains("6 slots for 3 samples")
                && err.to_string().contains("must implement"),
            "{err}"
        );
        assert!(check_output_slots(6, 3, 2).is_ok());
        assert!(check_output_slots(5, 3, 2)
            .unwrap_err()
            .to_string()
            .contains("5 slots for 3 samples x 2 outputs"));
    }
}
