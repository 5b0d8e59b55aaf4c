//! How far along a Newton update the solver steps.
//!
//! Two searches:
//!
//! * [`LineSearch::Residual`]: Armijo backtracking on the residual norm,
//!   `|R(u + a du)| <= (1 - 1e-4 a) |R(u)|`, by halves down to 1/16. Safe
//!   for any tangent; with a stiff penalty it rejects good steps whose
//!   residual rises at a few contact nodes while the body as a whole moves
//!   the right way.
//! * [`LineSearch::Slope`]: the slope search of Crisfield (1991,
//!   *Non-linear Finite Element Analysis of Solids and Structures*, vol. 1,
//!   section 9.3; Matthies and Strang 1979): for a problem with a potential
//!   `Pi` (hyperelastic bodies and frictionless penalty contact) the
//!   residual is its gradient, so `g(a) = du . R(u + a du)` is the slope of
//!   `Pi` along the update and its root is the energy minimum on the line.
//!   The full step is kept when `g(1) <= 0` (the energy still falls) or
//!   `|g(1)| <= eta |g(0)|`; otherwise the root is bracketed and found by
//!   regula falsi (safeguarded to the inner 80 % of the bracket), to the
//!   same tolerance. A trial whose assembly fails (an inverted element)
//!   counts as an overshoot. No energy is evaluated: only residuals, which
//!   the solver assembles anyway. Only for symmetric tangents of a
//!   potential problem (`g(0) = -R K^-1 R < 0`); the solver falls back to
//!   the residual search when `g(0) >= 0`.
//!
//! Written here rather than taken from argmin: argmin's line searches
//! (More-Thuente, Hager-Zhang, backtracking) need the objective value,
//! which the FE layer does not assemble, and work on its own state types.

use crate::FeError;

/// The line search of the Newton solver ([`crate::SolverOptions::line_search`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LineSearch {
    /// Armijo backtracking on the residual norm (any problem).
    #[default]
    Residual,
    /// Root of the slope `du . R(u + a du)` (potential problems: symmetric
    /// tangents, frictionless contact).
    Slope,
}

/// Slope tolerance `eta` of the search: `|g(a)| <= eta |g(0)|`.
pub(crate) const SLOPE_TOLERANCE: f64 = 0.5;

/// Trials of one search (the last one is taken whatever its slope).
pub(crate) const SLOPE_TRIALS: usize = 6;

/// The step length `a` of a slope search, given the slope `g0 < 0` at
/// `a = 0` and `trial(a)`, which moves the state to `u + a du`, assembles
/// it and returns `g(a)`. The state is left at the returned `a` (it is the
/// last trial). Errors only when every trial fails to assemble (the last
/// error is returned).
pub(crate) fn slope_search(
    g0: f64,
    mut trial: impl FnMut(f64) -> Result<f64, FeError>,
) -> Result<f64, FeError> {
    let (mut lo, mut g_lo) = (0.0, g0);
    let mut hi: Option<(f64, f64)> = None;
    let mut alpha = 1.0;
    let mut last_err = None;
    for k in 0..SLOPE_TRIALS {
        let last = k + 1 == SLOPE_TRIALS;
        match trial(alpha) {
            Ok(g) => {
                if last || g.abs() <= SLOPE_TOLERANCE * g0.abs() || (g <= 0.0 && hi.is_none()) {
                    return Ok(alpha);
                }
                if g < 0.0 {
                    (lo, g_lo) = (alpha, g);
                } else {
                    hi = Some((alpha, g));
                }
            }
            Err(e) => {
                last_err = Some(e);
                hi = Some((alpha, f64::INFINITY));
            }
        }
        let (ah, gh) = hi.expect("an overshoot bracket");
        let width = ah - lo;
        alpha = if gh.is_finite() {
            let root = lo - g_lo * width / (gh - g_lo);
            root.clamp(lo + 0.1 * width, ah - 0.1 * width)
        } else {
            lo + 0.5 * width
        };
    }
    Err(last_err.unwrap_or(FeError::NewtonFailed {
        iterations: 0,
        residual: f64::NAN,
        tolerance: f64::NAN,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a quadratic energy along the line the slope is linear: one
    /// regula falsi step lands on its root.
    #[test]
    fn linear_slope_is_solved_in_one_interpolation() {
        // g(a) = -1 + 4 a: the minimum at a = 0.25
        let mut trials = Vec::new();
        let a = slope_search(-1.0, |a| {
            trials.push(a);
            Ok(-1.0 + 4.0 * a)
        })
        .unwrap();
        assert_eq!(trials, vec![1.0, 0.25]);
        assert!((a - 0.25).abs() < 1e-15);
    }

    #[test]
    fn full_step_is_kept_while_the_energy_falls() {
        let a = slope_search(-1.0, |_| Ok(-0.9)).unwrap();
        assert_eq!(a, 1.0);
        let a = slope_search(-1.0, |_| Ok(0.4)).unwrap();
        assert_eq!(a, 1.0);
    }

    /// A failed assembly is an overshoot: the search bisects towards 0 and
    /// then interpolates once it has a finite slope beyond the root.
    #[test]
    fn failed_trials_bisect_then_interpolate() {
        // g(a) = -1 + 8 a (root 0.125), assembly fails above a = 0.6
        let mut trials = Vec::new();
        let a = slope_search(-1.0, |a| {
            trials.push(a);
            if a > 0.6 {
                Err(FeError::InvertedElement {
                    element: 0,
                    det_f: -1.0,
                })
            } else {
                Ok(-1.0 + 8.0 * a)
            }
        })
        .unwrap();
        assert_eq!(trials[..2], [1.0, 0.5]);
        assert!((a - 0.125).abs() < 1e-12, "{trials:?}");
    }

    #[test]
    fn every_trial_failing_is_an_error() {
        let r = slope_search(-1.0, |_| {
            Err(FeError::InvertedElement {
                element: 3,
                det_f: -1.0,
            })
        });
        assert!(matches!(
            r,
            Err(FeError::InvertedElement { element: 3, .. })
        ));
    }
}
