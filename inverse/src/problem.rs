//! The argmin adapter around an [`Objective`] (STYLE.md 10).
//!
//! argmin asks for the cost and then the gradient (or residuals and then the
//! Jacobian) in separate calls with the same parameter vector; the adapter
//! remembers the last vector and its residuals so they are computed once.
//!
//! With exact sensitivities (every data set has them) an evaluation is
//! either a plain run (residuals only) or a run with sensitivities that
//! gives the residuals and the Jacobian together
//! ([`crate::jacobian::residuals_and_exact_jacobian`]); which one, the
//! solver says before it evaluates a new point
//! ([`EvaluationCount::jacobian_with_residuals`]: by default, with). The
//! Jacobian of the last run with sensitivities is kept with its
//! predictions, so a Jacobian asked for at that point costs no run, nor do
//! the statistics at an optimum that was evaluated with sensitivities
//! ([`LeastSquaresProblem::take_exact`]). A run with sensitivities costs
//! more than a plain one (a tangent factorisation and a few assemblies per
//! increment), so a trial point the solver will probably reject is better
//! evaluated plain. [`LeastSquaresProblem::evaluations`] counts runs of
//! both kinds, [`LeastSquaresProblem::runs`] each kind.

use crate::jacobian::finite_difference_jacobian;
use crate::jacobian::{residuals_and_exact_jacobian, ExactEvaluation};
use crate::{sum_of_squares, Evaluators, FdOptions, InverseError, Objective};
use argmin::core::{CostFunction, Error, Gradient, Jacobian, Operator};
use nalgebra::DMatrix;
use std::cell::{Cell, RefCell};

/// Something that knows how many objective evaluations it has made (the
/// Levenberg-Marquardt solver's evaluation budget reads it).
pub trait EvaluationCount {
    /// Objective evaluations so far, finite-difference ones included.
    fn evaluations(&self) -> usize;

    /// Whether the evaluations of new points from now on should also
    /// compute the Jacobian there, where the two come cheaper together than
    /// apart (exact sensitivities). A hint: the default ignores it.
    fn jacobian_with_residuals(&self, _wanted: bool) {}

    /// The model's parameters at the solver's unknowns `z`, for messages
    /// (default: `z` itself).
    fn point(&self, z: &[f64]) -> Vec<f64> {
        z.to_vec()
    }
}

/// Forward runs of an objective with exact sensitivities, by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Runs {
    /// Runs for the residuals only.
    pub plain: usize,
    /// Runs that also gave the Jacobian.
    pub with_sensitivities: usize,
}

/// Residuals, SSE, gradient and Jacobian of an objective in the free
/// unbounded parameters `z`, for argmin.
pub struct LeastSquaresProblem<'a> {
    objective: &'a Objective,
    fd: FdOptions,
    evaluators: RefCell<Evaluators<'a>>,
    evaluations: Cell<usize>,
    jacobians: Cell<usize>,
    runs: Cell<Runs>,
    /// Evaluate new points with sensitivities (exact sensitivities only).
    with_jacobian: Cell<bool>,
    last: RefCell<Option<(Vec<f64>, Vec<f64>)>>,
    /// The last two runs with sensitivities (the last first): point,
    /// predictions, residuals and Jacobian. Two, so that the one at
    /// Levenberg-Marquardt's last accepted point survives a rejected trial
    /// evaluated with sensitivities after it.
    last_exact: RefCell<Vec<(Vec<f64>, ExactEvaluation)>>,
    /// The last point whose run with sensitivities failed, and how many
    /// failed.
    exact_failed: RefCell<Option<Vec<f64>>>,
    failed_exact: Cell<usize>,
}

