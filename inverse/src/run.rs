//! One local optimisation from one starting point, through argmin's
//! `Executor`: Levenberg-Marquardt, BFGS or L-BFGS (the latter two with the
//! Moré-Thuente line search on `SSE(z)` and the gradient `2 J^T r`, and
//! the reset of [`crate::curvature`] after a step whose curvature is not
//! positive).

use crate::curvature::{CurvatureGuard, Restart};
use crate::jacobian::ExactEvaluation;
use crate::observer::ArgminBridge;
use crate::problem::{inverse_error, EvaluationCount, LeastSquaresProblem};
use crate::{FdOptions, InverseError, LevenbergMarquardt, LmOptions, Objective, Termination};
use argmin::core::observers::ObserverMode;
use argmin::core::{Executor, State, TerminationReason};
use argmin::solver::linesearch::MoreThuenteLineSearch;
use argmin::solver::quasinewton::{BFGS, LBFGS};
use serde::{Deserialize, Serialize};

/// Options of the quasi-Newton solvers.
///
/// argmin's tolerances are absolute; they are set relative to the SSE at the
/// start: `tol_grad = relative_tol_grad * SSE(z0)` on `||grad SSE||` and
/// `tol_cost = relative_tol_cost * SSE(z0)` on the SSE change of one iteration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct QuasiNewtonOptions {
    pub max_iterations: u64,
    pub relative_tol_grad: f64,
    pub relative_tol_cost: f64,
}

impl Default for QuasiNewtonOptions {
    fn default() -> Self {
        QuasiNewtonOptions {
            max_iterations: 2000,
            relative_tol_grad: 1e-12,
            relative_tol_cost: 1e-16,
        }
    }
}

/// The estimator.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    LevenbergMarquardt(LmOptions),
    Bfgs(QuasiNewtonOptions),
    /// L-BFGS keeping `memory` correction pairs.
    Lbfgs {
        memory: usize,
        options: QuasiNewtonOptions,
    },
}

impl Default for Method {
    fn default() -> Self {
        Method::LevenbergMarquardt(LmOptions::default())
    }
}

impl Method {
    /// A short name for reports.
    pub fn name(&self) -> &'static str {
        match self {
            Method::LevenbergMarquardt(_) => "levenberg_marquardt",
            Method::Bfgs(_) => "bfgs",
            Method::Lbfgs { .. } => "lbfgs",
        }
    }
}

/// The outcome of one local run.
#[derive(Debug, Clone)]
pub(crate) struct RunOutcome {
    pub z: Vec<f64>,
    pub sse: f64,
    pub iterations: u64,
    pub evaluations: usize,
    pub jacobians: usize,
    pub termination: Termination,
    /// Levenberg-Marquardt only: the last trial failed to evaluate.
    pub blocked: bool,
    /// With exact sensitivities: the predictions, residuals and Jacobian at
    /// `z` when a run with sensitivities there is still kept (the
    /// statistics then need no run).
    pub exact: Option<ExactEvaluation>,
}

fn argmin_termination(reason: Option<&TerminationReason>) -> Termination {
    match reason {
        Some(TerminationReason::MaxItersReached) => Termination::MaxIterations,
        Some(r) => Termination::QuasiNewton(r.text().to_string()),
        None => Termination::QuasiNewton("not terminated".into()),
    }
}

