//! The argmin adapter around an [`Objective`] (STYLE.md 10).
//!
//! argmin asks for the cost and then the gradient (or residuals and then the
//! Jacobian) in separate calls with the same parameter vector; the adapter
//! remembers the last vector and its residuals so they are computed once.
//!
//! With exact sensitivities (every data set has them) each evaluation is
//! one run that gives the residuals and the Jacobian together
//! ([`crate::jacobian::residuals_and_exact_jacobian`]), and the Jacobian at
//! the last point is kept: Levenberg-Marquardt evaluates a trial point, and
//! when it accepts it asks for the Jacobian there, which then costs no
//! forward run. A rejected trial pays the sensitivities for nothing (the
//! back-substitutions and assemblies of one run, less than a second run),
//! so one forward run per trial point is the whole cost
//! ([`LeastSquaresProblem::evaluations`] counts them).

use crate::jacobian::residuals_and_exact_jacobian;
use crate::{jacobian_unbounded, sum_of_squares, Evaluators, FdOptions, InverseError, Objective};
use argmin::core::{CostFunction, Error, Gradient, Jacobian, Operator};
use nalgebra::DMatrix;
use std::cell::{Cell, RefCell};

/// Something that knows how many objective evaluations it has made (the
/// Levenberg-Marquardt solver's evaluation budget reads it).
pub trait EvaluationCount {
    /// Objective evaluations so far, finite-difference ones included.
    fn evaluations(&self) -> usize;
}

/// Residuals, SSE, gradient and Jacobian of an objective in the free
/// unbounded parameters `z`, for argmin.
pub struct LeastSquaresProblem<'a> {
    objective: &'a Objective,
    fd: FdOptions,
    evaluators: RefCell<Evaluators<'a>>,
    evaluations: Cell<usize>,
    jacobians: Cell<usize>,
    last: RefCell<Option<(Vec<f64>, Vec<f64>)>>,
    /// The exact Jacobian at `last`'s point (exact sensitivities only).
    last_jacobian: RefCell<Option<(Vec<f64>, DMatrix<f64>)>>,
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
            last: RefCell::new(None),
            last_jacobian: RefCell::new(None),
        }
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
        self.evaluations.set(self.evaluations.get() + 1);
        if self.objective.has_exact_sensitivities() {
            let (_, r, j) =
                residuals_and_exact_jacobian(self.objective, z, "objective evaluation")?;
            *self.last.borrow_mut() = Some((z.to_vec(), r.clone()));
            *self.last_jacobian.borrow_mut() = Some((z.to_vec(), j.matrix));
            return Ok(r);
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
    /// evaluation at `z` (computed by one run when `z` was not evaluated).
    pub fn jacobian_at(&self, z: &[f64]) -> Result<DMatrix<f64>, InverseError> {
        if self.objective.has_exact_sensitivities() {
            self.residuals_at(z)?;
            let kept = self.last_jacobian.borrow();
            if let Some((_, j)) = kept.as_ref().filter(|(zl, _)| zl.as_slice() == z) {
                self.jacobians.set(self.jacobians.get() + 1);
                return Ok(j.clone());
            }
        }
        let r0 = if self.fd.central || self.objective.has_exact_sensitivities() {
            None
        } else {
            Some(self.residuals_at(z)?)
        };
        let j = jacobian_unbounded(self.objective, z, r0.as_deref(), &self.fd)?;
        self.evaluations.set(self.evaluations.get() + j.evaluations);
        self.jacobians.set(self.jacobians.get() + 1);
        Ok(j.matrix)
    }
}

impl EvaluationCount for LeastSquaresProblem<'_> {
    fn evaluations(&self) -> usize {
        self.evaluations.get()
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
