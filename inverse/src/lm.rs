//! Levenberg-Marquardt as an argmin [`Solver`] (STYLE.md 10).
//!
//! Why not the `levenberg-marquardt` crate (rust-cv, a MINPACK port): it is
//! built on an older nalgebra than the workspace's 0.34 (two nalgebras in the
//! build), its residual/Jacobian callbacks return `Option`, so the
//! [`palpate_core::ForwardError`] of a failed evaluation (which data set,
//! which sample) is lost, and it has no observer hook for progress or an
//! evaluation budget that counts finite-difference evaluations. The
//! algorithm is short; written here on argmin's `Solver` so it shares
//! argmin's executor, observers and state with BFGS/L-BFGS.
//!
//! # Algorithm
//!
//! Minimises `SSE(z) = ||r(z)||^2`. Each iteration solves the damped
//! Gauss-Newton system (Moré 1978, "The Levenberg-Marquardt algorithm:
//! implementation and theory", LNM 630, eq. 2.2 with scaling `D`):
//!
//! `(J^T J + mu D^2) h = -J^T r`
//!
//! as the linear least-squares problem `[J; sqrt(mu) D] h ~ [-r; 0]` by SVD
//! (no normal equations, no explicit inverse). `D = diag(d_j)` with
//! `d_j = max over iterations of ||J_j||` (Moré's scale invariance; a zero
//! column gets `d_j = 1`). The gain ratio
//! `rho = (SSE(z) - SSE(z + h)) / (SSE(z) - ||r + J h||^2)` accepts the step
//! when `rho > 1e-4`; the damping follows Nielsen's rule (Nielsen 1999,
//! IMM-REP-1999-05; Madsen, Nielsen & Tingleff 2004, "Methods for non-linear
//! least squares problems", alg. 3.16): on acceptance
//! `mu <- mu * max(1/3, 1 - (2 rho - 1)^3)`, `nu <- 2`; on rejection
//! `mu <- mu * nu`, `nu <- 2 nu`. Initial `mu = tau` (relative to `D^2`).
//! A failed forward evaluation at a trial point is a rejected step, and so
//! is an accepted trial whose Jacobian fails to evaluate (the residuals
//! converged, the run with sensitivities or a finite-difference step did
//! not). A failure that says the point is outside what the model describes
//! ([`ForwardError::InvalidParameter`], [`ForwardError::Unphysical`]: an
//! admissibility limit, [`LevenbergMarquardt::blocked`]) only shortens the
//! step; after [`MAX_FAILED_TRIALS`] other failures in a row (a solver that
//! does not converge however short the step) the fit stops with
//! [`InverseError::TrialsFailed`], naming the point and the last cause.
//!
//! Where the Jacobian comes with the residuals at a price (exact
//! sensitivities: a run with sensitivities costs a plain run and a
//! fraction more, [`EvaluationCount::jacobian_with_residuals`]), a trial
//! is evaluated with its Jacobian only when it will probably be accepted:
//! when the last trial was accepted with a good gain ratio (`rho > 1/4`,
//! the quadratic model was trusted). Otherwise (the first trial, any trial
//! after a rejection or a poor step) it is evaluated plain, and a plain
//! trial that is accepted gets its Jacobian from one more run. With a
//! run with sensitivities costing `c` plain runs, this pays `1` for a
//! rejected plain trial and `1 + c` for an accepted one against `c` for
//! either with sensitivities: cheaper whenever the acceptance probability
//! is below `1 - 1/c` (a third at `c = 1.5`), which is the case after a
//! rejection (the growing damping is still searching for the trust
//! region) and not after a good step (a trusted model near the optimum
//! is accepted again).
//!
//! Stopping, as MINPACK's `lmder`:
//! * `ftol`: `|ared| / SSE <= ftol` and `pred / SSE <= ftol` and `rho <= 2`;
//! * `xtol`: `||D h|| <= xtol (||D z|| + xtol)`;
//! * `gtol`: `max_j |J_j . r| / (||J_j|| ||r||) <= gtol`;
//! * zero residual, evaluation budget, iteration budget (argmin's `max_iters`).

use crate::problem::EvaluationCount;
use crate::{InverseError, Termination};
use argmin::core::{
    Error, IterState, Jacobian, Operator, Problem, Solver, TerminationReason, TerminationStatus, KV,
};
use nalgebra::{DMatrix, DVector};
use palpate_core::ForwardError;
use serde::{Deserialize, Serialize};

