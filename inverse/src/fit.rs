//! Fitting an objective: local runs from one or several starts, then the
//! statistics at the best optimum.

use crate::boundary_polish::boundary_polish;
use crate::jacobian::ExactEvaluation;
use crate::observer::ArgminBridge;
use crate::run::{run, RunOutcome};
use crate::wall_slide::{limit_ahead, wall_slide};
use crate::{
    covariance, finite_difference_jacobian, residuals_and_exact_jacobian, sum_of_squares,
    BoundSide, FdOptions, FitReport, InverseError, Method, Objective, ParameterEstimate, SetReport,
    SharedObserver,
};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// Deterministic multi-start: `starts - 1` extra points
/// `z0_j + spread * scale_j * u_j`, with `u` the Halton sequence (bases
/// 2, 3, 5, ...) mapped to (-1, 1) and `scale_j = 1` for a transformed
/// (bounded) parameter, `max(|z0_j|, 1e-3)` for an unbounded one (so the
/// spread is relative there). The best SSE wins.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MultiStart {
    pub starts: usize,
    pub spread: f64,
}

impl Default for MultiStart {
    fn default() -> Self {
        MultiStart {
            starts: 1,
            spread: 1.0,
        }
    }
}

/// How to fit.
#[derive(Clone, Default)]
pub struct FitOptions {
    pub method: Method,
    pub fd: FdOptions,
    pub multistart: MultiStart,
    /// Full physical starting vector (fixed entries ignored); default: the
    /// space's initial values.
    pub start: Option<Vec<f64>>,
    /// Progress callback.
    pub observer: Option<SharedObserver>,
}

impl std::fmt::Debug for FitOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FitOptions")
            .field("method", &self.method)
            .field("fd", &self.fd)
            .field("multistart", &self.multistart)
            .field("start", &self.start)
            .field("observer", &self.observer.is_some())
            .finish()
    }
}

impl FitOptions {
    /// Options for a method, with defaults otherwise.
    pub fn with_method(method: Method) -> Self {
        FitOptions {
            method,
            ..FitOptions::default()
        }
    }
}

const PRIMES: [u32; 16] = [2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53];

/// The radical inverse of `k` in base `b` (Halton), in (0, 1) for k >= 1.
fn radical_inverse(mut k: u64, b: u32) -> f64 {
    let mut f = 1.0;
    let mut x = 0.0;
    let b64 = u64::from(b);
    while k > 0 {
        f /= f64::from(b);
        x += f * (k % b64) as f64;
        k /= b64;
    }
    x
}

/// The starting points in the unbounded space (the first is `z0`).
pub fn start_points(objective: &Objective, z0: &[f64], multistart: &MultiStart) -> Vec<Vec<f64>> {
    let mut points = vec![z0.to_vec()];
    for k in 1..multistart.starts.max(1) {
        let p: Vec<f64> = z0
            .iter()
            .enumerate()
            .map(|(j, &zj)| {
                let spec = &objective.space().params[objective.free_indices()[j]];
                let scale = if spec.lower.is_finite() || spec.upper.is_finite() {
                    1.0
                } else {
                    zj.abs().max(1e-3)
                };
                let u = 2.0 * radical_inverse(k as u64, PRIMES[j % PRIMES.len()]) - 1.0;
                zj + multistart.spread * scale * u
            })
            .collect();
        points.push(p);
    }
    points
}

