//! The diagnosis itself: base fit, residual structure, candidates, verdict.

use super::fit::{fit_from_starts, scale_moduli, Fitted};
use super::noise::difference_noise_sd;
use super::profile::profile_interval;
use super::report::{BaseSummary, FailedCandidate, GapPlot, GapReport, RankedEffect};
use super::score::{
    projected_columns, score_test, sensitivities, sensitivities_of, sensitivity_overlap,
};
use super::structure::{
    chi2_isf, chi2_sf, default_window, discrepancy_band, lag1, significant_windows, whiteness,
};
use super::{GapError, GapOptions};
use nalgebra::DMatrix;
use palpate_core::enrichable::{effects_of, embed, enrich};
use palpate_core::{Effect, ForwardError, ForwardModel, Loading};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Fewest samples the diagnosis works with.
const MIN_SAMPLES: usize = 16;

/// -2 log-likelihood of residuals `r` under AR(1) Gaussian errors, the
/// exact likelihood of a stationary AR(1) (Box & Jenkins) evaluated at the
/// lag-1 sample autocorrelation rho (clipped to +-0.99, a moment estimate,
/// not the maximum-likelihood one, so the AIC/BIC built on it are
/// approximate; they only break ties in the ranking) and the innovation
/// variance: e_0 = sqrt(1 - rho^2) r_0,
/// e_i = r_i - rho r_{i-1}, -2 log L = n ln(2 pi s^2) + n - ln(1 - rho^2),
/// s^2 = sum e^2 / n. A misfit that is smooth (rho near 1) is partly absorbed by
/// the correlation, so an extra parameter must remove more than what the
/// correlation already explains.
fn ar1_deviance(r: &[f64]) -> f64 {
    let n = r.len() as f64;
    let rho = lag1(r).clamp(-0.99, 0.99);
    let c = (1.0 - rho * rho).sqrt();
    let mut ss = (c * r[0]).powi(2);
    for w in r.windows(2) {
        ss += (w[1] - rho * w[0]).powi(2);
    }
    let s2 = (ss / n).max(f64::MIN_POSITIVE);
    n * (2.0 * std::f64::consts::PI * s2).ln() + n - (1.0 - rho * rho).ln()
}

fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

fn residuals(observed: &[f64], predicted: &[f64]) -> Vec<f64> {
    observed.iter().zip(predicted).map(|(y, f)| y - f).collect()
}