/// Gain ratio above which the next trial is expected to be accepted (and is
/// evaluated with its Jacobian where that is cheaper together).
const TRUSTED_GAIN: f64 = 0.25;

/// Trial steps in a row whose evaluation may fail (a forward failure other
/// than an admissibility limit) before the fit stops with an error: the
/// damping grows with each (`mu` by `2^(k (k + 1) / 2)` after `k`), so the
/// last trials are some `1e-10` of the first step's length, where a model
/// that converged at the accepted point and still fails is not going to
/// converge by shorter steps.
pub const MAX_FAILED_TRIALS: usize = 8;

/// The argmin state the solver works on: parameters `z`, gradient `J^T r`,
/// residuals `r`, cost SSE.
pub type LmState = IterState<Vec<f64>, Vec<f64>, (), (), Vec<f64>, f64>;

/// Tolerances and budgets.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LmOptions {
    pub ftol: f64,
    pub xtol: f64,
    pub gtol: f64,
    /// Objective evaluations, finite-difference ones included.
    pub max_evaluations: usize,
    pub max_iterations: u64,
    /// Initial damping `tau` relative to `D^2`.
    pub initial_damping: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            ftol: 1e-12,
            xtol: 1e-10,
            gtol: 1e-10,
            max_evaluations: 5000,
            max_iterations: 1000,
            initial_damping: 1e-3,
        }
    }
}

/// The solver. After a run, [`LevenbergMarquardt::termination`] says why it stopped.
#[derive(Debug, Clone)]
pub struct LevenbergMarquardt {
    options: LmOptions,
    mu: f64,
    nu: f64,
    scale: Vec<f64>,
    jacobian: DMatrix<f64>,
    termination: Option<Termination>,
    /// The last trial since the last accepted step failed to evaluate.
    blocked: bool,
    /// The last trial was accepted with a gain ratio above [`TRUSTED_GAIN`].
    trusted: bool,
    /// Trials in a row whose evaluation failed (admissibility limits not
    /// counted), and how many there were in all.
    failed_in_a_row: usize,
    failed_trials: usize,
}

impl LevenbergMarquardt {
    /// A solver with these options.
    pub fn new(options: LmOptions) -> Self {
        LevenbergMarquardt {
            options,
            mu: options.initial_damping,
            nu: 2.0,
            scale: Vec::new(),
            jacobian: DMatrix::zeros(0, 0),
            termination: None,
            blocked: false,
            trusted: false,
            failed_in_a_row: 0,
            failed_trials: 0,
        }
    }

    /// Trial steps whose evaluation (residuals or, once accepted, the
    /// Jacobian) failed in the last run; each was rejected.
    pub fn failed_trials(&self) -> usize {
        self.failed_trials
    }

    /// Counts a trial whose evaluation failed with `error`; the error that
    /// stops the fit when it is the [`MAX_FAILED_TRIALS`]-th in a row that
    /// is not an admissibility limit.
    fn trial_failed<O: EvaluationCount>(
        &mut self,
        problem: Option<&O>,
        z: &[f64],
        error: Error,
    ) -> Result<(), Error> {
        self.failed_trials += 1;
        let cause = match error.downcast::<InverseError>() {
            Ok(e) => e,
            Err(other) => InverseError::Solver {
                solver: "Levenberg-Marquardt",
                reason: other.to_string(),
            },
        };
        let limit = matches!(
            &cause,
            InverseError::Forward { source, .. }
                if matches!(**source, ForwardError::InvalidParameter { .. } | ForwardError::Unphysical { .. })
        );
        if limit {
            return Ok(());
        }
        self.failed_in_a_row += 1;
        if self.failed_in_a_row < MAX_FAILED_TRIALS {
            return Ok(());
        }
        Err(InverseError::TrialsFailed {
            solver: "Levenberg-Marquardt",
            from: problem.map_or_else(|| z.to_vec(), |p| p.point(z)),
            failures: self.failed_in_a_row,
            last: Box::new(cause),
        }
        .into())
    }

    /// Why the solver stopped, when it stopped by its own criteria.
    pub fn termination(&self) -> Option<&Termination> {
        self.termination.as_ref()
    }

    /// Whether the last trial step (after the last accepted one) failed to
    /// evaluate, e.g. left the law's admissible domain: the run ended against
    /// an admissibility limit that is not a box bound.
    pub fn blocked(&self) -> bool {
        self.blocked
    }

