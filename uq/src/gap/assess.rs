//! Assessment of one candidate effect: score test at "off", refit from
//! several starts, cross-validation, likelihood ratio, information criteria,
//! identifiability and practical size.

use super::crossval::{cross_validate_by, Folds};
use super::fit::{fit_from_starts, fit_with_budget, Fitted};
use super::plausible::degenerate;
use super::report::{PracticalSize, RankedEffect};
use super::residual::{ar1_deviance, residuals, rms, sse};
use super::score::{projected_columns, score_test, sensitivities_at};
use super::starts::{candidate_starts, projected_line_search, scale_scan_starts, screen_starts};
use super::structure::{chi2_isf, chi2_sf, whiteness};
use super::GapError;
use nalgebra::DMatrix;
use palpate_core::enrichable::embed;
use palpate_core::{Effect, ForwardModel, Loading, ParamRole, ParamSpec};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Levenberg-Marquardt iterations after a projected line search
/// ([`projected_line_search`]): none, only the statistics there. The
/// search's point is the optimum of the moduli exactly (their least-squares
/// factor) and of the effect's parameter to 0.1 sigma^2; measured on N1
/// friction, three LM iterations from it cost 11 solves (rejected steps
/// towards the bound of a flat valley) for no change a test resolves.
const PROJECTED_POLISH: u64 = 0;

/// What every candidate's assessment shares: the record, the noise, the
/// folds and the base fit.
pub(crate) struct Context<'a> {
    pub loading: &'a Loading,
    pub observed: &'a [f64],
    pub sigma: f64,
    pub folds: &'a Folds,
    /// First sample of the later segment (the last 1/K of the record).
    pub later: usize,
    pub p: usize,
    pub base_theta: Vec<f64>,
    pub base_full: &'a Fitted,
    pub base_cv: Vec<f64>,
    pub base_residual: Vec<f64>,
    /// Sensitivities of the base parameters at the base optimum, when
    /// computed (expensive models): reused for the score test of an
    /// enrichment whose "off" point reproduces the base predictions.
    pub base_jac: Option<&'a DMatrix<f64>>,
    pub candidates: usize,
    pub alpha: f64,
    pub rel_var_sd2: f64,
    /// Smallest RMS of the systematic misfit an effect must remove, in noise
    /// SDs, to be material (`GapOptions::materiality`).
    pub materiality: f64,
    /// Cross-validation by one linearised step per fold.
    pub linearised: bool,
    /// The model is expensive: fewer starts per refit.
    pub expensive: bool,
    /// When the "base" is a set of effects: each candidate's parameters
    /// fitted alone, and every relaxation time of the set is started again
    /// on the grid (an earlier member's fit can sit in a local optimum that
    /// the new effect's parameters alone cannot leave). Empty for the
    /// single-effect step.
    pub solo: BTreeMap<Effect, BTreeMap<String, f64>>,
}

/// A candidate after assessment: its ranking entry, its full-record fit, its
/// projected sensitivities at "off" and the enriched model.
pub(crate) struct Assessed {
    pub ranked: RankedEffect,
    pub fitted: Fitted,
    pub projected: DMatrix<f64>,
    pub model: Arc<dyn ForwardModel>,
    /// The enriched model's "off" point at the base optimum.
    pub off: Vec<f64>,
    /// Held-out (cross-validated) predictions of the enriched model.
    pub cv: Vec<f64>,
}

/// Prony terms of a parameter map relabelled by increasing relaxation time:
/// the response is symmetric in the terms, so this canonical order avoids
/// label switching in reports. Terms are found by their roles
/// ([`ParamRole::RelaxationWeight`], [`ParamRole::TimeConstant`]); the value
/// of the k-th shortest term is written under the names of term k.
pub(crate) fn canonical_prony<T: Clone>(
    map: &mut BTreeMap<String, T>,
    specs: &[ParamSpec],
    theta: &[f64],
) {
    let mut terms: BTreeMap<usize, (Option<String>, Option<String>, f64)> = BTreeMap::new();
    for (s, &v) in specs.iter().zip(theta) {
        match s.role {
            ParamRole::RelaxationWeight { term } => {
                terms.entry(term).or_insert((None, None, f64::NAN)).0 = Some(s.name.clone());
            }
            ParamRole::TimeConstant { term } => {
                let e = terms.entry(term).or_insert((None, None, f64::NAN));
                e.1 = Some(s.name.clone());
                e.2 = v;
            }
            _ => {}
        }
    }
    let labels: Vec<(Option<String>, Option<String>)> = terms
        .values()
        .map(|(g, t, _)| (g.clone(), t.clone()))
        .collect();
    let mut by_tau: Vec<&(Option<String>, Option<String>, f64)> = terms.values().collect();
    by_tau.sort_by(|a, b| a.2.total_cmp(&b.2));
    let values: Vec<(Option<T>, Option<T>)> = by_tau
        .iter()
        .map(|(g, t, _)| {
            (
                g.as_ref().and_then(|g| map.get(g).cloned()),
                t.as_ref().and_then(|t| map.get(t).cloned()),
            )
        })
        .collect();
    for ((g_name, t_name), (g, t)) in labels.into_iter().zip(values) {
        if let (Some(name), Some(v)) = (g_name, g) {
            map.insert(name, v);
        }
        if let (Some(name), Some(v)) = (t_name, t) {
            map.insert(name, v);
        }
    }
}