/// Fits `objective` and reports estimates, standard errors, correlations,
/// goodness of fit and identifiability at the best optimum.
pub fn fit(objective: &Objective, options: &FitOptions) -> Result<FitReport, InverseError> {
    let theta0 = match &options.start {
        Some(t) => {
            let mut t = t.clone();
            for (k, v) in t.iter_mut().enumerate() {
                if let Some(f) = objective.fixed_value(k) {
                    *v = f;
                }
            }
            t
        }
        None => objective.initial_theta(),
    };
    let z0 = objective.unbounded_from_theta(&theta0)?;
    if !(options.multistart.spread.is_finite() && options.multistart.spread >= 0.0) {
        return Err(InverseError::InvalidOption {
            option: "multistart.spread",
            reason: format!(
                "{} must be finite and non-negative",
                options.multistart.spread
            ),
        });
    }
    let points = start_points(objective, &z0, &options.multistart);
    let starts = points.len();
    let mut best: Option<(usize, RunOutcome)> = None;
    let (mut evaluations, mut jacobians, mut failed) = (0, 0, 0);
    for (k, z) in points.into_iter().enumerate() {
        let bridge = options
            .observer
            .as_ref()
            .map(|o| ArgminBridge::new(o.clone(), objective, k, starts));
        match run(objective, &options.method, &options.fd, z, bridge) {
            Ok(outcome) => {
                evaluations += outcome.evaluations;
                jacobians += outcome.jacobians;
                let better = best.as_ref().is_none_or(|(_, b)| outcome.sse < b.sse);
                if better && outcome.sse.is_finite() {
                    best = Some((k, outcome));
                }
            }
            Err(e) if k == 0 => return Err(e),
            Err(_) => failed += 1,
        }
    }
    let (best_start, outcome) = best.ok_or_else(|| InverseError::Solver {
        solver: options.method.name(),
        reason: "no start produced a finite SSE".into(),
    })?;
    // A run that ended against an admissibility limit (a failed trial step)
    // continues along it (see `wall_slide`); whether it ended on that limit
    // (not at a minimum short of it) is reported as `on_limit`.
    let blocked = outcome.blocked;
    let outcome = match outcome.blocked {
        true => match wall_slide(
            objective,
            &options.fd,
            &outcome,
            slide_budget(&options.method),
        ) {
            Some(slid) => {
                evaluations += slid.evaluations;
                jacobians += slid.jacobians;
                slid
            }
            None => outcome,
        },
        false => outcome,
    };
    // Optima on a finite bound sit at infinity in the transformed space;
    // try them exactly (see `boundary_polish`). A parameter put on its bound
    // is reported with `at_bound` set (also in `identifiability.at_bound`),
    // not `fixed`, and, like any parameter on a bound, without a standard
    // error; it is not among `free` nor in the correlation matrix.
    let (outcome, mut report) =
        match boundary_polish(objective, &options.method, &options.fd, &outcome) {
            Some(polished) => {
                evaluations += polished.evaluations;
                jacobians += polished.jacobians;
                let mut report = statistics(&polished.objective, &polished.outcome.z, &options.fd)?;
                if blocked {
                    report.on_limit =
                        limit_ahead(&polished.objective, &options.fd, &polished.outcome.z);
                }
                for &(k, side) in &polished.held {
                    report.parameters[k].fixed = false;
                    report.parameters[k].at_bound = Some(side);
                    let name = report.parameters[k].name.clone();
                    if !report.identifiability.at_bound.contains(&name) {
                        report.identifiability.at_bound.push(name);
                    }
                }
                (polished.outcome, report)
            }
            None => {
                let mut report =
                    statistics_with(objective, &outcome.z, &options.fd, outcome.exact.clone())?;
                if blocked {
                    report.on_limit = limit_ahead(objective, &options.fd, &outcome.z);
                }
                (outcome, report)
            }
        };
    report.method = options.method.name().to_string();
    report.iterations = outcome.iterations;
    report.evaluations += evaluations;
    report.jacobians += jacobians;
    report.converged = outcome.termination.converged();
    report.termination = outcome.termination;
    report.starts = starts;
    report.best_start = best_start;
    report.failed_starts = failed;
    Ok(report)
}

/// Evaluations the wall slide after a blocked run may spend: the method's
/// own budget of one run (Levenberg-Marquardt's `max_evaluations`), or, for
/// a method that counts only iterations, 5000 (the Levenberg-Marquardt
/// default).
fn slide_budget(method: &Method) -> usize {
    match method {
        Method::LevenbergMarquardt(lm) => lm.max_evaluations,
        Method::Bfgs(_) | Method::Lbfgs { .. } => crate::LmOptions::default().max_evaluations,
    }
}

/// Statistics at free unbounded values `z` (the solver fields of the report
/// are left for the caller: zero iterations, `MaxIterations`).
pub fn statistics(
    objective: &Objective,
    z: &[f64],
    fd: &FdOptions,
) -> Result<FitReport, InverseError> {
    statistics_with(objective, z, fd, None)
}

