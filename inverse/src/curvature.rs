//! The curvature guard of the quasi-Newton solvers.
//!
//! argmin's BFGS and L-BFGS (0.11) update their inverse Hessian with `rho =
//! 1 / (y . s)` whatever its sign (`s` the step, `y` the change of the
//! gradient along it). After a step along which the gradient did not grow
//! (`y . s <= 0`: the Moré-Thuente line search stopped without the curvature
//! condition, or the gradient disagrees with the cost, as the exact
//! sensitivities of a forward model solved to a tolerance can at the noise
//! floor) the next direction is an ascent one and the line search refuses it
//! ("Search direction must be a descent direction"). argmin has no switch to
//! skip such an update, and its solvers' state is private, so this wrapper
//! does the classical reset around them: after a step with `y . s <=
//! sqrt(eps) |y| |s|` it restarts from the best point seen with the initial
//! inverse Hessian (BFGS) or an empty memory (L-BFGS). A run whose steps
//! keep ending so, more than [`MAX_RESETS_IN_A_ROW`] resets in a row, has
//! reached the cost's noise floor (or a kink): it stops at the best point
//! with that reason, which a fit reports as not converged.

use argmin::core::{
    CostFunction, Error, Gradient, IterState, Problem, Solver, State, TerminationReason,
    TerminationStatus, KV,
};

/// Resets in a row (steps from the initial inverse Hessian whose curvature
/// was again not positive) after which a run stops.
pub const MAX_RESETS_IN_A_ROW: usize = 3;

/// What a reset restores.
#[derive(Clone)]
pub(crate) enum Restart<S, H> {
    /// BFGS: the initial inverse Hessian, put back in the state.
    InverseHessian(H),
    /// L-BFGS: the solver as built, with no correction pair in memory.
    Memory(S),
}

/// A quasi-Newton solver that forgets its curvature after a step whose
/// `y . s` is not positive (see the module's text).
pub(crate) struct CurvatureGuard<S, H> {
    solver: S,
    restart: Restart<S, H>,
    name: &'static str,
    /// Resets in a row.
    in_a_row: usize,
    /// Iterations since the last reset: the L-BFGS solver sees these as its
    /// iteration count, which decides when its memory is full.
    since_reset: u64,
}

