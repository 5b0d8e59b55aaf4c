//! Cross-validation of a fitted model: stratified blocked folds, and the
//! exact (refit per fold) and linearised (one Gauss-Newton step per fold)
//! held-out predictions.

use super::fit::{fit_from_starts, refit_kept, Fitted};
use super::residual::residuals;
use super::score::sensitivities_at;
use super::{FoldLayout, GapError};
use nalgebra::DMatrix;
use palpate_core::{ForwardModel, Loading};
use std::sync::Arc;

/// The folds of the cross-validation: each loading phase (a run of samples
/// over which the drive rises, holds or falls) cut into short contiguous
/// chunks, the chunks dealt to the folds in turn (one counter across the
/// phases), so that every fold holds samples from every phase and every
/// training set keeps every phase (ramp, hold, unloading).
///
/// Why not K contiguous blocks: leaving out a whole phase (the ramp or the
/// hold of a relaxation test) removes the samples that identify the
/// parameters of the effect that acts there (the time constants), and the
/// refit then extrapolates an unidentified parameter into the left-out
/// block; the cross-validation penalises the effect for the design of the
/// folds, not for overfitting. Chunks rather than
/// single samples: under residual correlation, neighbouring samples of a
/// left-out sample would otherwise predict it (Roberts et al. 2017,
/// "Cross-validation strategies for data with temporal, spatial,
/// hierarchical, or phylogenetic structure", Ecography 40: 913-929,
/// recommend blocks at least as long as the correlation range). The chunk
/// length is the running window of the structure tests halved, but within
/// each phase at most phase length / (2 K), so that even the shortest phase
/// (a fast ramp of ten samples) is spread over the folds.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Folds {
    /// The chunks [first, end) in order.
    pub chunks: Vec<(usize, usize)>,
    /// The fold of each chunk.
    pub fold_of: Vec<usize>,
    /// Number of folds.
    pub count: usize,
}

/// The loading phases of a drive: maximal runs [first, end) over which the
/// increment keeps its sign (rising, holding within 1e-9 of the range, or
/// falling). A sample where the direction changes starts the next phase.
pub(crate) fn phases(drive: &[f64]) -> Vec<(usize, usize)> {
    let n = drive.len();
    if n < 2 {
        return vec![(0, n)];
    }
    let (lo, hi) = drive
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let tol = 1e-9 * (hi - lo).abs().max(f64::MIN_POSITIVE);
    let direction = |i: usize| {
        let d = drive[i + 1] - drive[i];
        if d > tol {
            1
        } else if d < -tol {
            -1
        } else {
            0
        }
    };
    let mut out = Vec::new();
    let mut start = 0;
    let mut current = direction(0);
    for i in 1..n - 1 {
        let d = direction(i);
        if d != current {
            out.push((start, i + 1));
            start = i + 1;
            current = d;
        }
    }
    out.push((start, n));
    out.retain(|(a, b)| b > a);
    out
}

impl Folds {
    /// Stratified folds of `n` samples into `count` folds with chunks of
    /// about `window / 2` samples, shorter within short `phases`.
    pub fn stratified(n: usize, count: usize, window: usize, phases: &[(usize, usize)]) -> Folds {
        let whole = [(0, n)];
        let phases = if phases.is_empty() {
            &whole[..]
        } else {
            phases
        };
        let mut chunks = Vec::new();
        let mut fold_of = Vec::new();
        let mut next = 0;
        for &(a, b) in phases {
            let m = b - a;
            let len = (window / 2).min(m / (2 * count)).max(1);
            let pieces = m.div_ceil(len);
            for k in 0..pieces {
                let (s, e) = (a + k * m / pieces, a + (k + 1) * m / pieces);
                if e > s {
                    chunks.push((s, e));
                    fold_of.push(next % count);
                    next += 1;
                }
            }
        }
        Folds {
            chunks,
            fold_of,
            count,
        }
    }

    /// `count` contiguous blocks of `n` samples.
    pub fn contiguous(n: usize, count: usize) -> Folds {
        let chunks = (0..count)
            .map(|k| (k * n / count, (k + 1) * n / count))
            .collect();
        Folds {
            chunks,
            fold_of: (0..count).collect(),
            count,
        }
    }

