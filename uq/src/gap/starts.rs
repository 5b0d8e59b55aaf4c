//! Starting points of the fits: the base model's, and an enrichment's
//! (score step, "off", a point inside a bounded range, a grid of time
//! constants), screened by one prediction each for an expensive model.

use super::fit::scale_moduli;
use palpate_core::{ForwardModel, Loading, ParamRole};
use rayon::prelude::*;

/// Starting points of the base fit: the space's initial values, and the same
/// with every modulus ([`ParamRole::Modulus`]) scaled by the least-squares
/// factor <f0, y>/<f0, f0> (exact for laws linear in their moduli); and the
/// prediction f0 at the initial values when it could be made.
pub(crate) fn base_starts(
    base: &dyn ForwardModel,
    loading: &Loading,
    observed: &[f64],
) -> (Vec<Vec<f64>>, Option<Vec<f64>>) {
    let theta0 = base.space().initial();
    let mut starts = Vec::new();
    let f0 = base.predict(&theta0, loading).ok();
    if let Some(f0) = &f0 {
        if let Some((_, scaled)) = scale_moduli(&base.space().params, &theta0, f0, observed) {
            starts.push(scaled);
        }
    }
    starts.push(theta0);
    (starts, f0)
}

/// Extra starts for the new parameters of an enrichment: its time constants
/// ([`ParamRole::TimeConstant`]) on a grid across the record's duration (one
/// decade apart between successive terms), with the relaxation weights
/// ([`ParamRole::RelaxationWeight`]) at 0.1.
fn time_constant_starts(
    rich: &dyn ForwardModel,
    p: usize,
    around: &[f64],
    duration: f64,
) -> Vec<Vec<f64>> {
    let specs = &rich.space().params;
    let mut taus: Vec<(usize, usize)> = (p..specs.len())
        .filter_map(|j| match specs[j].role {
            ParamRole::TimeConstant { term } => Some((term, j)),
            _ => None,
        })
        .collect();
    taus.sort();
    if taus.is_empty() || duration.is_nan() || duration <= 0.0 {
        return Vec::new();
    }
    let weights: Vec<usize> = (p..specs.len())
        .filter(|&j| matches!(specs[j].role, ParamRole::RelaxationWeight { .. }))
        .collect();
    [duration / 100.0, duration / 20.0, duration / 4.0]
        .iter()
        .map(|&b| {
            let mut s = around.to_vec();
            for (k, &(_, j)) in taus.iter().enumerate() {
                s[j] = b * 10f64.powi(k as i32);
            }
            for &j in &weights {
                s[j] = 0.1;
            }
            s
        })
        .collect()
}

/// A start for the new parameters of an enrichment whose "off" value sits on
/// a bound of a finite range (e.g. friction 0 in [0, 2]): a tenth of the
/// range inside it. The fits run in an unbounded transform (logit) in which
/// a bound lies at infinity, so a fit started at "off" barely moves, and the
/// Gauss-Newton step from "off" is only as good as the local sensitivity of
/// an effect that may be strongly nonlinear (friction saturates as the
/// contact sticks). `None` when no new parameter is on such a bound.
fn off_bound_start(rich: &dyn ForwardModel, p: usize, off: &[f64]) -> Option<Vec<f64>> {
    let specs = &rich.space().params;
    let mut s = off.to_vec();
    let mut moved = false;
    for j in p..specs.len() {
        let (lo, hi) = (specs[j].lower, specs[j].upper);
        let range = hi - lo;
        if !range.is_finite() || range <= 0.0 {
            continue;
        }
        if off[j] <= lo {
            s[j] = lo + 0.1 * range;
            moved = true;
        } else if off[j] >= hi {
            s[j] = hi - 0.1 * range;
            moved = true;
        }
    }
    moved.then_some(s)
}

/// For an expensive model: the starts ordered by the misfit each reaches
/// with its moduli scaled by the least-squares factor a = <f, y> / <f, f>
/// (one prediction per start; exact for laws whose energy is linear in the
/// moduli under a prescribed displacement), scaled so. The refit then runs
/// from the first and falls back on the next only when that fit fails. A
/// start whose prediction fails goes last, unscaled.
pub(crate) fn screen_starts(
    model: &dyn ForwardModel,
    loading: &Loading,
    observed: &[f64],
    starts: Vec<Vec<f64>>,
) -> Vec<Vec<f64>> {
    let specs = &model.space().params;
    let mut scored: Vec<(f64, Vec<f64>)> = starts
        .into_par_iter()
        .map(|s| {
            let Ok(f) = model.predict(&s, loading) else {
                return (f64::INFINITY, s);
            };
            let Some((a, scaled)) = scale_moduli(specs, &s, &f, observed) else {
                return (f64::INFINITY, s);
            };
            let misfit: f64 = f
                .iter()
                .zip(observed)
                .map(|(v, y)| (y - a * v).powi(2))
                .sum();
            (misfit, scaled)
        })
        .collect();
    scored.sort_by(|x, y| x.0.total_cmp(&y.0));
    scored.into_iter().map(|(_, s)| s).collect()
}

