//! Boundary polish: reaching optima that lie on a finite parameter bound.
//!
//! Estimators move in the unbounded space of the bound transforms
//! (`x = lower + (upper - lower) / (1 + exp(-z))` etc.), where a bound sits
//! at `z = +-infinity`: an optimum on a bound is only approached, never
//! reached, and the flat transform (`dx/dz -> 0`) stalls the solver a few
//! percent of the SSE short (Treloar, Ogden-3 uniaxial: `alpha2 = 19.4`
//! instead of the bound 20, SSE +1.4 %).
//!
//! After the local runs, every free parameter whose value lies within
//! [`POLISH_RELATIVE_DISTANCE`] of a finite bound (relative to the span for
//! two bounds, to the initial value's distance to the bound otherwise) is
//! tried exactly on that bound: the objective is refitted with it held there
//! (same method, from the current optimum) and the result is kept only when
//! the SSE is strictly lower. Repeated while it helps (each success holds one
//! more parameter, so at most `q - 1` rounds). This is the active-set idea of
//! bound-constrained least squares (e.g. the reflective trust region of
//! scipy's `least_squares(method='trf')`) done as an a-posteriori check, so
//! fits whose optimum is interior pay nothing: no parameter near a bound, no
//! extra evaluation.

use crate::run::{run, RunOutcome};
use crate::{BoundSide, FdOptions, InverseError, Method, Objective};
use palpate_core::ParamSpec;

/// Relative distance to a bound under which the bound itself is tried.
/// Loose on purpose: a trial that does not lower the SSE is discarded.
pub const POLISH_RELATIVE_DISTANCE: f64 = 0.05;

/// Restarts of a refit on a bound, while each lowers the SSE by more than
/// [`RESTART_GAIN`] (relative).
const MAX_RESTARTS: usize = 20;
const RESTART_GAIN: f64 = 1e-9;

/// The bound a value is close enough to for the polish to try it.
pub fn near_bound(p: &ParamSpec, x: f64) -> Option<(BoundSide, f64)> {
    let two_sided = p.lower.is_finite() && p.upper.is_finite();
    let reference = |bound: f64| {
        if two_sided {
            p.upper - p.lower
        } else {
            (p.initial - bound).abs()
        }
    };
    let (to_lower, to_upper) = (x - p.lower, p.upper - x);
    if p.lower.is_finite()
        && to_lower <= POLISH_RELATIVE_DISTANCE * reference(p.lower)
        && to_lower <= to_upper
    {
        Some((BoundSide::Lower, p.lower))
    } else if p.upper.is_finite() && to_upper <= POLISH_RELATIVE_DISTANCE * reference(p.upper) {
        Some((BoundSide::Upper, p.upper))
    } else {
        None
    }
}

/// The result of a successful polish: the objective with the polished
/// parameters held on their bounds, the optimum of its free parameters, and
/// which parameters (indices into the full space) were put on which bound.
pub(crate) struct Polished {
    pub objective: Objective,
    pub outcome: RunOutcome,
    pub held: Vec<(usize, BoundSide)>,
    /// Evaluations and Jacobians of every polish run, kept or not.
    pub evaluations: usize,
    pub jacobians: usize,
}

/// Tries the bounds near the optimum `outcome` of `objective`; `None` when no
/// trial lowered the SSE.
pub(crate) fn boundary_polish(
    objective: &Objective,
    method: &Method,
    fd: &FdOptions,
    outcome: &RunOutcome,
) -> Option<Polished> {
    let mut current: Option<Polished> = None;
    let (mut evaluations, mut jacobians) = (0, 0);
    loop {
        let (obj, best) = match &current {
            Some(p) => (&p.objective, &p.outcome),
            None => (objective, outcome),
        };
        let theta = obj.theta_from_unbounded(&best.z);
        let mut improved = None;
        for &k in obj.free_indices() {
            let Some((side, bound)) = near_bound(&obj.space().params[k], theta[k]) else {
                continue;
            };
            let Ok((reduced, trial)) = refit_on_bound(obj, method, fd, &theta, k, bound) else {
                continue;
            };
            evaluations += trial.evaluations;
            jacobians += trial.jacobians;
            if trial.sse < best.sse {
                improved = Some((reduced, trial, k, side));
                break;
            }
        }
        let Some((reduced, trial, k, side)) = improved else {
            break;
        };
        let mut held = current.map(|p| p.held).unwrap_or_default();
        held.push((k, side));
        current = Some(Polished {
            objective: reduced,
            outcome: trial,
            held,
            evaluations: 0,
            jacobians: 0,
        });
    }
    current.map(|mut p| {
        p.evaluations = evaluations;
        p.jacobians = jacobians;
        p
    })
}

/// Refits `objective` with parameter `k` also held at `bound`, from `theta`.
fn refit_on_bound(
    objective: &Objective,
    method: &Method,
    fd: &FdOptions,
    theta: &[f64],
    k: usize,
    bound: f64,
) -> Result<(Objective, RunOutcome), InverseError> {
    let space = objective.space();
    let mut fixed: Vec<(String, f64)> = (0..space.len())
        .filter_map(|j| {
            objective
                .fixed_value(j)
                .map(|v| (space.params[j].name.clone(), v))
        })
        .collect();
    fixed.push((space.params[k].name.clone(), bound));
    let reduced = Objective::new(objective.sets().to_vec(), objective.residual_kind(), &fixed)?;
    let mut start = theta.to_vec();
    start[k] = bound;
    let z0 = reduced.unbounded_from_theta(&start)?;
    let mut trial = run(&reduced, method, fd, z0, None)?;
    // Restart from the optimum (fresh damping and scaling) while the SSE
    // still drops: once a parameter is held, the others often have to travel
    // far (Ogden: a vanishing term mu_i -> 0 beside it), and the scaling kept
    // from the first iterations stalls one run short of the optimum.
    for _ in 0..MAX_RESTARTS {
        let (evaluations, jacobians) = (trial.evaluations, trial.jacobians);
        match run(&reduced, method, fd, trial.z.clone(), None) {
            Ok(mut again) if again.sse < trial.sse * (1.0 - RESTART_GAIN) => {
                again.evaluations += evaluations;
                again.jacobians += jacobians;
                trial = again;
            }
            Ok(again) => {
                trial.evaluations += again.evaluations;
                trial.jacobians += again.jacobians;
                break;
            }
            Err(_) => break,
        }
    }
    Ok((reduced, trial))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_bound_picks_the_close_finite_bound_only() {
        let alpha = ParamSpec::new("alpha", "1", -20.0, 20.0, 2.0);
        assert_eq!(near_bound(&alpha, 19.4), Some((BoundSide::Upper, 20.0)));
        assert_eq!(near_bound(&alpha, -19.9), Some((BoundSide::Lower, -20.0)));
        assert_eq!(near_bound(&alpha, 17.0), None);
        let c10 = ParamSpec::new("C10", "MPa", 0.0, f64::INFINITY, 1e-3);
        assert_eq!(near_bound(&c10, 1e-6), Some((BoundSide::Lower, 0.0)));
        assert_eq!(near_bound(&c10, 0.3), None);
        let free = ParamSpec::new("C01", "MPa", f64::NEG_INFINITY, f64::INFINITY, 1e-4);
        assert_eq!(near_bound(&free, -0.3), None);
    }
}