    /// The Jacobian at the last accepted point.
    pub fn last_jacobian(&self) -> &DMatrix<f64> {
        &self.jacobian
    }

    fn update_scale(&mut self) {
        let norms = column_norms(&self.jacobian);
        if self.scale.is_empty() {
            self.scale = norms
                .iter()
                .map(|&n| if n > 0.0 { n } else { 1.0 })
                .collect();
        } else {
            for (d, n) in self.scale.iter_mut().zip(norms) {
                *d = d.max(n);
            }
        }
    }

    /// `max_j |J_j . r| / (||J_j|| ||r||)`, MINPACK's `gnorm`.
    fn gradient_cosine(&self, r: &[f64]) -> f64 {
        let rnorm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut worst: f64 = 0.0;
        for c in 0..self.jacobian.ncols() {
            let col = self.jacobian.column(c);
            let n = col.norm();
            if n > 0.0 {
                let dot: f64 = col.iter().zip(r).map(|(a, b)| a * b).sum();
                worst = worst.max((dot / (n * rnorm)).abs());
            }
        }
        worst
    }

    /// Solves `[J; sqrt(mu) D] h ~ [-r; 0]` by SVD, in the scaled unknowns
    /// `y = D h`: `[J D^-1; sqrt(mu) I] y ~ [-r; 0]`, `h = D^-1 y`. Same
    /// step in exact arithmetic, but the matrix has unit-scale columns, so
    /// a parameter whose column is 1e17 times another's (Ogden
    /// `mu_i l^alpha_i` with `alpha_i = 20` next to `mu_j l^-9`) does not
    /// drown the small singular values in round-off, which stalled LM on
    /// such fits (xtol met by a step that was noise).
    fn damped_step(&self, r: &[f64]) -> Option<Vec<f64>> {
        let (m, q) = self.jacobian.shape();
        let mut a = DMatrix::zeros(m + q, q);
        a.view_mut((0, 0), (m, q)).copy_from(&self.jacobian);
        for (j, d) in self.scale.iter().enumerate() {
            a.column_mut(j).scale_mut(d.recip());
        }
        let root_mu = self.mu.sqrt();
        for j in 0..q {
            a[(m + j, j)] = root_mu;
        }
        let mut b = DVector::zeros(m + q);
        for (bi, ri) in b.iter_mut().zip(r) {
            *bi = -ri;
        }
        let y = a.svd(true, true).solve(&b, f64::MIN_POSITIVE).ok()?;
        let h: Vec<f64> = y.iter().zip(&self.scale).map(|(v, d)| v / d).collect();
        h.iter().all(|v| v.is_finite()).then_some(h)
    }

    fn check_converged(&mut self, r: &[f64], sse: f64) {
        if sse == 0.0 {
            self.termination = Some(Termination::ZeroResidual);
        } else if self.gradient_cosine(r) <= self.options.gtol {
            self.termination = Some(Termination::Gradient);
        }
    }
}

/// Euclidean norm of each column.
pub fn column_norms(j: &DMatrix<f64>) -> Vec<f64> {
    (0..j.ncols()).map(|c| j.column(c).norm()).collect()
}

fn gradient(j: &DMatrix<f64>, r: &[f64]) -> Vec<f64> {
    (0..j.ncols())
        .map(|c| j.column(c).iter().zip(r).map(|(a, b)| a * b).sum())
        .collect()
}