/// [`statistics`], from the predictions, residuals and exact Jacobian of a
/// run with sensitivities at `z` when the solver kept one (no run then;
/// the report counts no evaluation).
fn statistics_with(
    objective: &Objective,
    z: &[f64],
    fd: &FdOptions,
    kept: Option<ExactEvaluation>,
) -> Result<FitReport, InverseError> {
    let theta = objective.theta_from_unbounded(z);
    // With exact sensitivities one run gives the predictions and the
    // Jacobian (none when the solver kept them); otherwise the
    // predictions, then finite differences.
    let exact = objective.has_exact_sensitivities();
    let ((predictions, r, jz), evaluations) = match (kept, exact) {
        (Some(kept), _) => (kept, 0),
        (None, true) => match residuals_and_exact_jacobian(objective, z, "final point") {
            Ok(e) => (e, 1),
            // the run with sensitivities failed: a plain one and finite
            // differences (as `jacobian_unbounded` falls back)
            Err(InverseError::Forward { .. }) => plain_and_differences(objective, z, fd, 1)?,
            Err(e) => return Err(e),
        },
        (None, false) => plain_and_differences(objective, z, fd, 0)?,
    };
    let sse = sum_of_squares(&r);
    let dxdz = objective.dx_dz(z);
    let free = objective.free_indices();
    let names = objective.free_names();
    let space = objective.space();
    // Which free parameters sit on a bound.
    let at_bound: Vec<Option<BoundSide>> = free
        .iter()
        .map(|&k| {
            let p = &space.params[k];
            let x = theta[k];
            let near = |dist: f64, initial_dist: f64| {
                dist <= 1e-6 * initial_dist.abs().max(f64::MIN_POSITIVE)
            };
            if p.lower.is_finite() && near(x - p.lower, p.initial - p.lower) {
                Some(BoundSide::Lower)
            } else if p.upper.is_finite() && near(p.upper - x, p.upper - p.initial) {
                Some(BoundSide::Upper)
            } else {
                None
            }
        })
        .collect();
    // Physical Jacobian J_x = J_z diag(1 / (dx/dz)) (chain rule at the optimum).
    let (m, q) = jz.matrix.shape();
    let mut jx = DMatrix::zeros(m, q);
    for j in 0..q {
        if at_bound[j].is_none() && dxdz[j] != 0.0 {
            jx.column_mut(j).copy_from(&(jz.matrix.column(j) / dxdz[j]));
        }
    }
    let on_bound: Vec<bool> = at_bound
        .iter()
        .zip(&dxdz)
        .map(|(b, &d)| b.is_some() || d == 0.0)
        .collect();
    let cov = covariance(&jx, sse, &names, &on_bound);
    let parameters = space
        .params
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let j = free.iter().position(|&f| f == k);
            ParameterEstimate {
                name: p.name.clone(),
                unit: p.unit.clone(),
                value: theta[k],
                standard_error: j.and_then(|j| cov.standard_errors[j]),
                fixed: j.is_none(),
                at_bound: j.and_then(|j| at_bound[j]),
                lower: p.lower,
                upper: p.upper,
            }
        })
        .collect();
    let (mut ss_res_all, mut ss_tot_all) = (0.0, 0.0);
    let sets: Vec<SetReport> = objective
        .sets()
        .iter()
        .enumerate()
        .map(|(s, set)| {
            let n = set.observed.len();
            let pred = &predictions[s];
            let sse_absolute: f64 = pred
                .iter()
                .zip(&set.observed)
                .map(|(f, y)| (f - y).powi(2))
                .sum();
            let mean = set.observed.iter().sum::<f64>() / n as f64;
            let ss_tot: f64 = set.observed.iter().map(|y| (y - mean).powi(2)).sum();
            ss_res_all += sse_absolute;
            ss_tot_all += ss_tot;
            let range = objective.residual_range(s);
            SetReport {
                name: set.name.clone(),
                model: set.model.name(),
                weight: set.weight,
                samples: n,
                sse: sum_of_squares(&r[range.clone()]),
                sse_absolute,
                rms_absolute: (sse_absolute / n as f64).sqrt(),
                r_squared: 1.0 - sse_absolute / ss_tot,
                observed: set.observed.clone(),
                predicted: pred.clone(),
                residuals: r[range].to_vec(),
                kept: objective.factors(s).iter().map(|&(i, _)| i).collect(),
            }
        })
        .collect();
    Ok(FitReport {
        method: String::new(),
        residual: objective.residual_kind(),
        parameters,
        free: names,
        correlation: cov.correlation,
        sigma2: cov.sigma2,
        sse,
        rms: (sse / m as f64).sqrt(),
        r_squared: 1.0 - ss_res_all / ss_tot_all,
        n_residuals: m,
        iterations: 0,
        evaluations,
        jacobians: 1,
        termination: crate::Termination::MaxIterations,
        converged: false,
        starts: 1,
        best_start: 0,
        failed_starts: 0,
        sets,
        identifiability: cov.identifiability,
        on_limit: false,
    })
}

/// The predictions and residuals at `z` from a plain run and the Jacobian
/// by finite differences, with the evaluations they cost plus `failed`.
fn plain_and_differences(
    objective: &Objective,
    z: &[f64],
    fd: &FdOptions,
    failed: usize,
) -> Result<(ExactEvaluation, usize), InverseError> {
    let theta = objective.theta_from_unbounded(z);
    let mut evs = objective.evaluators();
    let predictions = objective.predict(&mut evs, &theta, "final point")?;
    let mut r = vec![0.0; objective.n_residuals()];
    objective.residuals_from_predictions(&predictions, &mut r);
    let jz = finite_difference_jacobian(objective, z, Some(&r), fd)?;
    let evaluations = failed + 1 + jz.evaluations;
    Ok(((predictions, r, jz), evaluations))
}