fn sse(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// A shared model and the parameters held fixed in it.
type Proxy = (Arc<dyn ForwardModel>, Vec<(String, f64)>);

/// The base model as a shared (`Arc`) model the calibration can own: one of
/// its enrichments with the effect's own parameters held at "off", which
/// reproduces the base exactly. Preference goes to enrichments that need
/// nothing from the history (zero offset, tool compliance, ...).
fn base_proxy(base: &dyn ForwardModel, loading: &Loading) -> Result<Proxy, GapError> {
    let order = [
        Effect::ZeroOffset,
        Effect::ToolCompliance,
        Effect::Compressibility,
        Effect::MaterialForm,
        Effect::Viscoelasticity,
    ];
    let offered = effects_of(base);
    let p = base.space().len();
    let theta0 = base.space().initial();
    let want = base.predict(&theta0, loading)?;
    for effect in order.iter().chain(offered.iter()) {
        if !offered.contains(effect) {
            continue;
        }
        let Ok(rich) = enrich(base, *effect) else {
            continue;
        };
        let off = embed(rich.as_ref(), &theta0);
        if rich.space().names()[..p] != base.space().names()[..] {
            continue;
        }
        if rich.predict(&off, loading).ok().as_ref() != Some(&want) {
            continue;
        }
        let fixed = rich.space().params[p..]
            .iter()
            .zip(&off[p..])
            .map(|(s, v)| (s.name.clone(), *v))
            .collect();
        return Ok((Arc::from(rich), fixed));
    }
    Err(GapError::InvalidOption {
        option: "base",
        reason: format!(
            "{} offers no enrichment that reproduces it when switched off; nothing to diagnose",
            base.name()
        ),
    })
}

/// Starting points of the base fit: the space's initial values, and the same
/// with every parameter in MPa scaled by the least-squares factor
/// <f0, y> / <f0, f0> (exact for laws linear in their moduli).
fn base_starts(base: &dyn ForwardModel, loading: &Loading, observed: &[f64]) -> Vec<Vec<f64>> {
    let theta0 = base.space().initial();
    let mut starts = Vec::new();
    if let Ok(f0) = base.predict(&theta0, loading) {
        if let Some((_, scaled)) = scale_moduli(&base.space().params, &theta0, &f0, observed) {
            starts.push(scaled);
        }
    }
    starts.push(theta0);
    starts
}

/// Extra starts for the new parameters of an enrichment: time constants
/// (unit `s`) on a grid across the record's duration (one decade apart
/// between successive terms), with their companion weights at 0.1.
fn time_constant_starts(
    rich: &dyn ForwardModel,
    p: usize,
    around: &[f64],
    duration: f64,
) -> Vec<Vec<f64>> {
    let specs = &rich.space().params;
    let taus: Vec<usize> = (p..specs.len()).filter(|&j| specs[j].unit == "s").collect();
    if taus.is_empty() || duration.is_nan() || duration <= 0.0 {
        return Vec::new();
    }
    let weights: Vec<usize> = (p..specs.len())
        .filter(|&j| specs[j].unit == "1" && specs[j].upper <= 1.0)
        .collect();
    [duration / 100.0, duration / 20.0, duration / 4.0]
        .iter()
        .map(|&b| {
            let mut s = around.to_vec();
            for (k, &j) in taus.iter().enumerate() {
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
/// with its moduli (parameters in MPa) scaled by the least-squares factor
/// a = <f, y> / <f, f> (one prediction per start; exact for laws whose energy
/// is linear in the moduli under a prescribed displacement), scaled so. The
/// refit then runs from the first and falls back on the next only when that
/// fit fails. A start whose prediction fails goes last, unscaled.
fn screen_starts(
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

/// Contiguous blocks [first, end) of `n` samples.
fn blocks(n: usize, folds: usize) -> Vec<(usize, usize)> {
    (0..folds)
        .map(|k| (k * n / folds, (k + 1) * n / folds))
        .collect()
}

/// Blocked cross-validation: each block left out in turn, the model refitted
/// to the rest (a local re-estimation from the full-record optimum, the
/// first of `starts`; the others are fallbacks when that fit fails) and the
/// block predicted. Returns the out-of-block predictions.
fn cross_validate(
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    folds: &[(usize, usize)],
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
) -> Result<Vec<f64>, GapError> {
    let n = observed.len();
    let mut out = vec![0.0; n];
    for &(a, b) in folds {
        let keep: Vec<usize> = (0..a).chain(b..n).collect();
        let mut fitted = fit_from_starts(
            model,
            loading,
            observed,
            Some(&keep),
            &starts[..1],
            fixed,
            false,
        );
        if fitted.is_err() && starts.len() > 1 {
            fitted = fit_from_starts(
                model,
                loading,
                observed,
                Some(&keep),
                &starts[1..],
                fixed,
                false,
            );
        }
        let fitted = fitted?;
        out[a..b].copy_from_slice(&fitted.predicted[a..b]);
    }
    Ok(out)
}

/// Linearised blocked cross-validation
/// ([`CrossValidation::Linearised`](super::CrossValidation::Linearised)):
/// with the sensitivities J of the free parameters at the full-record
/// optimum (predictions f, residuals r = y - f), each block B is predicted by
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
fn cross_validate_linearised(
    model: &dyn ForwardModel,
    loading: &Loading,
    observed: &[f64],
    folds: &[(usize, usize)],
    fitted: &Fitted,
    fixed: &[(String, f64)],
) -> Result<Vec<f64>, GapError> {
    let n = observed.len();
    let specs = &model.space().params;
    let free: Vec<bool> = specs
        .iter()
        .map(|s| !fixed.iter().any(|(name, _)| *name == s.name))
        .collect();
    let jac = sensitivities_of(model, &fitted.theta, loading, &free)?;
    let r = residuals(observed, &fitted.predicted);
    let mut out = fitted.predicted.clone();
    for &(a, b) in folds {
        let keep: Vec<usize> = (0..a).chain(b..n).collect();
        let mut active: Vec<usize> = (0..specs.len())
            .filter(|&j| free[j] && jac.column(j).norm() > 0.0)
            .collect();
        let delta = loop {
            if active.is_empty() {
                break Vec::new();
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
                None => break d,
            }
        };
        for (i, o) in out.iter_mut().enumerate().take(b).skip(a) {
            *o += active
                .iter()
                .zip(&delta)
                .map(|(&j, dj)| jac[(i, j)] * dj)
                .sum::<f64>();
        }
    }
    Ok(out)
}

/// Blocked cross-validation by the strategy the options and the model's
/// cost select.
#[allow(clippy::too_many_arguments)]
fn cross_validate_by(
    linearised: bool,
    model: &Arc<dyn ForwardModel>,
    loading: &Loading,
    observed: &[f64],
    folds: &[(usize, usize)],
    fitted: &Fitted,
    starts: &[Vec<f64>],
    fixed: &[(String, f64)],
) -> Result<Vec<f64>, GapError> {
    if linearised {
        cross_validate_linearised(model.as_ref(), loading, observed, folds, fitted, fixed)
    } else {
        cross_validate(model, loading, observed, folds, starts, fixed)
    }
}

/// Prony terms (`g<i>`, `tau<i>_s`) of a parameter map relabelled by
/// increasing relaxation time: the response is symmetric in the terms, so
/// this canonical order avoids label switching in reports.
fn canonical_prony<T: Clone>(map: &mut BTreeMap<String, T>, taus: &BTreeMap<String, f64>) {
    let mut terms: Vec<(f64, Option<T>, Option<T>)> = Vec::new();
    let mut i = 1;
    while let Some(&tau) = taus.get(&format!("tau{i}_s")) {
        terms.push((
            tau,
            map.remove(&format!("g{i}")),
            map.remove(&format!("tau{i}_s")),
        ));
        i += 1;
    }
    terms.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (k, (_, g, tau)) in terms.into_iter().enumerate() {
        if let Some(g) = g {
            map.insert(format!("g{}", k + 1), g);
        }
        if let Some(tau) = tau {
            map.insert(format!("tau{}_s", k + 1), tau);
        }
    }
}

struct Context<'a> {
    loading: &'a Loading,
    observed: &'a [f64],
    sigma: f64,
    folds: Vec<(usize, usize)>,
    p: usize,
    base_theta: Vec<f64>,
    base_full: &'a Fitted,
    base_cv: Vec<f64>,
    base_residual: Vec<f64>,
    candidates: usize,
    alpha: f64,
    rel_var_sd2: f64,
    /// Blocked cross-validation by one linearised step per block.
    linearised: bool,
    /// The model is expensive: fewer starts per refit.
    expensive: bool,
}

/// A candidate's ranking entry, its full-record fit and its projected
/// sensitivities at "off", or why it failed.
type Assessment = Result<(RankedEffect, Fitted, DMatrix<f64>, Arc<dyn ForwardModel>), GapError>;

/// Score test, refits and comparison of one enrichment.
fn assess(effect: Effect, rich: Arc<dyn ForwardModel>, ctx: &Context<'_>) -> Assessment {
    let (n, p) = (ctx.observed.len(), ctx.p);
    let specs = rich.space().params.clone();
    let q = specs.len() - p;
    let off = embed(rich.as_ref(), &ctx.base_theta);
    let jac = sensitivities(rich.as_ref(), &off, ctx.loading)?;
    let at_lower: Vec<bool> = (p..specs.len()).map(|j| off[j] <= specs[j].lower).collect();
    let at_upper: Vec<bool> = (p..specs.len()).map(|j| off[j] >= specs[j].upper).collect();
    let score = score_test(&ctx.base_residual, &jac, p, ctx.sigma, &at_lower, &at_upper);

    // Starts: the Gauss-Newton step from "off", "off" itself (moved inside
    // the bounds), and a grid of time constants when the effect has any.
    let mut gn = off.clone();
    for (k, d) in score.step.iter().enumerate() {
        let j = p + k;
        let x = off[j] + d;
        if x.is_finite() && x > specs[j].lower && x < specs[j].upper {
            gn[j] = x;
        }
    }
    let duration = ctx
        .loading
        .time
        .as_ref()
        .map(|t| t[t.len() - 1] - t[0])
        .unwrap_or(0.0);
    let grid = time_constant_starts(rich.as_ref(), p, &off, duration);
    let mut starts = vec![gn];
    if grid.is_empty() {
        starts.extend(off_bound_start(rich.as_ref(), p, &off));
    }
    starts.push(off.clone());
    starts.extend(grid);
    let mut unique: Vec<Vec<f64>> = Vec::new();
    for st in starts {
        if !unique.contains(&st) {
            unique.push(st);
        }
    }
    let mut starts = unique;
    if ctx.expensive {
        starts = screen_starts(rich.as_ref(), ctx.loading, ctx.observed, starts);
    }
    let full = if ctx.expensive {
        // From the best screened start; the next ones only if it fails.
        let mut outcome = Err(GapError::InvalidOption {
            option: "starts",
            reason: "no starting point".into(),
        });
        for start in &starts {
            outcome = fit_from_starts(
                &rich,
                ctx.loading,
                ctx.observed,
                None,
                std::slice::from_ref(start),
                &[],
                true,
            );
            if outcome.is_ok() {
                break;
            }
        }
        outcome?
    } else {
        fit_from_starts(&rich, ctx.loading, ctx.observed, None, &starts, &[], false)?
    };
    let mut cv_starts = vec![full.theta.clone()];
    cv_starts.extend(starts.iter().take(2).cloned());
    let cv = cross_validate_by(
        ctx.linearised,
        &rich,
        ctx.loading,
        ctx.observed,
        &ctx.folds,
        &full,
        &cv_starts,
        &[],
    )?;

    let r_after = residuals(ctx.observed, &full.predicted);
    let sigma2 = ctx.sigma * ctx.sigma;
    let lr = (ctx.base_full.sse - full.sse) / sigma2;
    // A discrete switch (q = 0, e.g. bonded -> sliding base) is a
    // non-nested alternative: charged as one parameter.
    let lr_dof = q.max(1);
    let lr_p = chi2_sf(lr, lr_dof as f64);
    let h_before = residuals(ctx.observed, &ctx.base_cv);
    let h_after = residuals(ctx.observed, &cv);
    let later = ctx.folds[ctx.folds.len() - 1].0;
    let heldout_gain = (sse(&h_before) - sse(&h_after)) / sigma2;
    let dev_base = ar1_deviance(&ctx.base_residual);
    let dev_rich = ar1_deviance(&r_after);
    let nf = n as f64;
    let delta_aic = dev_rich - dev_base + 2.0 * lr_dof as f64;
    let delta_bic = dev_rich - dev_base + lr_dof as f64 * nf.ln();
    let lr_level = ctx.alpha / ctx.candidates.max(1) as f64;
    let gain_threshold = chi2_isf(ctx.alpha, 1.0);
    let earns = lr_p < lr_level && heldout_gain > gain_threshold;

    let names = rich.space().names();
    let own: Vec<String> = names[p..].to_vec();
    let mut params: BTreeMap<String, f64> = own
        .iter()
        .zip(&full.theta[p..])
        .map(|(k, v)| (k.clone(), *v))
        .collect();
    let mut all_params: BTreeMap<String, f64> = names
        .iter()
        .zip(&full.theta)
        .map(|(k, v)| (k.clone(), *v))
        .collect();
    let mut standard_errors: BTreeMap<String, Option<f64>> = own
        .iter()
        .map(|k| (k.clone(), full.report.standard_error(k)))
        .collect();
    let fitted_values = params.clone();
    canonical_prony(&mut params, &fitted_values);
    canonical_prony(&mut all_params, &fitted_values);
    canonical_prony(&mut standard_errors, &fitted_values);
    let ident = &full.report.identifiability;
    let own_involved = ident.involved.iter().any(|k| own.contains(k));
    let identifiable = ident.identifiable || !own_involved;
    let max_correlation = full
        .report
        .correlation
        .iter()
        .enumerate()
        .flat_map(|(a, row)| {
            row.iter()
                .enumerate()
                .filter(move |(b, _)| *b != a)
                .map(|(_, c)| c.abs())
        })
        .filter(|c| c.is_finite())
        .fold(0.0, f64::max);
    let after = whiteness(&r_after, specs.len(), ctx.sigma, ctx.rel_var_sd2);
    let evidence = format!(
        "score test {:.1} on {} dof (p = {:.1e}); refit: likelihood ratio {:.1} on {lr_dof} parameter(s) (p = {:.1e}, \
         needs < {:.1e}); blocked cross-validation gain {:.1} (needs > {:.1}), held-out RMS {:.3e} -> {:.3e} \
         (later segment {:.3e} -> {:.3e}); dAIC {:.1}, dBIC {:.1} \
         under AR(1) errors; residual RMS/noise {:.2} -> {:.2}, runs p {:.1e} -> {:.1e}; {}",
        score.statistic,
        score.dof,
        score.p_value,
        lr,
        lr_p,
        lr_level,
        heldout_gain,
        gain_threshold,
        rms(&h_before),
        rms(&h_after),
        rms(&h_before[later..]),
        rms(&h_after[later..]),
        delta_aic,
        delta_bic,
        rms(&ctx.base_residual) / ctx.sigma,
        after.rms_over_noise,
        whiteness(&ctx.base_residual, p, ctx.sigma, ctx.rel_var_sd2).runs_p,
        after.runs_p,
        ident.reason
    );
    let ranked = RankedEffect {
        effect: effect.name().to_string(),
        params,
        misfit_before: rms(&ctx.base_residual),
        misfit_after: rms(&r_after),
        heldout_before: rms(&h_before),
        heldout_after: rms(&h_after),
        later_before: rms(&h_before[later..]),
        later_after: rms(&h_after[later..]),
        evidence,
        identifiable,
        confounded_with: Vec::new(),
        sensitivity_overlap: BTreeMap::new(),
        earns,
        model: rich.name(),
        all_params,
        standard_errors,
        score,
        lr_statistic: lr,
        lr_p,
        heldout_gain,
        delta_aic_ar1: delta_aic,
        delta_bic_ar1: delta_bic,
        after,
        max_correlation,
        identifiability: ident.reason.clone(),
        profile: Vec::new(),
    };
    let projected = projected_columns(&jac, p);
    Ok((ranked, full, projected, rich))
}

/// Diagnoses the gap between `base` and `observed` (one value per sample of
/// `loading`, in the unit of `base.observable()`). See the module docs.
pub fn diagnose(
    base: &dyn ForwardModel,
    loading: &Loading,
    observed: &[f64],
    options: &GapOptions,
) -> Result<GapReport, GapError> {
    options.validate()?;
    let n = observed.len();
    if n != loading.len() {
        return Err(GapError::LengthMismatch {
            observed: n,
            samples: loading.len(),
        });
    }
    let needed = MIN_SAMPLES.max(2 * options.folds);
    if n < needed {
        return Err(GapError::TooFewSamples { got: n, needed });
    }
    if let Some(index) = observed.iter().position(|v| !v.is_finite()) {
        return Err(GapError::NonFinite { index });
    }
    loading
        .validate()
        .map_err(|e| GapError::Forward(ForwardError::InvalidLoading(e)))?;
    let (axis_name, x) = match &loading.time {
        Some(t) => ("time_s".to_string(), t.clone()),
        None => (
            loading.drive_kind.column().to_string(),
            loading.drive.clone(),
        ),
    };
    let noise = difference_noise_sd(observed, loading.time.as_deref())?;
    let sigma = noise.sd;
    if sigma.is_nan() || sigma <= 0.0 {
        return Err(GapError::ZeroNoise);
    }
    let p = base.space().len();
    let folds = blocks(n, options.folds);

    // Base fit on all samples, and blocked cross-validation.
    let (proxy, fixed) = base_proxy(base, loading)?;
    let starts: Vec<Vec<f64>> = base_starts(base, loading, observed)
        .iter()
        .map(|s| embed(proxy.as_ref(), s))
        .collect();
    let expensive = base.expensive();
    let linearised = options.cross_validation.linearised(expensive);
    // An expensive model is fitted from the first start only, the others
    // being fallbacks when that fit fails.
    let mut base_fit = fit_from_starts(
        &proxy,
        loading,
        observed,
        None,
        if expensive { &starts[..1] } else { &starts },
        &fixed,
        expensive,
    );
    if base_fit.is_err() && expensive && starts.len() > 1 {
        base_fit = fit_from_starts(&proxy, loading, observed, None, &starts[1..], &fixed, true);
    }
    let base_full = base_fit?;
    let base_theta = base_full.theta[..p].to_vec();
    let mut cv_starts = vec![base_full.theta.clone()];
    cv_starts.extend(starts.iter().cloned());
    let base_cv = cross_validate_by(
        linearised, &proxy, loading, observed, &folds, &base_full, &cv_starts, &fixed,
    )?;
    let base_residual = residuals(observed, &base_full.predicted);

    // Where: whole-record tests and windows.
    let tests = whiteness(&base_residual, p, sigma, noise.rel_var_sd2);
    let w = options.window.unwrap_or_else(|| default_window(n)).min(n);
    let windows = significant_windows(&base_residual, &axis_name, &x, sigma, w, options.alpha);
    let mut reasons = Vec::new();
    if tests.misfit_p < options.alpha {
        reasons.push(format!(
            "misfit RMS/noise {:.2} (p = {:.1e})",
            tests.rms_over_noise, tests.misfit_p
        ));
    }
    if tests.runs_p < options.alpha {
        reasons.push(format!(
            "{} runs for {:.0} expected (p = {:.1e})",
            tests.runs, tests.runs_expected, tests.runs_p
        ));
    }
    if tests.lag1_p < options.alpha {
        reasons.push(format!(
            "lag-1 autocorrelation {:.2} (p = {:.1e})",
            tests.lag1_autocorrelation, tests.lag1_p
        ));
    }
    if !windows.is_empty() {
        reasons.push(format!("{} window(s) of significant misfit", windows.len()));
    }
    let gap_significant = !reasons.is_empty();
    let reason = if gap_significant {
        reasons.join("; ")
    } else {
        format!(
            "misfit consistent with noise at level {:.0e}: RMS/noise {:.2} (p = {:.2}), runs p = {:.2}, lag-1 p = {:.2}, no window",
            options.alpha, tests.rms_over_noise, tests.misfit_p, tests.runs_p, tests.lag1_p
        )
    };

    // Attribute: every applicable enrichment.
    let effects: Vec<Effect> = match &options.effects {
        Some(list) => list
            .iter()
            .copied()
            .filter(|e| effects_of(base).contains(e))
            .collect(),
        None => effects_of(base),
    };
    let mut enriched: Vec<(Effect, Arc<dyn ForwardModel>)> = Vec::new();
    for e in effects {
        if let Ok(rich) = enrich(base, e) {
            // Skip enrichments that cannot run on this history (e.g. no time for QLV).
            if rich
                .predict(&embed(rich.as_ref(), &base_theta), loading)
                .is_ok()
            {
                enriched.push((e, Arc::from(rich)));
            }
        }
    }
    let ctx = Context {
        loading,
        observed,
        sigma,
        folds: folds.clone(),
        p,
        base_theta: base_theta.clone(),
        base_full: &base_full,
        base_cv: base_cv.clone(),
        base_residual: base_residual.clone(),
        candidates: enriched.len(),
        alpha: options.alpha,
        rel_var_sd2: noise.rel_var_sd2,
        linearised,
        expensive,
    };
    // Candidates are independent: assessed in parallel, collected in order.
    let outcomes: Vec<(Effect, Assessment)> = enriched
        .into_par_iter()
        .map(|(e, rich)| (e, assess(e, rich, &ctx)))
        .collect();
    let mut assessed = Vec::new();
    let mut failed = Vec::new();
    for (e, outcome) in outcomes {
        match outcome {
            Ok(a) => assessed.push(a),
            Err(err) => failed.push(FailedCandidate {
                effect: e.name().to_string(),
                error: err.to_string(),
            }),
        }
    }
    // Local identifiability between effects: overlap of their sensitivity
    // directions at "off" once the base parameters are refitted.
    for a in 0..assessed.len() {
        let overlaps: BTreeMap<String, f64> = (0..assessed.len())
            .filter(|&b| b != a)
            .map(|b| {
                (
                    assessed[b].0.effect.clone(),
                    sensitivity_overlap(&assessed[a].2, &assessed[b].2),
                )
            })
            .collect();
        assessed[a].0.sensitivity_overlap = overlaps;
    }
    // Rank: effects that earn their parameters first, then by the held-out
    // (cross-validated) gain, which charges every extra parameter through its
    // prediction error rather than through a fixed penalty; AR(1) BIC breaks ties.
    assessed.sort_by(|a, b| {
        b.0.earns
            .cmp(&a.0.earns)
            .then(b.0.heldout_gain.total_cmp(&a.0.heldout_gain))
            .then(a.0.delta_bic_ar1.total_cmp(&b.0.delta_bic_ar1))
    });

    // Confounding: two earning effects the data cannot tell apart, because
    // their fits (in sample) or their held-out predictions differ by less
    // than a chi2(1) quantile of the noise: the likelihood ratio between the
    // two enriched models is not decisive.
    let confound_threshold = chi2_isf(options.confound_alpha, 1.0);
    let sigma2 = sigma * sigma;
    for a in 0..assessed.len() {
        let mut with = Vec::new();
        for b in 0..assessed.len() {
            if a != b && assessed[a].0.earns && assessed[b].0.earns {
                let fit = (assessed[a].1.sse - assessed[b].1.sse).abs() / sigma2;
                let held_out = (assessed[a].0.heldout_gain - assessed[b].0.heldout_gain).abs();
                if fit < confound_threshold || held_out < confound_threshold {
                    with.push(assessed[b].0.effect.clone());
                }
            }
        }
        if !with.is_empty() {
            assessed[a].0.identifiable = false;
            let overlaps: Vec<String> = with
                .iter()
                .map(|e| {
                    format!(
                        "{e}: {:.3}",
                        assessed[a]
                            .0
                            .sensitivity_overlap
                            .get(e)
                            .copied()
                            .unwrap_or(f64::NAN)
                    )
                })
                .collect();
            let overlap_note = format!("; sensitivity overlap at off {}", overlaps.join(", "));
            assessed[a].0.evidence.push_str(&overlap_note);
            let note = format!(
                "; the data cannot tell it apart from {} (fitted or held-out SSE difference below \
                 chi2(1) quantile {:.1} x noise^2)",
                with.join(", "),
                confound_threshold
            );
            assessed[a].0.evidence.push_str(&note);
        }
        assessed[a].0.confounded_with = with;
    }

    // Within the leading group of effects the held-out predictions cannot
    // separate, the likelihood on all the data decides the order (they stay
    // flagged as confounded).
    if let Some(first) = assessed.first() {
        if first.0.earns && !first.0.confounded_with.is_empty() {
            let group = first.0.confounded_with.clone();
            let lead = (0..assessed.len())
                .filter(|&k| k == 0 || group.contains(&assessed[k].0.effect))
                .max_by(|&a, &b| {
                    assessed[a]
                        .0
                        .lr_statistic
                        .total_cmp(&assessed[b].0.lr_statistic)
                })
                .unwrap_or(0);
            let moved = assessed.remove(lead);
            assessed.insert(0, moved);
        }
    }
    // Identifiability of the leading effect's parameters by their profile
    // likelihood (its other parameters refitted at each point).
    if let Some(first) = assessed.first_mut() {
        if first.0.earns {
            let (ranked, fitted, _, model) = first;
            let names = model.space().names();
            let own: Vec<usize> = (p..names.len()).collect();
            ranked.profile = own
                .par_iter()
                .map(|&j| {
                    profile_interval(
                        model,
                        loading,
                        observed,
                        &fitted.theta,
                        fitted.sse,
                        sigma,
                        j,
                        expensive,
                    )
                })
                .collect();
            if !ranked.profile.is_empty() {
                let text: Vec<String> = ranked.profile.iter().map(|i| i.describe()).collect();
                ranked.evidence.push_str(&format!("; {}", text.join(", ")));
            }
        }
    }
    let best_earning = assessed.iter().find(|a| a.0.earns);
    let (verdict, confounded, explanation) = match (gap_significant, best_earning) {
        (false, _) => (
            "none".to_string(),
            Vec::new(),
            format!("No significant gap: the base misfit is {reason}."),
        ),
        (true, None) => (
            "none".to_string(),
            Vec::new(),
            format!(
                "The base model misses the data ({reason}), but no candidate effect earns its parameters \
                 (significant likelihood ratio and cross-validated gain); the gap is left unexplained."
            ),
        ),
        (true, Some(best)) => {
            let r = &best.0;
            let mut text = format!(
                "The base model misses the data ({reason}). Adding `{}` brings the misfit from {:.3e} to {:.3e} \
                 (noise {:.3e}) and the held-out misfit from {:.3e} to {:.3e}.",
                r.effect, r.misfit_before, r.misfit_after, sigma, r.heldout_before, r.heldout_after
            );
            if !r.confounded_with.is_empty() {
                text.push_str(&format!(
                    " It cannot be told apart from {} with these data.",
                    r.confounded_with.join(", ")
                ));
            }
            (r.effect.clone(), r.confounded_with.clone(), text)
        }
    };

    let (band_mean, band_lower, band_upper) = discrepancy_band(&base_residual, sigma, w);
    let best_fit = assessed.first();
    let plot = GapPlot {
        axis: axis_name,
        x,
        drive_name: loading.drive_kind.column().to_string(),
        drive: loading.drive.clone(),
        observed: observed.to_vec(),
        base_fit: base_full.predicted.clone(),
        base_residual: base_residual.clone(),
        band_mean,
        band_lower,
        band_upper,
        enriched_effect: best_fit.map(|a| a.0.effect.clone()),
        enriched_fit: best_fit.map(|a| a.1.predicted.clone()),
        enriched_residual: best_fit.map(|a| residuals(observed, &a.1.predicted)),
        folds: folds.clone(),
        base_cv: base_cv.clone(),
    };
    let base_names = base.space().names();
    let heldout_base = residuals(observed, &base_cv);
    Ok(GapReport {
        verdict,
        noise_sd: sigma,
        where_: windows,
        ranking: assessed.into_iter().map(|a| a.0).collect(),
        failed,
        confounded,
        explanation,
        base: BaseSummary {
            model: base.name(),
            params: base_names.into_iter().zip(base_theta).collect(),
            misfit: rms(&base_residual),
            heldout: rms(&heldout_base),
            tests,
            gap_significant,
            reason,
        },
        noise,
        samples: n,
        folds: options.folds,
        plot,
    })
}

#[cfg(test)]
mod tests {
    //! The diagnosis on a toy model defined here (a linear spring with a zero
    //! offset), so that this crate tests it without any physics crate.
    use super::*;
    use palpate_core::{Drive, Enrichable, Evaluator, Observable, ParamSpace, ParamSpec};
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// F = k max(d - d0, 0); `offset` says whether d0 is a parameter.
    struct Spring {
        offset: bool,
        space: ParamSpace,
    }

    impl Spring {
        fn new(offset: bool) -> Self {
            let mut p = vec![ParamSpec::new("k", "N/mm", 0.0, f64::INFINITY, 1.0)];
            if offset {
                p.push(ParamSpec::new("d0_mm", "mm", -1.0, 1.0, 0.0));
            }
            Spring {
                offset,
                space: ParamSpace::new(p),
            }
        }
    }

    struct SpringEval(bool);

    impl Evaluator for SpringEval {
        fn predict_into(
            &mut self,
            theta: &[f64],
            loading: &Loading,
            out: &mut [f64],
        ) -> Result<(), ForwardError> {
            let d0 = if self.0 { theta[1] } else { 0.0 };
            for (o, d) in out.iter_mut().zip(&loading.drive) {
                *o = theta[0] * (d - d0).max(0.0);
            }
            Ok(())
        }
    }

    impl ForwardModel for Spring {
        fn name(&self) -> String {
            format!("spring{}", if self.offset { " + offset" } else { "" })
        }
        fn space(&self) -> &ParamSpace {
            &self.space
        }
        fn observable(&self) -> Observable {
            Observable::ForceN
        }
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(SpringEval(self.offset))
        }
        fn as_enrichable(&self) -> Option<&dyn Enrichable> {
            Some(self)
        }
    }

    impl Enrichable for Spring {
        fn effects(&self) -> Vec<Effect> {
            if self.offset {
                Vec::new()
            } else {
                vec![Effect::ZeroOffset]
            }
        }
        fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
            match (effect, self.offset) {
                (Effect::ZeroOffset, false) => Ok(Box::new(Spring::new(true))),
                _ => Err(ForwardError::InvalidConfig {
                    field: "effect".into(),
                    reason: "not offered".into(),
                }),
            }
        }
    }

    fn data(d0: f64, seed: u64) -> (Loading, Vec<f64>) {
        let d: Vec<f64> = (0..200).map(|i| 0.01 * i as f64).collect();
        let loading = Loading::quasi_static(Drive::DisplacementMm, d);
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let noise = Normal::new(0.0, 0.01).unwrap();
        let f = Spring::new(true).predict(&[3.0, d0], &loading).unwrap();
        (
            loading,
            f.into_iter().map(|v| v + noise.sample(&mut rng)).collect(),
        )
    }

    #[test]
    fn finds_a_planted_offset_and_says_none_without_one() {
        let base = Spring::new(false);
        let (loading, y) = data(0.1, 1);
        let r = diagnose(&base, &loading, &y, &GapOptions::default()).unwrap();
        assert_eq!(r.verdict, "zero_offset", "{}", r.explanation);
        let best = &r.ranking[0];
        let (d0, se) = (best.params["d0_mm"], best.standard_errors["d0_mm"].unwrap());
        assert!((d0 - 0.1).abs() < 3.0 * se, "d0 = {d0} +- {se}");
        // the profile interval is bounded, contains the planted value and
        // is about +-1.96 standard errors wide (the model is nearly linear)
        let profile = &best.profile[0];
        let (lo, hi) = (profile.lower.unwrap(), profile.upper.unwrap());
        assert!(lo < 0.1 && 0.1 < hi, "{}", profile.describe());
        assert!(
            ((hi - lo) / (2.0 * 1.96 * se) - 1.0).abs() < 0.3,
            "{} for se {se}",
            profile.describe()
        );
        assert!(best.heldout_after < 1.2 * 0.01 && best.misfit_before > 2.0 * best.misfit_after);
        assert!(!r.where_.is_empty() && r.where_[0].axis == "displacement_mm");
        assert!((r.noise_sd / 0.01 - 1.0).abs() < 0.2);

        let (loading, y) = data(0.0, 2);
        let r = diagnose(&base, &loading, &y, &GapOptions::default()).unwrap();
        assert_eq!(r.verdict, "none", "{}", r.explanation);
        assert!(!r.base.gap_significant && r.where_.is_empty());
    }

    #[test]
    fn a_model_without_enrichments_cannot_be_diagnosed() {
        let (loading, y) = data(0.0, 3);
        let err = diagnose(&Spring::new(true), &loading, &y, &GapOptions::default()).unwrap_err();
        assert!(
            matches!(err, GapError::InvalidOption { option: "base", .. }),
            "{err}"
        );
    }
}