    /// The folds of `layout` for a record of drive `drive`.
    pub fn new(layout: FoldLayout, drive: &[f64], count: usize, window: usize) -> Folds {
        let n = drive.len();
        match layout {
            FoldLayout::Stratified => Folds::stratified(n, count, window, &phases(drive)),
            FoldLayout::Contiguous => Folds::contiguous(n, count),
        }
    }

    /// Held-out sample indices of fold `f`.
    pub fn held_out(&self, f: usize) -> Vec<usize> {
        self.chunks
            .iter()
            .zip(&self.fold_of)
            .filter(|(_, &k)| k == f)
            .flat_map(|(&(a, b), _)| a..b)
            .collect()
    }

    /// The samples kept for fitting when fold `f` is held out.
    fn kept(&self, f: usize, n: usize) -> Vec<usize> {
        let mut keep = vec![true; n];
        for i in self.held_out(f) {
            keep[i] = false;
        }
        (0..n).filter(|&i| keep[i]).collect()
    }
}

/// Cross-validation: each fold left out in turn, the model refitted to the
/// rest (a local re-estimation from the full-record optimum, the first of
/// `starts`; the others are fallbacks when that fit fails) and the fold
/// predicted. Returns the held-out predictions of every sample.
fn cross_validate(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    folds: &Folds,
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
) -> Result<Vec<f64>, GapError> {
    let mut out = vec![0.0; observed.len()];
    for f in 0..folds.count {
        refit_fold(
            model, loading, observed, folds, f, starts, fixed, true, &mut out,
        )?;
    }
    Ok(out)
}

/// The exact refit of one fold (see [`cross_validate`]): its held-out
/// predictions written into `out`. `reference`: with the tight settings
/// of the `refit` cross-validation; otherwise with those of a whole-record
/// fit ([`refit_kept`], a fold the linearised form left unsettled).
#[allow(clippy::too_many_arguments)]
fn refit_fold(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    folds: &Folds,
    f: usize,
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
    reference: bool,
    out: &mut [f64],
) -> Result<(), GapError> {
    let keep = folds.kept(f, observed.len());
    let refit = |starts: &[Vec<f64>]| {
        if reference {
            fit_from_starts(model, loading, observed, Some(&keep), starts, fixed, false)
        } else {
            refit_kept(model, loading, observed, &keep, starts, fixed)
        }
    };
    let mut fitted = refit(&starts[..1]);
    if fitted.is_err() && starts.len() > 1 {
        fitted = refit(&starts[1..]);
    }
    let fitted = fitted?;
    for i in folds.held_out(f) {
        out[i] = fitted.predicted[i];
    }
    Ok(())
}

/// Chord iterations of a refined linearised refit: at most this many
/// predictions per fold.
const CHORD_ITERATIONS: usize = 4;