/// Runs `method` from `z0`.
pub(crate) fn run(
    objective: &Objective,
    method: &Method,
    fd: &FdOptions,
    z0: Vec<f64>,
    observer: Option<ArgminBridge>,
) -> Result<RunOutcome, InverseError> {
    let problem = LeastSquaresProblem::new(objective, *fd);
    match method {
        Method::LevenbergMarquardt(options) => {
            let mut executor = Executor::new(problem, LevenbergMarquardt::new(*options))
                .configure(|s| s.param(z0).max_iters(options.max_iterations));
            if let Some(obs) = observer {
                executor = executor.add_observer(obs, ObserverMode::Always);
            }
            let result = executor
                .run()
                .map_err(|e| inverse_error(e, "Levenberg-Marquardt"))?;
            let p = result.problem.problem.as_ref().expect("problem kept");
            let termination = match result.solver.termination() {
                Some(t) => t.clone(),
                None => argmin_termination(result.state.get_termination_reason()),
            };
            let z = result.state.get_best_param().cloned().unwrap_or_default();
            Ok(RunOutcome {
                exact: p.take_exact(&z),
                z,
                sse: result.state.get_best_cost(),
                iterations: result.state.get_iter(),
                evaluations: p.evaluations(),
                jacobians: p.jacobians(),
                termination,
                blocked: result.solver.blocked(),
            })
        }
        Method::Bfgs(options) => {
            let sse0 = start_sse(&problem, &z0)?;
            let q = z0.len();
            // Initial inverse Hessian: the inverse diagonal of the Gauss-Newton
            // Hessian 2 J^T J at z0 (scale-aware, symmetric positive definite).
            let j0 = problem.jacobian_at(&z0)?;
            let h0: Vec<Vec<f64>> = (0..q)
                .map(|a| {
                    (0..q)
                        .map(|b| {
                            let d = 2.0 * j0.column(a).norm_squared();
                            if a == b && d > 0.0 {
                                1.0 / d
                            } else if a == b {
                                1.0
                            } else {
                                0.0
                            }
                        })
                        .collect()
                })
                .collect();
            let solver = BFGS::new(MoreThuenteLineSearch::new())
                .with_tolerance_grad(options.relative_tol_grad * sse0)
                .and_then(|s| s.with_tolerance_cost(options.relative_tol_cost * sse0))
                .map_err(|e| inverse_error(e, "BFGS"))?;
            let solver = CurvatureGuard::new(solver, Restart::InverseHessian(h0.clone()), "BFGS");
            let mut executor = Executor::new(&problem, solver).configure(|s| {
                s.param(z0)
                    .inv_hessian(h0)
                    .max_iters(options.max_iterations)
            });
            if let Some(obs) = observer {
                executor = executor.add_observer(obs, ObserverMode::Always);
            }
            let result = executor.run().map_err(|e| inverse_error(e, "BFGS"))?;
            let p = &problem;
            let z = result.state.get_best_param().cloned().unwrap_or_default();
            Ok(RunOutcome {
                exact: p.take_exact(&z),
                z,
                sse: result.state.get_best_cost(),
                iterations: result.state.get_iter(),
                evaluations: p.evaluations(),
                jacobians: p.jacobians(),
                termination: argmin_termination(result.state.get_termination_reason()),
                blocked: false,
            })
        }
        Method::Lbfgs { memory, options } => {
            let sse0 = start_sse(&problem, &z0)?;
            let solver = LBFGS::new(MoreThuenteLineSearch::new(), (*memory).max(1))
                .with_tolerance_grad(options.relative_tol_grad * sse0)
                .and_then(|s| s.with_tolerance_cost(options.relative_tol_cost * sse0))
                .map_err(|e| inverse_error(e, "L-BFGS"))?;
            let solver =
                CurvatureGuard::<_, ()>::new(solver.clone(), Restart::Memory(solver), "L-BFGS");
            let mut executor = Executor::new(&problem, solver)
                .configure(|s| s.param(z0).max_iters(options.max_iterations));
            if let Some(obs) = observer {
                executor = executor.add_observer(obs, ObserverMode::Always);
            }
            let result = executor.run().map_err(|e| inverse_error(e, "L-BFGS"))?;
            let p = &problem;
            let z = result.state.get_best_param().cloned().unwrap_or_default();
            Ok(RunOutcome {
                exact: p.take_exact(&z),
                z,
                sse: result.state.get_best_cost(),
                iterations: result.state.get_iter(),
                evaluations: p.evaluations(),
                jacobians: p.jacobians(),
                termination: argmin_termination(result.state.get_termination_reason()),
                blocked: false,
            })
        }
    }
}

fn start_sse(problem: &LeastSquaresProblem<'_>, z0: &[f64]) -> Result<f64, InverseError> {
    let r = problem.residuals_at(z0)?;
    Ok(crate::sum_of_squares(&r).max(f64::MIN_POSITIVE))
}
