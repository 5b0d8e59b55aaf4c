//! Finite-difference Jacobians: the one implementation that the estimators
//! (`palpate-inverse`), the gap diagnosis and the samplers (`palpate-uq`) and
//! [`ModelExt::fd_jacobian`](crate::ModelExt::fd_jacobian) share.
//!
//! **Step rule.** Coordinate `j` is stepped by
//! `h_j = relative_step * max(|x_j|, typical_j)`, where `typical_j` is a
//! scale that does not vanish: 1 for an unbounded coordinate
//! ([`FdRule::unbounded_step`]) and [`param_scale`] for a physical parameter
//! ([`FdRule::param_step`]), which stays positive at an "off" point such as
//! g = 0. The default relative step `eps^(1/3) ~ 6e-6` is the optimum for
//! central differences of a smooth function computed to machine precision;
//! callers whose function is only accurate to a solver tolerance pass a
//! larger one.
//!
//! **Bounds and failures.** A step that would leave `[lower, upper]` is not
//! taken; the column is then a one-sided difference into the interior
//! through the base point. When a step is taken but the function fails there
//! (e.g. the law's admissible domain ends before the bound), the other side
//! is used the same way. The quotient divides by the step actually taken,
//! `(x_j + h) - x_j`, not by `h`.
//!
//! Columns are independent: a caller that wants them in parallel maps
//! [`fd_column`] over `j` (with one evaluator per thread); each column is
//! computed by the same arithmetic whatever the thread, so the result is
//! bit-identical to the serial [`fd_jacobian`].
//!
//! ```
//! use palpate_core::fd::{fd_jacobian, FdRule};
//! // f(x) = (x0^2, x0 x1) at (3, 2): Jacobian columns (6, 2) and (0, 3).
//! let mut f = |x: &[f64], out: &mut [f64]| -> Result<(), ()> {
//!     out[0] = x[0] * x[0];
//!     out[1] = x[0] * x[1];
//!     Ok(())
//! };
//! let x = [3.0, 2.0];
//! let rule = FdRule::default();
//! let steps: Vec<_> = x.iter().map(|&xj| rule.unbounded_step(xj)).collect();
//! let (cols, evaluations) = fd_jacobian(&mut f, &x, &steps, None, 2).unwrap();
//! assert_eq!(evaluations, 4);
//! assert!((cols[0][0] - 6.0).abs() < 1e-8 && (cols[0][1] - 2.0).abs() < 1e-8);
//! assert!(cols[1][0].abs() < 1e-8 && (cols[1][1] - 3.0).abs() < 1e-8);
//! ```

use crate::ParamSpec;

/// Central (two evaluations per column, error O(h^2)) or forward (one per
/// column given the base point, error O(h)) differences.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FdScheme {
    Central,
    Forward,
}

/// The step rule `h = relative_step * max(|x|, typical)` and the scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FdRule {
    /// Relative step; must lie in (0, 1).
    pub relative_step: f64,
    pub scheme: FdScheme,
}

impl Default for FdRule {
    /// Central differences with `relative_step = eps^(1/3)`.
    fn default() -> Self {
        FdRule {
            relative_step: f64::EPSILON.cbrt(),
            scheme: FdScheme::Central,
        }
    }
}

impl FdRule {
    /// Central differences with the given relative step.
    pub fn central(relative_step: f64) -> Self {
        FdRule {
            relative_step,
            scheme: FdScheme::Central,
        }
    }

    /// The step of a coordinate at `x` with scale `typical`.
    pub fn step(&self, x: f64, typical: f64) -> f64 {
        self.relative_step * x.abs().max(typical)
    }

    /// The step of an unbounded coordinate (typical scale 1, no bounds).
    pub fn unbounded_step(&self, z: f64) -> FdStep {
        FdStep {
            h: self.step(z, 1.0),
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            scheme: self.scheme,
        }
    }

    /// The step of a physical parameter at `x`: typical scale
    /// [`param_scale`], kept inside the parameter's bounds.
    pub fn param_step(&self, spec: &ParamSpec, x: f64) -> FdStep {
        FdStep {
            h: self.step(x, param_scale(spec)),
            lower: spec.lower,
            upper: spec.upper,
            scheme: self.scheme,
        }
    }
}

/// A scale of a physical parameter that does not vanish at an "off" point:
/// `max(|initial|, 1e-3 x (upper - lower) when finite, 1e-8)`.
pub fn param_scale(spec: &ParamSpec) -> f64 {
    let range = spec.upper - spec.lower;
    let range_scale = if range.is_finite() { 1e-3 * range } else { 0.0 };
    spec.initial.abs().max(range_scale).max(1e-8)
}

/// How one coordinate is differenced: step, bounds and scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FdStep {
    pub h: f64,
    pub lower: f64,
    pub upper: f64,
    pub scheme: FdScheme,
}

