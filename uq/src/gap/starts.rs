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