/// Extra starts of an effect joining a set (`p` parameters of the set,
/// "off" point `off`): its own parameters at their values fitted alone
/// (`alone`, by name), and that with every relaxation time of the model
/// restarted from a twentieth of the record's duration, a decade apart, the
/// weights at 0.1 (one start: each costs a refit per fold).
fn set_starts(
    rich: &dyn ForwardModel,
    p: usize,
    off: &[f64],
    alone: &BTreeMap<String, f64>,
    duration: f64,
) -> Vec<Vec<f64>> {
    let specs = &rich.space().params;
    let mut own = off.to_vec();
    for j in p..specs.len() {
        if let Some(v) = alone.get(&specs[j].name) {
            if *v > specs[j].lower && *v < specs[j].upper {
                own[j] = *v;
            }
        }
    }
    let mut out = vec![own.clone()];
    let taus: Vec<(usize, usize)> = {
        let mut t: Vec<(usize, usize)> = specs
            .iter()
            .enumerate()
            .filter_map(|(j, s)| match s.role {
                ParamRole::TimeConstant { term } => Some((term, j)),
                _ => None,
            })
            .collect();
        t.sort();
        t
    };
    if !taus.is_empty() && duration > 0.0 {
        for b in [duration / 20.0] {
            let mut s = own.clone();
            for (k, &(_, j)) in taus.iter().enumerate() {
                s[j] = b * 10f64.powi(k as i32);
            }
            for (j, spec) in specs.iter().enumerate() {
                if matches!(spec.role, ParamRole::RelaxationWeight { .. }) {
                    s[j] = 0.1;
                }
            }
            out.push(s);
        }
    }
    out
}

/// The practical size of an effect: misfit/noise before and after, the
/// share of the excess mean square (above sigma^2) it removes, and the RMS
/// of the systematic component it removes, sqrt(max(MS_b - MS_a, 0)), in
/// noise SDs, against the materiality threshold.
pub(crate) fn practical_size(
    before: f64,
    after: f64,
    sigma: f64,
    materiality: f64,
) -> PracticalSize {
    let (mb, ma, s2) = (before * before, after * after, sigma * sigma);
    let excess = mb - s2;
    let removed = (mb - ma).max(0.0).sqrt() / sigma;
    PracticalSize {
        misfit_over_noise_before: before / sigma,
        misfit_over_noise_after: after / sigma,
        excess_explained: (excess > 0.0).then(|| ((mb - ma) / excess).min(1.0)),
        removed_over_noise: removed,
        material: removed >= materiality,
    }
}

/// The enrichment's sensitivities at "off" (`f_off` its predictions there).
/// When "off" reproduces the base fit's predictions, the base columns are
/// the base model's sensitivities at its optimum, already computed
/// (`ctx.base_jac`), and only the effect's own columns are differenced,
/// through `f_off` (forward differences for an expensive model).
fn sensitivities_at_off(
    rich: &dyn ForwardModel,
    off: &[f64],
    f_off: &[f64],
    ctx: &Context<'_>,
) -> Result<DMatrix<f64>, GapError> {
    let p = ctx.p;
    let m = off.len();
    let scale = ctx
        .base_full
        .predicted
        .iter()
        .fold(0.0f64, |a, v| a.max(v.abs()));
    let reproduces = f_off
        .iter()
        .zip(&ctx.base_full.predicted)
        .all(|(a, b)| (a - b).abs() <= 1e-12 * scale);
    match ctx.base_jac {
        Some(base_jac) if reproduces && base_jac.ncols() == p => {
            let wanted: Vec<bool> = (0..m).map(|j| j >= p).collect();
            let mut jac =
                sensitivities_at(rich, off, ctx.loading, &wanted, Some(f_off), ctx.expensive)?;
            jac.columns_mut(0, p).copy_from(base_jac);
            Ok(jac)
        }
        _ => Ok(sensitivities_at(
            rich,
            off,
            ctx.loading,
            &vec![true; m],
            Some(f_off),
            ctx.expensive,
        )?),
    }
}