/// Column `j` of the Jacobian of `f: R^q -> R^m` at `x`, written into `col`
/// (`col.len() == m`): `col[i] = d f_i / d x_j`. `f(x, out)` writes `m`
/// values. `base` is `f(x)` when the caller has it (forward differences and
/// one-sided columns need it; it is evaluated here otherwise). Returns the
/// number of evaluations of `f`. When no step fits inside the bounds the
/// column is zero; when every step taken fails, the first error is returned.
pub fn fd_column<E, F>(
    f: &mut F,
    x: &[f64],
    j: usize,
    step: FdStep,
    base: Option<&[f64]>,
    col: &mut [f64],
) -> Result<usize, E>
where
    F: FnMut(&[f64], &mut [f64]) -> Result<(), E> + ?Sized,
{
    let m = col.len();
    let xj = x[j];
    let (up, down) = (xj + step.h, xj - step.h);
    let can_up = step.h > 0.0 && up <= step.upper;
    let can_down = step.h > 0.0 && down >= step.lower;
    let mut xs = x.to_vec();
    let mut evaluations = 0;
    let mut at = |t: f64, out: &mut [f64]| -> Result<(), E> {
        xs[j] = t;
        evaluations += 1;
        f(&xs, out)
    };
    // `col` receives f(x + h), `other` f(x - h).
    let mut other = vec![0.0; m];
    let plus = can_up.then(|| at(up, col));
    let plus_ok = matches!(plus, Some(Ok(())));
    // Forward differences need x - h only when x + h is out of reach or failed.
    let minus =
        (can_down && !(step.scheme == FdScheme::Forward && plus_ok)).then(|| at(down, &mut other));
    let minus_ok = matches!(minus, Some(Ok(())));
    if !plus_ok && !minus_ok {
        return match (plus, minus) {
            (Some(Err(e)), _) | (_, Some(Err(e))) => Err(e),
            _ => {
                col.fill(0.0);
                Ok(0)
            }
        };
    }
    if plus_ok && minus_ok {
        for (c, o) in col.iter_mut().zip(&other) {
            *c = (*c - o) / (up - down);
        }
    } else {
        let owned;
        let b: &[f64] = match base {
            Some(b) => b,
            None => {
                let mut v = vec![0.0; m];
                at(xj, &mut v)?;
                owned = v;
                &owned
            }
        };
        if plus_ok {
            for (c, b) in col.iter_mut().zip(b) {
                *c = (*c - b) / (up - xj);
            }
        } else {
            for ((c, b), o) in col.iter_mut().zip(b).zip(&other) {
                *c = (b - o) / (xj - down);
            }
        }
    }
    Ok(evaluations)
}

/// The whole Jacobian of `f: R^q -> R^m` at `x`, serially, as columns
/// (`cols[j][i] = d f_i / d x_j`), and the evaluations it cost; `steps[j]`
/// says how coordinate `j` is differenced. See [`fd_column`].
pub fn fd_jacobian<E, F>(
    f: &mut F,
    x: &[f64],
    steps: &[FdStep],
    base: Option<&[f64]>,
    m: usize,
) -> Result<(Vec<Vec<f64>>, usize), E>
where
    F: FnMut(&[f64], &mut [f64]) -> Result<(), E> + ?Sized,
{
    let mut evaluations = 0;
    let mut owned_base = None;
    let needs_base = base.is_none()
        && steps.iter().enumerate().any(|(j, s)| {
            s.scheme == FdScheme::Forward || x[j] + s.h > s.upper || x[j] - s.h < s.lower
        });
    if needs_base {
        let mut b = vec![0.0; m];
        f(x, &mut b)?;
        evaluations += 1;
        owned_base = Some(b);
    }
    let base = base.or(owned_base.as_deref());
    let mut cols = Vec::with_capacity(x.len());
    for (j, &step) in steps.iter().enumerate() {
        let mut col = vec![0.0; m];
        evaluations += fd_column(f, x, j, step, base, &mut col)?;
        cols.push(col);
    }
    Ok((cols, evaluations))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: &[f64], out: &mut [f64]) -> Result<(), &'static str> {
        if x[0] < 0.0 {
            return Err("negative");
        }
        out[0] = x[0] * x[0];
        Ok(())
    }

    fn step(h: f64, lower: f64, upper: f64, scheme: FdScheme) -> FdStep {
        FdStep {
            h,
            lower,
            upper,
            scheme,
        }
    }

    #[test]
    fn one_sided_at_bounds_and_zero_when_pinned() {
        let mut f = square;
        let mut col = [0.0];
        // At the lower bound 0: forward difference into the interior, (h^2 - 0) / h = h.
        let n = fd_column(
            &mut f,
            &[0.0],
            0,
            step(1e-3, 0.0, 1.0, FdScheme::Central),
            None,
            &mut col,
        )
        .unwrap();
        assert_eq!(n, 2);
        assert!((col[0] - 1e-3).abs() < 1e-15);
        // At the upper bound 1: backward difference, 2 - h.
        let n = fd_column(
            &mut f,
            &[1.0],
            0,
            step(1e-3, 0.0, 1.0, FdScheme::Central),
            Some(&[1.0]),
            &mut col,
        )
        .unwrap();
        assert_eq!(n, 1);
        assert!((col[0] - (2.0 - 1e-3)).abs() < 1e-12);
        // No room: zero column, no evaluation.
        let n = fd_column(
            &mut f,
            &[0.5],
            0,
            step(1e-3, 0.5, 0.5, FdScheme::Central),
            None,
            &mut col,
        )
        .unwrap();
        assert_eq!((n, col[0]), (0, 0.0));
    }

    #[test]
    fn failed_side_falls_back_and_forward_uses_base() {
        let mut f = square;
        let mut col = [0.0];
        // Unbounded, but f fails below 0: the backward side fails, forward is used.
        let s = FdRule::default().unbounded_step(0.0);
        fd_column(&mut f, &[0.0], 0, s, None, &mut col).unwrap();
        assert!((col[0] - s.h).abs() < 1e-15);
        // Forward differences with a given base: one evaluation.
        let s = step(1e-4, f64::NEG_INFINITY, f64::INFINITY, FdScheme::Forward);
        let n = fd_column(&mut f, &[2.0], 0, s, Some(&[4.0]), &mut col).unwrap();
        assert_eq!(n, 1);
        assert!((col[0] - 4.0).abs() < 1e-3);
        // Both sides fail: the error.
        let s = step(1e-4, f64::NEG_INFINITY, f64::INFINITY, FdScheme::Central);
        assert!(fd_column(&mut f, &[-1.0], 0, s, None, &mut col).is_err());
    }
}