/// Linearised cross-validation
/// ([`CrossValidation::Linearised`](super::CrossValidation::Linearised)):
/// with the sensitivities J of the free parameters at the full-record
/// optimum (predictions f, residuals r = y - f), each fold B is predicted by
/// one Gauss-Newton step fitted to the other samples K,
///
/// ```text
/// delta_B = argmin || r_K - J_K delta ||,   prediction_B = f_B + J_B delta_B,
/// ```
///
/// the first-order approximation of the refit without B (approximate
/// cross-validation: Beirami et al. 2017, "On optimal generalizability in
/// parametric learning"; Stephenson & Broderick 2020). Columns are scaled to
/// unit norm and solved by SVD (singular values below 1e-10 of the largest
/// dropped); a step that would cross a parameter's bound drops that
/// parameter from the step (it stays at its optimum), as a bounded refit would.
///
/// With `refine` (a cheap model and its loading) the step is refined by
/// chord iterations (simplified Gauss-Newton: the model predicted at the
/// fold's parameters, the residual of the kept samples solved again with
/// the same factorised J_K) until the correction changes the kept fit by
/// under 1e-6 of its SSE or [`CHORD_ITERATIONS`] predictions, and the fold
/// is predicted by the model itself at the refined parameters. Its fixed
/// point is the refit's stationary point up to the change of J between the
/// two optima (second order in the step): the exact refit's held-out
/// predictions to well within the noise at a few predictions per fold,
/// where a Levenberg-Marquardt refit per fold (with its statistics and the
/// polish of parameters near a bound) costs hundreds. A fold whose chord
/// fails (a prediction fails, or the kept samples end up fitted worse than
/// by the full-record optimum, which an exact refit never is: a strongly
/// nonlinear parameter such as a relaxation time can send the simplified
/// iteration away) is returned for an exact refit. Written here rather
/// than taken from a solver crate because it reuses one factorisation
/// across the folds' iterations, which a general solver does not offer.
fn cross_validate_linearised(
    model: &dyn ForwardModel,
    observed: &[f64],
    folds: &Folds,
    fitted: &Fitted,
    free: &[bool],
    jac: &DMatrix<f64>,
    refine: Option<&Loading>,
) -> Result<(Vec<f64>, Vec<usize>), GapError> {
    let n = observed.len();
    let specs = &model.space().params;
    let r = residuals(observed, &fitted.predicted);
    let mut out = fitted.predicted.clone();
    let mut unsettled = Vec::new();
    for f in 0..folds.count {
        let keep = folds.kept(f, n);
        let mut active: Vec<usize> = (0..specs.len())
            .filter(|&j| free[j] && jac.column(j).norm() > 0.0)
            .collect();
        let (delta, svd, norms) = loop {
            if active.is_empty() {
                break (Vec::new(), None, Vec::new());
            }
            let norms: Vec<f64> = active.iter().map(|&j| jac.column(j).norm()).collect();
            let m = DMatrix::from_fn(keep.len(), active.len(), |i, k| {
                jac[(keep[i], active[k])] / norms[k]
            });
            let rhs = nalgebra::DVector::from_iterator(keep.len(), keep.iter().map(|&i| r[i]));
            let svd = m.svd(true, true);
            let tol = 1e-10 * svd.singular_values.amax();
            let scaled = svd
                .solve(&rhs, tol)
                .map_err(|reason| GapError::InvalidOption {
                    option: "cross_validation",
                    reason: format!("linearised refit failed: {reason}"),
                })?;
            let d: Vec<f64> = scaled.iter().zip(&norms).map(|(x, s)| x / s).collect();
            let crossing = active.iter().zip(&d).position(|(&j, dj)| {
                let x = fitted.theta[j] + dj;
                x < specs[j].lower || x > specs[j].upper
            });
            match crossing {
                Some(k) => {
                    active.remove(k);
                }
                None => break (d, Some((svd, tol)), norms),
            }
        };
        let held = folds.held_out(f);
        let refined = match (refine, &svd) {
            (Some(loading), Some((svd, tol))) => Some(chord(
                model, loading, observed, fitted, &keep, &active, &delta, svd, *tol, &norms,
            )),
            _ => None,
        };
        match refined {
            Some(Some(pred)) => {
                for i in held {
                    out[i] = pred[i];
                }
            }
            Some(None) => unsettled.push(f),
            None => {
                for i in held {
                    out[i] += active
                        .iter()
                        .zip(&delta)
                        .map(|(&j, dj)| jac[(i, j)] * dj)
                        .sum::<f64>();
                }
            }
        }
    }
    Ok((out, unsettled))
}

/// The chord iterations of [`cross_validate_linearised`] for one fold:
/// the model's predictions at the refined parameters (a correction that
/// would cross a bound stops the iteration where it is), or `None` when a
/// prediction fails or the kept samples are fitted worse than by the
/// full-record optimum (the fold is then refitted exactly).
#[allow(clippy::too_many_arguments)]
fn chord(
    model: &dyn ForwardModel,
    loading: &Loading,
    observed: &[f64],
    fitted: &Fitted,
    keep: &[usize],
    active: &[usize],
    delta: &[f64],
    svd: &nalgebra::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>,
    tol: f64,
    norms: &[f64],
) -> Option<Vec<f64>> {
    let specs = &model.space().params;
    let mut theta = fitted.theta.clone();
    for (&j, dj) in active.iter().zip(delta) {
        theta[j] += dj;
    }
    let kept_sse = |f: &[f64]| {
        keep.iter()
            .map(|&i| (observed[i] - f[i]).powi(2))
            .sum::<f64>()
    };
    // the exact refit of the kept samples fits them at least this well
    let at_optimum = kept_sse(&fitted.predicted);
    let settled = |f: Vec<f64>| {
        let sse = kept_sse(&f);
        (sse.is_finite() && sse <= at_optimum * (1.0 + 1e-9) + f64::MIN_POSITIVE).then_some(f)
    };
    let mut f = model.predict(&theta, loading).ok()?;
    for _ in 1..CHORD_ITERATIONS {
        let rhs =
            nalgebra::DVector::from_iterator(keep.len(), keep.iter().map(|&i| observed[i] - f[i]));
        let sse: f64 = rhs.norm_squared();
        let scaled = svd.solve(&rhs, tol).ok()?;
        // the correction's change of the kept fit, |J_K c|^2 (columns scaled)
        let change = (svd.u.as_ref()?.transpose() * &rhs).norm_squared();
        if change <= 1e-6 * sse {
            break;
        }
        for ((&j, x), s) in active.iter().zip(scaled.iter()).zip(norms) {
            let v = theta[j] + x / s;
            if !(v >= specs[j].lower && v <= specs[j].upper) {
                return settled(f);
            }
            theta[j] = v;
        }
        f = model.predict(&theta, loading).ok()?;
    }
    settled(f)
}

