//! Wall slide: reaching optima on an admissibility limit that is not a box
//! bound.
//!
//! A law may reject parameters inside the box bounds (Mooney-Rivlin:
//! `C10 + C01 > 0`, [`palpate_core::ForwardError::InvalidParameter`]). The
//! estimators meet such a limit only as failed evaluations: LM rejects the
//! step, raises the damping and stops against the limit, short of the
//! constrained optimum further along it (Treloar, Mooney-Rivlin uniaxial
//! absolute: SSE +1.0 %).
//!
//! When a Levenberg-Marquardt run ends with a failed trial step, this
//! continues from its optimum `z` with the limit treated as an unknown
//! constraint, learned from feasibility alone (no constraint function is
//! available):
//!
//! 1. Gauss-Newton step `h = -J^+ r`; if `z + h` evaluates, there is no
//!    blocking limit and the slide stops. Otherwise bisection gives the
//!    largest admissible fraction `t0` of `h` (the wall point `w0 = z + t0 h`).
//! 2. The wall's normal `n` at `w0`: from `q` nearby points `z + eps e_j`,
//!    the same bisection along `h` gives wall points `w_j`; the differences
//!    `w_j - w0` span the wall's tangent plane, and `n` is their smallest
//!    right singular vector.
//! 3. Step: halfway to the wall along `h`, plus the Gauss-Newton step
//!    restricted to the tangent plane (`min ||r + J P y||`, `P = I - n n^T`),
//!    halved until it evaluates and lowers the SSE. Iterates stay strictly
//!    admissible and approach the wall geometrically while moving along it:
//!    a gradient-projection method (Rosen 1960) with a learned active
//!    constraint.
//!
//! Repeated while the SSE drops. Runs only after a blocked LM run, so fits
//! that end in the interior pay nothing.

use crate::run::RunOutcome;
use crate::{jacobian_unbounded, sum_of_squares, FdOptions, Objective};
use nalgebra::{DMatrix, DVector};

/// Slide iterations at most.
const MAX_SLIDES: usize = 200;
/// Bisection steps for the largest admissible fraction (2^-40 ~ 1e-12).
const BISECTIONS: usize = 40;
/// Halvings of the tangent step (and of a wall fraction's bracket) at most.
const MAX_HALVINGS: usize = 40;
/// Stop when one slide lowers the SSE by less than this (relative).
const MIN_GAIN: f64 = 1e-13;

struct Walker<'a> {
    objective: &'a Objective,
    evaluators: crate::Evaluators<'a>,
    evaluations: usize,
}