impl<O> Solver<O, LmState> for LevenbergMarquardt
where
    O: Operator<Param = Vec<f64>, Output = Vec<f64>>
        + Jacobian<Param = Vec<f64>, Jacobian = DMatrix<f64>>
        + EvaluationCount,
{
    fn name(&self) -> &str {
        "Levenberg-Marquardt"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let z = state
            .take_param()
            .ok_or_else(|| Error::msg("Levenberg-Marquardt needs a starting point"))?;
        // the start needs its Jacobian: one run for both where they come together
        if let Some(p) = problem.problem.as_ref() {
            p.jacobian_with_residuals(true);
        }
        let r = problem.apply(&z)?;
        self.jacobian = problem.jacobian(&z)?;
        self.update_scale();
        self.mu = self.options.initial_damping;
        self.nu = 2.0;
        self.termination = None;
        self.trusted = false;
        self.failed_in_a_row = 0;
        self.failed_trials = 0;
        let sse: f64 = r.iter().map(|v| v * v).sum();
        self.check_converged(&r, sse);
        let g = gradient(&self.jacobian, &r);
        Ok((state.param(z).cost(sse).gradient(g).residuals(r), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let z = state
            .take_param()
            .ok_or_else(|| Error::msg("Levenberg-Marquardt lost its parameters"))?;
        let r = state
            .take_residuals()
            .ok_or_else(|| Error::msg("Levenberg-Marquardt lost its residuals"))?;
        let sse = state.get_cost();
        loop {
            if problem.problem.as_ref().map_or(0, |p| p.evaluations())
                >= self.options.max_evaluations
            {
                self.termination = Some(Termination::MaxEvaluations);
                break;
            }
            let Some(h) = self.damped_step(&r) else {
                self.termination = Some(Termination::NoProgress);
                break;
            };
            let dh: f64 = h
                .iter()
                .zip(&self.scale)
                .map(|(a, d)| (a * d).powi(2))
                .sum::<f64>()
                .sqrt();
            let dz: f64 = z
                .iter()
                .zip(&self.scale)
                .map(|(a, d)| (a * d).powi(2))
                .sum::<f64>()
                .sqrt();
            if dh <= self.options.xtol * (dz + self.options.xtol) {
                self.termination = Some(Termination::RelativeStep);
                break;
            }
            let jh = &self.jacobian * DVector::from_column_slice(&h);
            let predicted_sse: f64 = r.iter().zip(jh.iter()).map(|(a, b)| (a + b).powi(2)).sum();
            let pred = sse - predicted_sse;
            let z_new: Vec<f64> = z.iter().zip(&h).map(|(a, b)| a + b).collect();
            if let Some(p) = problem.problem.as_ref() {
                p.jacobian_with_residuals(self.trusted);
            }
            let trial = match problem.apply(&z_new) {
                Ok(r_new) => {
                    let sse_new: f64 = r_new.iter().map(|v| v * v).sum();
                    sse_new.is_finite().then_some((r_new, sse_new))
                }
                Err(e) => {
                    self.trial_failed(problem.problem.as_ref(), &z, e)?;
                    None
                }
            };
            self.blocked = trial.is_none();
            let (mut rho, accepted) = match trial {
                Some((r_new, sse_new)) if pred > 0.0 => {
                    ((sse - sse_new) / pred, Some((r_new, sse_new)))
                }
                _ => (f64::NEG_INFINITY, None),
            };
            // kept from the trial's run, or one run with sensitivities (or
            // finite differences where that run fails)
            let jacobian = match accepted {
                Some(_) if rho > 1e-4 => match problem.jacobian(&z_new) {
                    Ok(j) => Some(j),
                    Err(e) => {
                        self.trial_failed(problem.problem.as_ref(), &z, e)?;
                        self.blocked = true;
                        rho = f64::NEG_INFINITY;
                        None
                    }
                },
                _ => None,
            };
            if !self.blocked {
                self.failed_in_a_row = 0;
            }
            self.trusted = rho > TRUSTED_GAIN;
            if let (Some((r_new, sse_new)), Some(jacobian)) = (accepted, jacobian) {
                self.jacobian = jacobian;
                self.update_scale();
                self.mu *= (1.0 / 3.0f64).max(1.0 - (2.0 * rho - 1.0).powi(3));
                self.nu = 2.0;
                let ared = sse - sse_new;
                if ared.abs() <= self.options.ftol * sse
                    && pred <= self.options.ftol * sse
                    && rho <= 2.0
                {
                    self.termination = Some(Termination::CostReduction);
                } else {
                    self.check_converged(&r_new, sse_new);
                }
                let g = gradient(&self.jacobian, &r_new);
                let kv = argmin::kv!("mu" => self.mu; "rho" => rho;);
                return Ok((
                    state
                        .param(z_new)
                        .cost(sse_new)
                        .gradient(g)
                        .residuals(r_new),
                    Some(kv),
                ));
            }
            self.mu *= self.nu;
            self.nu *= 2.0;
            if !(self.mu.is_finite() && self.mu < 1e300) {
                self.termination = Some(Termination::NoProgress);
                break;
            }
        }
        Ok((state.param(z).cost(sse).residuals(r), None))
    }

    fn terminate(&mut self, _state: &LmState) -> TerminationStatus {
        match &self.termination {
            None => TerminationStatus::NotTerminated,
            Some(t) if t.converged() => {
                TerminationStatus::Terminated(TerminationReason::SolverConverged)
            }
            Some(t) => TerminationStatus::Terminated(TerminationReason::SolverExit(t.to_string())),
        }
    }
}