/// The sensitivities of the free parameters (those not in `fixed`) at a
/// fit's optimum, reusing its predictions there; forward differences for an
/// expensive model (one evaluation per free parameter).
pub(crate) fn optimum_sensitivities(
    model: &dyn ForwardModel,
    loading: &Loading,
    fitted: &Fitted,
    fixed: &[(String, f64)],
) -> Result<(Vec<bool>, DMatrix<f64>), GapError> {
    let free: Vec<bool> = model
        .space()
        .params
        .iter()
        .map(|s| !fixed.iter().any(|(name, _)| *name == s.name))
        .collect();
    let jac = sensitivities_at(
        model,
        &fitted.theta,
        loading,
        &free,
        Some(&fitted.predicted),
        model.expensive(),
    )?;
    Ok((free, jac))
}

/// Held-out predictions by the strategy the options and the model's cost
/// select. The linearised form uses `jac`, the sensitivities at the optimum
/// (from [`optimum_sensitivities`]), when the caller has them.
#[allow(clippy::too_many_arguments)]
pub(crate) fn cross_validate_by(
    linearised: bool,
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    folds: &Folds,
    fitted: &Fitted,
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
    jac: Option<&(Vec<bool>, DMatrix<f64>)>,
) -> Result<Vec<f64>, GapError> {
    if linearised {
        let owned;
        let (free, jac) = match jac {
            Some(j) => j,
            None => {
                owned = optimum_sensitivities(model.as_ref(), loading, fitted, fixed)?;
                &owned
            }
        };
        let refine = (!model.expensive()).then_some(loading);
        let (mut out, unsettled) =
            cross_validate_linearised(model.as_ref(), observed, folds, fitted, free, jac, refine)?;
        for f in unsettled {
            refit_fold(
                model, loading, observed, folds, f, starts, fixed, false, &mut out,
            )?;
        }
        Ok(out)
    } else {
        cross_validate(model, loading, observed, folds, starts, fixed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phases_of_a_ramp_hold_unload() {
        let mut d: Vec<f64> = (0..10).map(|i| i as f64).collect();
        d.extend([9.0; 20]);
        d.extend((0..9).rev().map(|i| i as f64));
        let p = phases(&d);
        assert_eq!(p, [(0, 10), (10, 30), (30, 39)]);
        // a fast ramp of 10 samples in a record of 600: every fold has ramp samples
        let mut d: Vec<f64> = (0..10).map(|i| i as f64).collect();
        d.extend([9.0; 590]);
        let folds = Folds::stratified(d.len(), 4, 40, &phases(&d));
        for f in 0..4 {
            assert!(folds.held_out(f).iter().any(|&i| i < 10), "fold {f}");
        }
    }

    #[test]
    fn stratified_folds_cover_every_sample_once_and_every_phase() {
        for (n, k, w) in [(200, 8, 13), (41, 8, 8), (1001, 5, 60), (16, 8, 8)] {
            let folds = Folds::stratified(n, k, w, &[]);
            let mut seen = vec![0; n];
            for f in 0..k {
                let held = folds.held_out(f);
                assert!(!held.is_empty(), "n {n} fold {f}");
                for i in held {
                    seen[i] += 1;
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "n {n}");
            // every fold has samples in the first and the last quarter
            if n >= 16 * k {
                for f in 0..k {
                    let held = folds.held_out(f);
                    assert!(
                        held.iter().any(|&i| i < n / 4) && held.iter().any(|&i| i >= 3 * n / 4)
                    );
                }
            }
        }
    }
}