/// Score test, refits and comparison of one enrichment; `f_off` are its
/// predictions at "off" (the base optimum embedded).
pub(crate) fn assess(
    effect: Effect,
    rich: Arc<dyn ForwardModel>,
    f_off: &[f64],
    ctx: &Context<'_>,
) -> Result<Assessed, GapError> {
    let (n, p) = (ctx.observed.len(), ctx.p);
    let specs = rich.space().params.clone();
    let q = specs.len() - p;
    let off = embed(rich.as_ref(), &ctx.base_theta);
    let jac = sensitivities_at_off(rich.as_ref(), &off, f_off, ctx)?;
    let at_lower: Vec<bool> = (p..specs.len()).map(|j| off[j] <= specs[j].lower).collect();
    let at_upper: Vec<bool> = (p..specs.len()).map(|j| off[j] >= specs[j].upper).collect();
    let score = score_test(&ctx.base_residual, &jac, p, ctx.sigma, &at_lower, &at_upper);

    let duration = ctx
        .loading
        .time
        .as_ref()
        .map(|t| t[t.len() - 1] - t[0])
        .unwrap_or(0.0);
    let mut starts = candidate_starts(rich.as_ref(), p, &off, &score.step, duration);
    if let Some(alone) = ctx.solo.get(&effect) {
        starts.extend(set_starts(rich.as_ref(), p, &off, alone, duration));
    }
    if !ctx.expensive {
        let scanned = scale_scan_starts(rich.as_ref(), p, &off, &starts, ctx.loading, ctx.observed);
        starts.extend(scanned);
    }
    let mut projected = false;
    if ctx.expensive {
        starts = screen_starts(rich.as_ref(), ctx.loading, ctx.observed, starts);
        // one non-modulus parameter: a projected line search from the best
        // screened start gives the refit a start near its optimum
        if q == 1 && !specs[p].is_modulus() {
            if let Some(first) = starts.first() {
                if let Some(found) = projected_line_search(
                    rich.as_ref(),
                    ctx.loading,
                    ctx.observed,
                    first,
                    p,
                    ctx.sigma,
                ) {
                    starts.insert(0, found);
                    projected = true;
                }
            }
        }
    }
    let full = if ctx.expensive {
        // From the best screened start; the next ones only if it fails.
        let mut outcome = Err(GapError::InvalidOption {
            option: "starts",
            reason: "no starting point".into(),
        });
        for (k, start) in starts.iter().enumerate() {
            // from the projected search's optimum: its statistics (along a
            // flat valley, such as friction once the needle sticks, the LM
            // only creeps by fractions of sigma^2)
            outcome = fit_with_budget(
                &rich,
                ctx.loading,
                ctx.observed,
                None,
                std::slice::from_ref(start),
                &[],
                true,
                (projected && k == 0).then_some(PROJECTED_POLISH),
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
        ctx.folds,
        &full,
        &cv_starts,
        &[],
        None,
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
    let later = ctx.later;
    let heldout_gain = (sse(&h_before) - sse(&h_after)) / sigma2;
    let dev_base = ar1_deviance(&ctx.base_residual);
    let dev_rich = ar1_deviance(&r_after);
    let nf = n as f64;
    let delta_aic = dev_rich - dev_base + 2.0 * lr_dof as f64;
    let delta_bic = dev_rich - dev_base + lr_dof as f64 * nf.ln();
    let lr_level = ctx.alpha / ctx.candidates.max(1) as f64;
    let gain_threshold = chi2_isf(ctx.alpha, 1.0);
    // A degenerate member (Prony terms at total relaxation, or a time
    // constant the record cannot resolve) is reported and earns nothing.
    let degenerate_why = degenerate(&specs, &full.theta, p, ctx.loading);
    let earns = lr_p < lr_level && heldout_gain > gain_threshold && degenerate_why.is_none();

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
    canonical_prony(&mut params, &specs, &full.theta);
    canonical_prony(&mut all_params, &specs, &full.theta);
    canonical_prony(&mut standard_errors, &specs, &full.theta);
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
    let misfit_before = rms(&ctx.base_residual);
    let misfit_after = rms(&r_after);
    let practical = practical_size(misfit_before, misfit_after, ctx.sigma, ctx.materiality);
    let evidence = format!(
        "score test {:.1} on {} dof (p = {:.1e}); refit: likelihood ratio {:.1} on {lr_dof} parameter(s) (p = {:.1e}, \
         needs < {:.1e}); cross-validation gain {:.1} (needs > {:.1}), held-out RMS {:.3e} -> {:.3e} \
         (later segment {:.3e} -> {:.3e}); dAIC {:.1}, dBIC {:.1} \
         under AR(1) errors; residual RMS/noise {:.2} -> {:.2} ({} of the excess misfit, a systematic \
         component of {:.2} noise SD removed: {}), runs p {:.1e} -> {:.1e}; {}",
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
        practical.misfit_over_noise_before,
        practical.misfit_over_noise_after,
        practical
            .excess_explained
            .map_or("none".to_string(), |s| format!("{:.0} %", 100.0 * s)),
        practical.removed_over_noise,
        if practical.material {
            "material"
        } else {
            "immaterial"
        },
        whiteness(&ctx.base_residual, p, ctx.sigma, ctx.rel_var_sd2).runs_p,
        after.runs_p,
        ident.reason
    );
    let evidence = match &degenerate_why {
        Some(why) => format!("{evidence}; degenerate fit, not credited: {why}"),
        None => evidence,
    };
    let ranked = RankedEffect {
        effect,
        params,
        misfit_before,
        misfit_after,
        heldout_before: rms(&h_before),
        heldout_after: rms(&h_after),
        later_before: rms(&h_before[later..]),
        later_after: rms(&h_after[later..]),
        evidence,
        identifiable,
        confounded_with: Vec::new(),
        sensitivity_overlap: BTreeMap::new(),
        earns,
        practical,
        model: rich.name(),
        form: None,
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
    Ok(Assessed {
        ranked,
        fitted: full,
        projected,
        model: rich,
        off,
        cv,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prony_terms_are_relabelled_by_increasing_time_constant() {
        let specs = vec![
            ParamSpec::new("C10", "MPa", 0.0, 1.0, 0.1).with_role(ParamRole::Modulus),
            ParamSpec::new("g1", "1", 0.0, 1.0, 0.1)
                .with_role(ParamRole::RelaxationWeight { term: 1 }),
            ParamSpec::new("tau1_s", "s", 0.0, 1e9, 1.0)
                .with_role(ParamRole::TimeConstant { term: 1 }),
            ParamSpec::new("g2", "1", 0.0, 1.0, 0.1)
                .with_role(ParamRole::RelaxationWeight { term: 2 }),
            ParamSpec::new("tau2_s", "s", 0.0, 1e9, 1.0)
                .with_role(ParamRole::TimeConstant { term: 2 }),
        ];
        let theta = [1e-3, 0.2, 30.0, 0.3, 2.0];
        let mut map: BTreeMap<String, f64> = specs
            .iter()
            .zip(&theta)
            .map(|(s, v)| (s.name.clone(), *v))
            .collect();
        canonical_prony(&mut map, &specs, &theta);
        assert_eq!(map["g1"], 0.3);
        assert_eq!(map["tau1_s"], 2.0);
        assert_eq!(map["g2"], 0.2);
        assert_eq!(map["tau2_s"], 30.0);
        assert_eq!(map["C10"], 1e-3);
    }

    #[test]
    fn practical_size_of_a_tiny_and_of_a_large_reduction() {
        // 1.08 -> 1.05 x noise removes a 0.25 sigma component: significant
        // with many samples, immaterial.
        let tiny = practical_size(1.08, 1.05, 1.0, 0.4);
        assert!((tiny.removed_over_noise - 0.2528).abs() < 1e-3 && !tiny.material);
        assert!((tiny.excess_explained.unwrap() - 0.0639 / 0.1664).abs() < 1e-3);
        let large = practical_size(1.5, 1.0, 1.0, 0.4);
        assert!(large.material && (large.excess_explained.unwrap() - 1.0).abs() < 1e-12);
        assert!(practical_size(0.9, 0.89, 1.0, 0.4)
            .excess_explained
            .is_none());
    }
}