impl<'a> LeastSquaresProblem<'a> {
    /// An adapter with its own evaluators (for the calling thread).
    pub fn new(objective: &'a Objective, fd: FdOptions) -> Self {
        LeastSquaresProblem {
            objective,
            fd,
            evaluators: RefCell::new(objective.evaluators()),
            evaluations: Cell::new(0),
            jacobians: Cell::new(0),
            runs: Cell::new(Runs::default()),
            with_jacobian: Cell::new(true),
            last: RefCell::new(None),
            last_exact: RefCell::new(Vec::new()),
            exact_failed: RefCell::new(None),
            failed_exact: Cell::new(0),
        }
    }

    /// Runs so far by kind (exact sensitivities; finite differences count
    /// in [`LeastSquaresProblem::evaluations`] only).
    pub fn runs(&self) -> Runs {
        self.runs.get()
    }

    /// The predictions, residuals and exact Jacobian of one of the last two
    /// runs with sensitivities when it was at `z` (taken: a second call
    /// gives `None`).
    pub fn take_exact(&self, z: &[f64]) -> Option<ExactEvaluation> {
        let mut kept = self.last_exact.borrow_mut();
        let i = kept.iter().position(|(zl, _)| zl.as_slice() == z)?;
        Some(kept.remove(i).1)
    }

    /// Runs with sensitivities that failed (each then replaced by a plain
    /// run, or by finite differences for a Jacobian).
    pub fn failed_sensitivity_runs(&self) -> usize {
        self.failed_exact.get()
    }

    /// Notes that the run with sensitivities at `z` failed.
    fn exact_failed_at(&self, z: &[f64]) {
        self.failed_exact.set(self.failed_exact.get() + 1);
        *self.exact_failed.borrow_mut() = Some(z.to_vec());
    }

    /// One run with sensitivities at `z`, kept.
    fn exact_run(&self, z: &[f64]) -> Result<Vec<f64>, InverseError> {
        self.evaluations.set(self.evaluations.get() + 1);
        let mut runs = self.runs.get();
        runs.with_sensitivities += 1;
        self.runs.set(runs);
        let e = residuals_and_exact_jacobian(self.objective, z, "objective evaluation")?;
        let r = e.1.clone();
        *self.last.borrow_mut() = Some((z.to_vec(), r.clone()));
        let mut kept = self.last_exact.borrow_mut();
        kept.insert(0, (z.to_vec(), e));
        kept.truncate(2);
        Ok(r)
    }

    /// The objective.
    pub fn objective(&self) -> &'a Objective {
        self.objective
    }

    /// Jacobians computed so far.
    pub fn jacobians(&self) -> usize {
        self.jacobians.get()
    }

    /// Residuals at `z`, reusing the last ones when `z` is unchanged.
    pub fn residuals_at(&self, z: &[f64]) -> Result<Vec<f64>, InverseError> {
        if let Some((zl, rl)) = self.last.borrow().as_ref() {
            if zl.as_slice() == z {
                return Ok(rl.clone());
            }
        }
        let exact = self.objective.has_exact_sensitivities();
        if exact && self.with_jacobian.get() {
            // a run with sensitivities may fail where a plain one converges
            // (its differentiation inverts an element at a perturbed state)
            match self.exact_run(z) {
                Err(InverseError::Forward { .. }) => self.exact_failed_at(z),
                done => return done,
            }
        }
        self.evaluations.set(self.evaluations.get() + 1);
        if exact {
            let mut runs = self.runs.get();
            runs.plain += 1;
            self.runs.set(runs);
        }
        let r = self.objective.residuals(
            &mut self.evaluators.borrow_mut(),
            z,
            "objective evaluation",
        )?;
        *self.last.borrow_mut() = Some((z.to_vec(), r.clone()));
        Ok(r)
    }

    /// d r / d z at `z`. With exact sensitivities, the one kept from the
    /// run with sensitivities at `z`, or one such run when there was none
    /// (`z` not evaluated, or evaluated plain).
    pub fn jacobian_at(&self, z: &[f64]) -> Result<DMatrix<f64>, InverseError> {
        if self.objective.has_exact_sensitivities() {
            let here = |kept: &[(Vec<f64>, ExactEvaluation)]| {
                kept.iter()
                    .find(|(zl, _)| zl.as_slice() == z)
                    .map(|(_, (_, _, j))| j.matrix.clone())
            };
            let found = here(&self.last_exact.borrow());
            let failed_here = self.exact_failed.borrow().as_deref() == Some(z);
            let j = match found {
                Some(j) => Some(j),
                None if failed_here => None,
                None => match self.exact_run(z) {
                    Ok(_) => here(&self.last_exact.borrow()),
                    Err(InverseError::Forward { .. }) => {
                        self.exact_failed_at(z);
                        None
                    }
                    Err(e) => return Err(e),
                },
            };
            if let Some(j) = j {
                self.jacobians.set(self.jacobians.get() + 1);
                return Ok(j);
            }
            // the run with sensitivities failed here: finite differences
        }
        let r0 = if self.fd.central {
            None
        } else {
            Some(self.residuals_at(z)?)
        };
        let j = finite_difference_jacobian(self.objective, z, r0.as_deref(), &self.fd)?;
        self.evaluations.set(self.evaluations.get() + j.evaluations);
        self.jacobians.set(self.jacobians.get() + 1);
        Ok(j.matrix)
    }
}