/// Starts of an enrichment's refit: the Gauss-Newton step `step` of its own
/// parameters from "off" (kept where it stays inside the bounds), a point
/// inside a bounded range whose end is "off" (when there is no time
/// constant), "off" itself, and the time-constant grid; duplicates removed.
pub(crate) fn candidate_starts(
    rich: &dyn ForwardModel,
    p: usize,
    off: &[f64],
    step: &[f64],
    duration: f64,
) -> Vec<Vec<f64>> {
    let specs = &rich.space().params;
    let mut gn = off.to_vec();
    for (k, d) in step.iter().enumerate() {
        let j = p + k;
        let x = off[j] + d;
        if x.is_finite() && x > specs[j].lower && x < specs[j].upper {
            gn[j] = x;
        }
    }
    let grid = time_constant_starts(rich, p, off, duration);
    let mut starts = vec![gn];
    if grid.is_empty() {
        starts.extend(off_bound_start(rich, p, off));
    }
    starts.push(off.to_vec());
    starts.extend(grid);
    let mut unique: Vec<Vec<f64>> = Vec::new();
    for st in starts {
        if !unique.contains(&st) {
            unique.push(st);
        }
    }
    unique
}

/// For an expensive model whose enrichment adds one parameter `j` (e.g.
/// friction): a line search on that parameter alone, the moduli eliminated
/// by their least-squares factor at every point — the variable-projection
/// objective SSE(x) = min_a ||y - a f(theta with theta_j = x)||^2 (Golub &
/// Pereyra 1973), exact for a model homogeneous in its moduli, one solve
/// per point. Levenberg-Marquardt on both parameters crawls along the
/// curved valley of a saturating effect (N1 friction: 36 solves from 0.2 to
/// 0.96, each iteration a fraction of a noise variance); this search
/// brackets the minimum by doubling steps in the parameter's unbounded
/// coordinate and narrows it by golden sections until the bracket's SSEs
/// agree to 0.1 sigma^2 (finer than any test resolves) or 12 solves. The
/// refit then starts at the best point found (scaled), and needs a few
/// iterations for its statistics. `None` when the first solve fails.
pub(crate) fn projected_line_search(
    model: &dyn ForwardModel,
    loading: &Loading,
    observed: &[f64],
    start: &[f64],
    j: usize,
    sigma: f64,
) -> Option<Vec<f64>> {
    let specs = &model.space().params;
    let spec = &specs[j];
    let eval = |z: f64| -> Option<(f64, Vec<f64>)> {
        let x = spec.from_unbounded(z);
        if !x.is_finite() || x <= spec.lower || x >= spec.upper {
            return None;
        }
        let mut theta = start.to_vec();
        theta[j] = x;
        let f = model.predict(&theta, loading).ok()?;
        let (a, scaled) = scale_moduli(specs, &theta, &f, observed)?;
        let sse: f64 = f
            .iter()
            .zip(observed)
            .map(|(v, y)| (y - a * v).powi(2))
            .sum();
        Some((sse, scaled))
    };
    let tol = 0.1 * sigma * sigma;
    let z0 = spec.to_unbounded(start[j]);
    let (s0, t0) = eval(z0)?;
    let mut solves = 1;
    let mut best = (s0, t0.clone());
    // Bracket: step 0.25 both ways (parallel), then double downhill.
    let (lo, hi) = rayon::join(|| eval(z0 - 0.25), || eval(z0 + 0.25));
    solves += 2;
    let mut pts: Vec<(f64, f64)> = vec![(z0, s0)];
    for (z, r) in [(z0 - 0.25, &lo), (z0 + 0.25, &hi)] {
        if let Some((s, t)) = r {
            pts.push((z, *s));
            if *s < best.0 {
                best = (*s, t.clone());
            }
        }
    }
    let dir = match (&lo, &hi) {
        (Some((a, _)), Some((b, _))) if a.min(*b) >= s0 => 0.0,
        (Some((a, _)), Some((b, _))) => {
            if a < b {
                -1.0
            } else {
                1.0
            }
        }
        (Some(_), None) => -1.0,
        (None, Some(_)) => 1.0,
        (None, None) => return Some(best.1),
    };
    let (mut a, mut b);
    if dir == 0.0 {
        a = z0 - 0.25;
        b = z0 + 0.25;
    } else {
        let mut step = 0.25;
        let mut z_prev = z0;
        let mut z_cur = z0 + dir * step;
        let mut s_cur = pts.iter().find(|p| p.0 == z_cur).map(|p| p.1)?;
        loop {
            step *= 2.0;
            let z_next = z_cur + dir * step;
            if solves >= 12 {
                return Some(best.1);
            }
            let Some((s_next, t_next)) = eval(z_next) else {
                // the range ends: the minimum lies on that side
                return Some(best.1);
            };
            solves += 1;
            if s_next < best.0 {
                best = (s_next, t_next);
            }
            if s_next >= s_cur || (s_cur - s_next) < tol {
                a = z_prev.min(z_next);
                b = z_prev.max(z_next);
                break;
            }
            z_prev = z_cur;
            z_cur = z_next;
            s_cur = s_next;
        }
    }
    // Golden sections of [a, b].
    const R: f64 = 0.618_033_988_749_895;
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let (mut sc, mut sd) = match rayon::join(|| eval(c), || eval(d)) {
        (Some(x), Some(y)) => {
            solves += 2;
            for (s, t) in [&x, &y] {
                if *s < best.0 {
                    best = (*s, t.clone());
                }
            }
            (x.0, y.0)
        }
        _ => return Some(best.1),
    };
    while solves < 12 && (sc - sd).abs() >= tol {
        if sc < sd {
            b = d;
            d = c;
            sd = sc;
            c = b - R * (b - a);
            let Some((s, t)) = eval(c) else { break };
            sc = s;
            if s < best.0 {
                best = (s, t);
            }
        } else {
            a = c;
            c = d;
            sc = sd;
            d = a + R * (b - a);
            let Some((s, t)) = eval(d) else { break };
            sd = s;
            if s < best.0 {
                best = (s, t);
            }
        }
        solves += 1;
    }
    Some(best.1)
}