impl<S: Clone, H> CurvatureGuard<S, H> {
    pub(crate) fn new(solver: S, restart: Restart<S, H>, name: &'static str) -> Self {
        CurvatureGuard {
            solver,
            restart,
            name,
            in_a_row: 0,
            since_reset: 0,
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Whether the step `s` with gradient change `y` has a curvature too small
/// to keep: `y . s <= sqrt(eps) |y| |s|` (zero or NaN included).
pub(crate) fn curvature_not_positive(s: &[f64], y: &[f64]) -> bool {
    let ys = dot(y, s);
    let scale = f64::EPSILON.sqrt() * dot(y, y).sqrt() * dot(s, s).sqrt();
    ys.is_nan() || ys <= scale
}

/// Whether an inverse Hessian's direction `-H g` descends (`g . H g > 0`).
pub(crate) trait Descent {
    fn descends(&self, g: &[f64]) -> bool;
}

/// L-BFGS keeps no inverse Hessian in the state.
impl Descent for () {
    fn descends(&self, _g: &[f64]) -> bool {
        true
    }
}

impl Descent for Vec<Vec<f64>> {
    fn descends(&self, g: &[f64]) -> bool {
        let ghg: f64 = self.iter().zip(g).map(|(row, gi)| gi * dot(row, g)).sum();
        ghg.is_finite() && ghg > 0.0
    }
}

type QnState<H> = IterState<Vec<f64>, Vec<f64>, (), H, (), f64>;

impl<O, S, H> Solver<O, QnState<H>> for CurvatureGuard<S, H>
where
    O: CostFunction<Param = Vec<f64>, Output = f64>
        + Gradient<Param = Vec<f64>, Gradient = Vec<f64>>,
    S: Solver<O, QnState<H>> + Clone,
    H: Clone + Descent,
{
    fn name(&self) -> &str {
        self.name
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        state: QnState<H>,
    ) -> Result<(QnState<H>, Option<KV>), Error> {
        self.solver.init(problem, state)
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        mut state: QnState<H>,
    ) -> Result<(QnState<H>, Option<KV>), Error> {
        // an update that passed the curvature test can still leave, by
        // round-off, an inverse Hessian whose direction does not descend
        if let (Some(h), Some(g), Restart::InverseHessian(h0)) =
            (state.get_inv_hessian(), state.get_gradient(), &self.restart)
        {
            if !h.descends(g) {
                state = state.inv_hessian(h0.clone());
            }
        }
        let x0 = state.get_param().cloned();
        let g0 = state.get_gradient().cloned();
        let iter = state.get_iter();
        state.iter = self.since_reset;
        let (mut state, kv) = self.solver.next_iter(problem, state)?;
        state.iter = iter;
        self.since_reset += 1;
        if state.terminated() {
            return Ok((state, kv));
        }
        let (Some(x0), Some(g0), Some(x1), Some(g1)) =
            (x0, g0, state.get_param(), state.get_gradient())
        else {
            return Ok((state, kv));
        };
        let s: Vec<f64> = x1.iter().zip(&x0).map(|(a, b)| a - b).collect();
        let y: Vec<f64> = g1.iter().zip(&g0).map(|(a, b)| a - b).collect();
        if !curvature_not_positive(&s, &y) {
            self.in_a_row = 0;
            return Ok((state, kv));
        }
        self.in_a_row += 1;
        if self.in_a_row > MAX_RESETS_IN_A_ROW {
            let why = format!(
                "the gradient did not grow along {} steps in a row (curvature y . s <= 0), each \
                 but the first taken from the initial inverse Hessian at the best point: stopped \
                 at the best point, where the gradient disagrees with the cost (the noise floor \
                 of a forward model solved to a tolerance, or a cost that is not smooth)",
                self.in_a_row
            );
            return Ok((state.terminate_with(TerminationReason::SolverExit(why)), kv));
        }
        // back to the best point seen when the step ended above it
        let best = state.get_best_param().cloned();
        if let Some(best) = best.filter(|_| state.get_cost() > state.get_best_cost()) {
            let cost = state.get_best_cost();
            let grad = problem.gradient(&best)?;
            state = state.param(best).cost(cost).gradient(grad);
        }
        match &self.restart {
            Restart::InverseHessian(h0) => state = state.inv_hessian(h0.clone()),
            Restart::Memory(fresh) => self.solver = fresh.clone(),
        }
        self.since_reset = 0;
        Ok((state, kv))
    }

    fn terminate(&mut self, state: &QnState<H>) -> TerminationStatus {
        self.solver.terminate(state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use argmin::core::{Executor, TerminationReason};
    use argmin::solver::linesearch::MoreThuenteLineSearch;
    use argmin::solver::quasinewton::{BFGS, LBFGS};

    /// A deterministic noise in [-1, 1] from the bits of `x` (as a forward
    /// model solved to a tolerance gives: repeatable, not smooth).
    fn noise(x: f64, seed: u64) -> f64 {
        let mut h = x.to_bits() ^ seed.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        (h as f64 / u64::MAX as f64) * 2.0 - 1.0
    }

    /// `sum (x_i - 1)^2` whose cost and gradient each carry such a noise of
    /// amplitude `A`: far from the minimum they agree, near it the gradient
    /// disagrees with the cost, and a step can end where the gradient did
    /// not grow.
    struct Noisy;
    const A: f64 = 1e-6;

    impl CostFunction for Noisy {
        type Param = Vec<f64>;
        type Output = f64;
        fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
            Ok(x.iter().map(|v| (v - 1.0).powi(2)).sum::<f64>() + A * noise(x[0], 7))
        }
    }

    impl Gradient for Noisy {
        type Param = Vec<f64>;
        type Gradient = Vec<f64>;
        fn gradient(&self, x: &Vec<f64>) -> Result<Vec<f64>, Error> {
            Ok(x.iter()
                .enumerate()
                .map(|(i, v)| 2.0 * (v - 1.0) + A * noise(*v, 11 + i as u64))
                .collect())
        }
    }

    /// `(x - 1)^2` whose "gradient" is the constant 2: it never grows
    /// along a step.
    struct Flat;

    impl CostFunction for Flat {
        type Param = Vec<f64>;
        type Output = f64;
        fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
            Ok((x[0] - 1.0).powi(2))
        }
    }

    impl Gradient for Flat {
        type Param = Vec<f64>;
        type Gradient = Vec<f64>;
        fn gradient(&self, _x: &Vec<f64>) -> Result<Vec<f64>, Error> {
            Ok(vec![2.0])
        }
    }

    fn eye(n: usize) -> Vec<Vec<f64>> {
        (0..n)
            .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
            .collect()
    }

    fn bfgs() -> BFGS<MoreThuenteLineSearch<Vec<f64>, Vec<f64>, f64>, f64> {
        BFGS::new(MoreThuenteLineSearch::new())
            .with_tolerance_grad(1e-12)
            .and_then(|s| s.with_tolerance_cost(1e-16))
            .unwrap()
    }

    type Lbfgs = LBFGS<MoreThuenteLineSearch<Vec<f64>, Vec<f64>, f64>, Vec<f64>, Vec<f64>, f64>;

    fn lbfgs() -> Lbfgs {
        LBFGS::new(MoreThuenteLineSearch::new(), 5)
            .with_tolerance_grad(1e-12)
            .and_then(|s| s.with_tolerance_cost(1e-16))
            .unwrap()
    }

    /// argmin's BFGS alone stops on the ascent direction its update makes
    /// after a step with `y . s <= 0`; guarded, it reaches the minimum from
    /// the same starts.
    #[test]
    fn bfgs_resets_where_the_gradient_did_not_grow() {
        for x0 in [5.0, -3.0, 0.3, 2.5] {
            let plain = Executor::new(Noisy, bfgs())
                .configure(|s| s.param(vec![x0; 2]).inv_hessian(eye(2)).max_iters(200))
                .run();
            let e = plain.err().map(|e| e.to_string()).unwrap_or_default();
            assert!(e.contains("descent direction"), "start {x0}: {e:?}");

            let guarded = CurvatureGuard::new(bfgs(), Restart::InverseHessian(eye(2)), "BFGS");
            let r = Executor::new(Noisy, guarded)
                .configure(|s| s.param(vec![x0; 2]).inv_hessian(eye(2)).max_iters(200))
                .run()
                .unwrap_or_else(|e| panic!("start {x0}: {e}"));
            let best = r.state.get_best_param().unwrap();
            assert!(
                best.iter().all(|v| (v - 1.0).abs() < 1e-2),
                "start {x0}: {best:?}"
            );
            assert!(r.state.get_best_cost() < 1e-4, "start {x0}");
        }
    }

    /// argmin's L-BFGS alone keeps the pair and gives up with its line
    /// search ("Line search terminated"); guarded, it forgets its memory
    /// and reaches the minimum.
    #[test]
    fn lbfgs_forgets_its_memory_where_the_gradient_did_not_grow() {
        let mut plain_gave_up = 0;
        for x0 in [5.0, -3.0, 0.3, 2.5] {
            let plain = Executor::new(Noisy, lbfgs())
                .configure(|s| s.param(vec![x0; 2]).max_iters(200))
                .run()
                .unwrap();
            if let Some(TerminationReason::SolverExit(why)) = plain.state.get_termination_reason() {
                assert!(why.contains("descent direction"), "start {x0}: {why}");
                plain_gave_up += 1;
            }
            let guarded = CurvatureGuard::<_, ()>::new(lbfgs(), Restart::Memory(lbfgs()), "L-BFGS");
            let r = Executor::new(Noisy, guarded)
                .configure(|s| s.param(vec![x0; 2]).max_iters(200))
                .run()
                .unwrap_or_else(|e| panic!("start {x0}: {e}"));
            let reason = r.state.get_termination_reason();
            assert!(
                !matches!(reason, Some(TerminationReason::SolverExit(_))),
                "start {x0}: {reason:?}"
            );
            let best = r.state.get_best_param().unwrap();
            assert!(
                best.iter().all(|v| (v - 1.0).abs() < 1e-2),
                "start {x0}: {best:?}"
            );
        }
        assert!(plain_gave_up > 0, "the unguarded L-BFGS never gave up");
    }

    /// A gradient that never grows along a step: after
    /// `MAX_RESETS_IN_A_ROW` resets the run stops at its best point with
    /// the reason, which a fit does not count as convergence.
    #[test]
    fn a_gradient_that_never_grows_stops_the_run_with_its_reason() {
        let guarded = CurvatureGuard::new(bfgs(), Restart::InverseHessian(eye(1)), "BFGS");
        let r = Executor::new(Flat, guarded)
            .configure(|s| s.param(vec![5.0]).inv_hessian(eye(1)).max_iters(200))
            .run()
            .unwrap();
        let reason = r.state.get_termination_reason().cloned();
        let Some(TerminationReason::SolverExit(why)) = reason.clone() else {
            panic!("{reason:?}");
        };
        assert!(
            why.contains(&format!("{} steps in a row", MAX_RESETS_IN_A_ROW + 1)),
            "{why}"
        );
        assert!(!crate::Termination::QuasiNewton(why).converged());
        assert_eq!(r.state.get_iter(), MAX_RESETS_IN_A_ROW as u64 + 1);
        // the best point is below the start
        assert!(r.state.get_best_cost() < 16.0);
    }

    #[test]
    fn the_descent_test() {
        let h = vec![vec![1.0, 0.0], vec![0.0, 2.0]];
        assert!(h.descends(&[1.0, -1.0]));
        let indefinite = vec![vec![1.0, 0.0], vec![0.0, -2.0]];
        assert!(!indefinite.descends(&[0.1, 1.0]));
        assert!(!vec![vec![f64::NAN]].descends(&[1.0]));
        assert!(().descends(&[1.0]));
    }

    #[test]
    fn the_curvature_test() {
        assert!(!curvature_not_positive(&[1.0, 0.0], &[0.5, 0.1]));
        assert!(curvature_not_positive(&[1.0, 0.0], &[-0.5, 0.1]));
        assert!(curvature_not_positive(&[0.0, 0.0], &[0.0, 0.0]));
        assert!(curvature_not_positive(&[1.0], &[f64::NAN]));
        // positive but below sqrt(eps) |y| |s|: too small to keep
        assert!(curvature_not_positive(&[1.0, 0.0], &[1e-9, 1.0]));
    }
}