impl EvaluationCount for LeastSquaresProblem<'_> {
    fn evaluations(&self) -> usize {
        self.evaluations.get()
    }

    fn jacobian_with_residuals(&self, wanted: bool) {
        self.with_jacobian.set(wanted);
    }

    fn point(&self, z: &[f64]) -> Vec<f64> {
        self.objective.theta_from_unbounded(z)
    }
}

impl Operator for LeastSquaresProblem<'_> {
    type Param = Vec<f64>;
    type Output = Vec<f64>;
    fn apply(&self, z: &Vec<f64>) -> Result<Vec<f64>, Error> {
        Ok(self.residuals_at(z)?)
    }
}

impl Jacobian for LeastSquaresProblem<'_> {
    type Param = Vec<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, z: &Vec<f64>) -> Result<DMatrix<f64>, Error> {
        Ok(self.jacobian_at(z)?)
    }
}

impl CostFunction for LeastSquaresProblem<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    /// `SSE(z) = sum_i r_i(z)^2`.
    fn cost(&self, z: &Vec<f64>) -> Result<f64, Error> {
        Ok(sum_of_squares(&self.residuals_at(z)?))
    }
}

impl Gradient for LeastSquaresProblem<'_> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    /// `grad SSE = 2 J^T r`.
    fn gradient(&self, z: &Vec<f64>) -> Result<Vec<f64>, Error> {
        let r = self.residuals_at(z)?;
        let j = self.jacobian_at(z)?;
        Ok((0..j.ncols())
            .map(|c| 2.0 * j.column(c).iter().zip(&r).map(|(a, b)| a * b).sum::<f64>())
            .collect())
    }
}

/// The adapter lent to a quasi-Newton executor: argmin's L-BFGS drops the
/// problem it holds when its line search fails (it then ends the run with
/// the failure as its reason), so the run lends it and keeps its counts and
/// kept evaluations.
impl CostFunction for &LeastSquaresProblem<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, z: &Vec<f64>) -> Result<f64, Error> {
        (**self).cost(z)
    }
}

impl Gradient for &LeastSquaresProblem<'_> {
    type Param = Vec<f64>;
    type Gradient = Vec<f64>;
    fn gradient(&self, z: &Vec<f64>) -> Result<Vec<f64>, Error> {
        (**self).gradient(z)
    }
}

/// Recovers an [`InverseError`] from an argmin error, or wraps the text.
pub fn inverse_error(error: Error, solver: &'static str) -> InverseError {
    match error.downcast::<InverseError>() {
        Ok(e) => e,
        Err(other) => InverseError::Solver {
            solver,
            reason: other.to_string(),
        },
    }
}