impl Walker<'_> {
    /// Residuals and SSE at `z`, `None` when the evaluation fails.
    fn eval(&mut self, z: &[f64]) -> Option<(Vec<f64>, f64)> {
        self.evaluations += 1;
        let r = self
            .objective
            .residuals(&mut self.evaluators, z, "wall slide")
            .ok()?;
        let sse = sum_of_squares(&r);
        sse.is_finite().then_some((r, sse))
    }

    fn admissible(&mut self, z: &[f64]) -> bool {
        self.eval(z).is_some()
    }

    /// Largest admissible fraction of `h` from the admissible `z`, given an
    /// inadmissible fraction `hi`; `None` if `z + hi h` is admissible.
    fn wall_fraction(&mut self, z: &[f64], h: &[f64], hi: f64) -> Option<f64> {
        let at = |t: f64| -> Vec<f64> { z.iter().zip(h).map(|(a, b)| a + t * b).collect() };
        if self.admissible(&at(hi)) {
            return None;
        }
        // Bracket by halving first, so the bisection below is accurate
        // relative to the fraction itself, however close the wall is (the
        // slide approaches it geometrically; an absolute 2^-40 would leave
        // the normal of step 2 to round-off near the wall).
        let (mut lo, mut hi) = (0.0, hi);
        for _ in 0..MAX_HALVINGS {
            let half = 0.5 * hi;
            if self.admissible(&at(half)) {
                lo = half;
                break;
            }
            hi = half;
        }
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if self.admissible(&at(mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(lo)
    }
}

/// Least-squares solution of `A x ~ b` by SVD on unit-scaled columns,
/// singular values below `1e-12` of the largest dropped.
fn solve(a: &DMatrix<f64>, b: &[f64]) -> Option<Vec<f64>> {
    let norms: Vec<f64> = (0..a.ncols())
        .map(|c| {
            let n = a.column(c).norm();
            if n > 0.0 {
                n
            } else {
                1.0
            }
        })
        .collect();
    let mut s = a.clone();
    for (c, n) in norms.iter().enumerate() {
        s.column_mut(c).scale_mut(n.recip());
    }
    let svd = s.svd(true, true);
    let cut = 1e-12 * svd.singular_values.max();
    let y = svd.solve(&DVector::from_column_slice(b), cut).ok()?;
    let x: Vec<f64> = y.iter().zip(&norms).map(|(v, n)| v / n).collect();
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Whether the fit at `z` stopped on an admissibility limit: the
/// Gauss-Newton step from `z` reaches parameters the model refuses, so the
/// unconstrained minimum the local model points to lies beyond the limit.
/// At an interior minimum that step is tiny and evaluates.
pub(crate) fn limit_ahead(objective: &Objective, fd: &FdOptions, z: &[f64]) -> bool {
    let mut w = Walker {
        objective,
        evaluators: objective.evaluators(),
        evaluations: 0,
    };
    let Some((r, _)) = w.eval(z) else {
        return false;
    };
    let Ok(jac) = jacobian_unbounded(objective, z, Some(&r), fd) else {
        return false;
    };
    let minus_r: Vec<f64> = r.iter().map(|v| -v).collect();
    let Some(h) = solve(&jac.matrix, &minus_r) else {
        return false;
    };
    let ahead: Vec<f64> = z.iter().zip(&h).map(|(a, b)| a + b).collect();
    !w.admissible(&ahead)
}

/// Continues a blocked run along the limit it ran into; `None` when nothing
/// lowered the SSE. No slide starts once `budget` evaluations are spent
/// (the run's own budget, [`crate::fit`]): near a limit the SSE can keep
/// dropping by tiny amounts for every one of [`MAX_SLIDES`] slides, each of
/// which costs a Jacobian and some hundred bisection evaluations (measured
/// on a compressible neo-Hookean law with relaxation: 72,000 evaluations,
/// 200 slides, after a run of 1,500).
pub(crate) fn wall_slide(
    objective: &Objective,
    fd: &FdOptions,
    outcome: &RunOutcome,
    budget: usize,
) -> Option<RunOutcome> {
    let mut w = Walker {
        objective,
        evaluators: objective.evaluators(),
        evaluations: 0,
    };
    let mut jacobians = 0;
    let q = outcome.z.len();
    let mut z = outcome.z.clone();
    let (mut r, mut sse) = w.eval(&z)?;
    let mut iterations = 0;
    for _ in 0..MAX_SLIDES {
        if w.evaluations >= budget {
            break;
        }
        let Ok(jac) = jacobian_unbounded(objective, &z, Some(&r), fd) else {
            break;
        };
        w.evaluations += jac.evaluations;
        jacobians += 1;
        let j = jac.matrix;
        let minus_r: Vec<f64> = r.iter().map(|v| -v).collect();
        let Some(h) = solve(&j, &minus_r) else {
            break;
        };
        // 1. The wall along the Gauss-Newton step.
        let Some(t0) = w.wall_fraction(&z, &h, 1.0) else {
            break;
        };
        let hnorm = h.iter().map(|v| v * v).sum::<f64>().sqrt();
        let eps = 0.1 * t0 * hnorm;
        if eps.is_nan() || eps <= 0.0 {
            break;
        }
        let w0: Vec<f64> = z.iter().zip(&h).map(|(a, b)| a + t0 * b).collect();
        // 2. The wall's normal from q more wall points.
        let mut diffs = DMatrix::zeros(q, q);
        let mut ok = true;
        for c in 0..q {
            let mut zc = z.clone();
            zc[c] += eps;
            if !w.admissible(&zc) {
                zc[c] = z[c] - eps;
            }
            let Some(tc) = [2.0, 4.0, 8.0]
                .iter()
                .find_map(|&hi| w.wall_fraction(&zc, &h, hi * t0.max(1e-300)))
            else {
                ok = false;
                break;
            };
            for k in 0..q {
                diffs[(c, k)] = zc[k] + tc * h[k] - w0[k];
            }
        }
        if !ok {
            break;
        }
        let svd = diffs.svd(false, true);
        let Some(vt) = svd.v_t else {
            break;
        };
        let smallest = svd
            .singular_values
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .map(|(i, _)| i)?;
        let n: Vec<f64> = vt.row(smallest).iter().copied().collect();
        // 3. Tangent Gauss-Newton step: min ||r + J P y||, h_t = P y.
        let mut p = DMatrix::<f64>::identity(q, q);
        for a in 0..q {
            for b in 0..q {
                p[(a, b)] -= n[a] * n[b];
            }
        }
        let jp = &j * &p;
        let ht: Vec<f64> = match solve(&jp, &minus_r) {
            Some(y) => (&p * DVector::from_vec(y)).iter().copied().collect(),
            None => vec![0.0; q],
        };
        let base: Vec<f64> = z.iter().zip(&h).map(|(a, b)| a + 0.5 * t0 * b).collect();
        let mut alpha = 1.0;
        let mut accepted = None;
        for _ in 0..MAX_HALVINGS {
            let trial: Vec<f64> = base.iter().zip(&ht).map(|(a, b)| a + alpha * b).collect();
            if let Some((rt, st)) = w.eval(&trial) {
                if st < sse {
                    accepted = Some((trial, rt, st));
                    break;
                }
            }
            alpha *= 0.5;
        }
        let Some((zn, rn, sn)) = accepted else {
            break;
        };
        let gain = sse - sn;
        z = zn;
        r = rn;
        sse = sn;
        iterations += 1;
        if gain <= MIN_GAIN * sse {
            break;
        }
    }
    (sse < outcome.sse).then(|| RunOutcome {
        exact: None,
        z,
        sse,
        iterations,
        evaluations: w.evaluations,
        jacobians,
        termination: outcome.termination.clone(),
        blocked: true,
    })
}