/// Decades of the scan of [`scale_scan_start`], relative to the distance
/// from the bound to the parameter's initial value.
const SCAN_DECADES: std::ops::RangeInclusive<i32> = -2..=6;

/// For a cheap model: a start for each new parameter whose range is
/// unbounded above and whose "off" value sits on its lower bound (a
/// compliance-like parameter, such as D1 = 2 / K or c = 1 / k, "off" at 0):
/// such a parameter acts on a scale the base does not set, and its effect
/// may show only decades away from "off" (a bulk modulus comparable to the
/// shear modulus), across a plateau where the moduli absorb it and a fit
/// started near "off" stays. The parameter is scanned on a log grid,
/// `lower + g 10^k` for k in [`SCAN_DECADES`] (g the distance from the bound
/// to its initial value), the others at `off` and the moduli eliminated by
/// their least-squares factor (one prediction per point); the best point
/// becomes a start when it fits better than "off" itself. The scan runs
/// from `off` and from each of `around` (the other starts: a relaxation
/// restarted on its grid may need the parameter far from "off" too).
/// Empty when no parameter is of that kind or no point does better.
pub(crate) fn scale_scan_starts(
    rich: &dyn ForwardModel,
    p: usize,
    off: &[f64],
    around: &[Vec<f64>],
    loading: &Loading,
    observed: &[f64],
) -> Vec<Vec<f64>> {
    let specs = &rich.space().params;
    let scanned: Vec<usize> = (p..specs.len())
        .filter(|&j| {
            let s = &specs[j];
            s.lower.is_finite()
                && s.upper == f64::INFINITY
                && off[j] <= s.lower
                && !s.is_modulus()
                && !matches!(
                    s.role,
                    ParamRole::TimeConstant { .. } | ParamRole::RelaxationWeight { .. }
                )
        })
        .collect();
    let mut out: Vec<Vec<f64>> = Vec::new();
    if scanned.is_empty() {
        return out;
    }
    for start in std::iter::once(off).chain(around.iter().map(|s| s.as_slice())) {
        for &j in &scanned {
            if let Some(s) = scan_one(rich, j, start, loading, observed) {
                if !out.contains(&s) {
                    out.push(s);
                }
            }
        }
    }
    out
}

/// The best point of the log-grid scan of parameter `j` from `from` (see
/// [`scale_scan_starts`]), when it fits better than `from`.
fn scan_one(
    rich: &dyn ForwardModel,
    j: usize,
    from: &[f64],
    loading: &Loading,
    observed: &[f64],
) -> Option<Vec<f64>> {
    let specs = &rich.space().params;
    let misfit = |theta: &[f64]| -> Option<(f64, Vec<f64>)> {
        let f = rich.predict(theta, loading).ok()?;
        let (a, scaled) = scale_moduli(specs, theta, &f, observed)?;
        let sse: f64 = f
            .iter()
            .zip(observed)
            .map(|(v, y)| (y - a * v).powi(2))
            .sum();
        sse.is_finite().then_some((sse, scaled))
    };
    let s = &specs[j];
    let at_from = misfit(from).map_or(f64::INFINITY, |m| m.0);
    let g = if s.initial > s.lower {
        s.initial - s.lower
    } else {
        1.0
    };
    let (sse, theta) = SCAN_DECADES
        .into_par_iter()
        .filter_map(|k| {
            let mut theta = from.to_vec();
            theta[j] = s.lower + g * 10f64.powi(k);
            misfit(&theta)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))?;
    (sse < at_from).then_some(theta)
}
