//! The diagnosis itself: the stages in order. Validate the record, estimate
//! the noise, fit the base model ([`super::base`]), locate the misfit
//! ([`super::structure`]), assess every candidate ([`super::assess`]), rank
//! them ([`super::rank`]), decide ([`super::verdict`]) and hold the effects
//! the record cannot see at the ends of their range ([`super::undetectable`]).

use super::assess::{assess, Assessed, Context};
use super::base::fit_base;
use super::compose::{enrich_form, Composite};
use super::crossval::Folds;
use super::memo::Memo;
use super::noise::{difference_noise_sd, path_noise_sd};
use super::plausible::offset_range;
use super::rank::rank;
use super::report::{BaseSummary, FailedCandidate, GapPlot, GapReport};
use super::residual::{residuals, rms};
use super::set::{explain, remainder_of_base, Stage};
use super::structure::{default_window, discrepancy_band, significant_windows, whiteness};
use super::undetectable::undetectable;
use super::verdict::decide;
use super::{GapError, GapOptions};
use palpate_core::enrichable::{effects_of, embed, enrich_forms};
use palpate_core::{Effect, ForwardError, ForwardModel, Loading};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::Arc;

/// One form of a candidate: the effect, the form's index and name, the
/// enriched model and its predictions at "off".
type Form = (Effect, usize, String, Arc<dyn ForwardModel>, Vec<f64>);

/// Fewest samples the diagnosis works with: the noise estimate from second
/// differences needs them.
const MIN_SAMPLES: usize = 8;
/// Below this many samples a diagnosis is made with a caveat that states
/// its power (the smallest misfit it can tell from the noise), and the
/// cross-validation uses fewer folds (two samples at least per fold).
pub(crate) const SHORT_RECORD: usize = 16;

/// Diagnoses the gap between `base` and `observed` (one value per sample of
/// `loading`, in the unit of `base.observable()`). See the module docs.
pub fn diagnose(
    base: &dyn ForwardModel,
    loading: &Loading,
    observed: &[f64],
    options: &GapOptions,
) -> Result<GapReport, GapError> {
    options.validate()?;
    // An expensive model's predictions are cached for the whole diagnosis
    // (repeats and, when the model is homogeneous in its moduli, whole rays;
    // see `memo`).
    let memo;
    let base: &dyn ForwardModel = if base.expensive() && options.cache {
        memo = Memo::borrowed(base);
        &memo
    } else {
        base
    };
    let n = observed.len();
    if n != loading.len() {
        return Err(GapError::LengthMismatch {
            observed: n,
            samples: loading.len(),
        });
    }
    if n < MIN_SAMPLES {
        return Err(GapError::TooFewSamples {
            got: n,
            needed: MIN_SAMPLES,
        });
    }
    // A short record keeps at least two samples per fold.
    let fold_count = options.folds.min(n / 2);
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
    let noise = match &options.paths {
        Some(paths) => path_noise_sd(observed, paths)?,
        None => difference_noise_sd(observed, loading.time.as_deref())?,
    };
    let sigma = noise.sd;
    if sigma.is_nan() || sigma <= 0.0 {
        return Err(GapError::ZeroNoise);
    }
    let p = base.space().len();
    let caveat =
        (n < SHORT_RECORD).then(|| short_record_caveat(n, p, &noise, options.alpha, fold_count));
    let w = options.window.unwrap_or_else(|| default_window(n)).min(n);
    let folds = Folds::new(options.fold_layout, &loading.drive, fold_count, w);
    let later = n - n / fold_count;

    // Base fit on all samples, and its held-out predictions.
    let expensive = base.expensive();
    let linearised = options
        .cross_validation
        .linearised(expensive, options.fold_layout);
    let base_fit = fit_base(base, loading, observed, &folds, linearised)?;
    let base_theta = base_fit.theta.clone();
    let base_residual = residuals(observed, &base_fit.full.predicted);

    // Where: whole-record tests and windows.
    let tests = whiteness(&base_residual, p, sigma, noise.rel_var_sd2);
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
    // Each enrichment's predictions at "off", for every form of the
    // effect (the richer laws of `material_form`): enrichments that cannot
    // run on this history (e.g. no time for QLV) are skipped, the others
    // reuse them in their score test.
    let enriched: Vec<Form> = effects
        .into_par_iter()
        .flat_map_iter(|e| {
            let forms = enrich_forms(base, e).unwrap_or_default();
            forms
                .into_iter()
                .enumerate()
                .filter_map(|(k, form)| {
                    let rich: Arc<dyn ForwardModel> = Arc::from(form.model);
                    let f_off = rich
                        .predict(&embed(rich.as_ref(), &base_theta), loading)
                        .ok()?;
                    Some((e, k, form.name, rich, f_off))
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let mut distinct: Vec<Effect> = enriched.iter().map(|x| x.0).collect();
    distinct.dedup();
    // The default forms first; the others only where the default earns its
    // place, or where no candidate does (see `search_forms`).
    let (enriched, mut other_forms): (Vec<_>, Vec<_>) =
        enriched.into_iter().partition(|x| x.1 == 0);
    let ctx = Context {
        loading,
        observed,
        sigma,
        folds: &folds,
        later,
        p,
        base_theta: base_theta.clone(),
        base_full: &base_fit.full,
        base_cv: base_fit.cv.clone(),
        base_residual: base_residual.clone(),
        base_jac: base_fit.jac.as_ref(),
        candidates: distinct.len(),
        alpha: options.alpha,
        rel_var_sd2: noise.rel_var_sd2,
        materiality: options.materiality,
        linearised,
        expensive,
        solo: Default::default(),
    };
    // Candidates are independent: assessed in parallel, collected in order.
    // A zero offset fitted where the record carries load is refitted within
    // what the record permits.
    let offsets = offset_range(loading, observed, sigma);
    let assess_all = |enriched: Vec<Form>| {
        enriched
        .into_par_iter()
        .map(|(e, k, name, rich, f_off)| {
            let outcome = assess(e, rich, &f_off, &ctx);
            let implausible = outcome.as_ref().is_ok_and(|a| offset_outside(a, offsets));
            if !implausible {
                return (e, k, name, outcome);
            }
            let bounded = enrich_form(base, e, &BTreeMap::from([(e, k)])).and_then(|inner| {
                let off = embed(inner.as_ref(), &base_theta);
                Composite::bounded(inner, &off, p, offsets)
            });
            match bounded {
                Some(c) => {
                    let again = assess(e, Arc::new(c), &f_off, &ctx).map(|mut a| {
                        let (lo, hi) = offsets.unwrap_or_default();
                        a.ranked.evidence.push_str(&format!(
                            "; zero offset held within [{lo:.4}, {hi:.4}], what the record's unloaded samples permit \
                             (fitted free, it put the unloaded state where the record carries load)"
                        ));
                        a
                    });
                    (e, k, name, again)
                }
                None => (e, k, name, outcome),
            }
        })
        .collect::<Vec<(Effect, usize, String, Result<Assessed, GapError>)>>()
    };
    let mut outcomes = assess_all(enriched);
    other_forms.retain(|x| search_forms(x.0, &outcomes, gap_significant));
    if !other_forms.is_empty() {
        outcomes.extend(assess_all(other_forms));
    }
    // An effect of several forms: the form with the best held-out misfit,
    // each parameter charged.
    let (outcomes, forms) = choose_forms(outcomes, options.alpha);
    let mut assessed = Vec::new();
    let mut failed = Vec::new();
    for (effect, outcome) in outcomes {
        match outcome {
            Ok(a) => assessed.push(a),
            Err(err) => failed.push(FailedCandidate {
                effect,
                error: err.to_string(),
            }),
        }
    }
    rank(
        &mut assessed,
        loading,
        observed,
        p,
        sigma,
        options.confound_alpha,
        expensive,
    );
    let ranking: Vec<_> = assessed.iter().map(|a| a.ranked.clone()).collect();
    let decision = decide(
        &ranking,
        gap_significant,
        &reason,
        sigma,
        options.alpha,
        options.materiality,
    );
    let detected: Vec<Effect> = decision
        .verdict
        .effect()
        .into_iter()
        .chain(decision.confounded.iter().copied())
        .chain(decision.immaterial.iter().copied())
        .collect();
    let undetectable = undetectable(
        &assessed,
        &detected,
        loading,
        observed,
        p,
        base_fit.full.sse,
        sigma,
        expensive,
    );

    // Explain: the verdict as the first member of a set of effects.
    let mut stage = Stage {
        base,
        base_theta: &base_theta,
        loading,
        observed,
        sigma,
        folds: &folds,
        later,
        alpha: options.alpha,
        confound_alpha: options.confound_alpha,
        rel_var_sd2: noise.rel_var_sd2,
        materiality: options.materiality,
        linearised,
        expensive,
        axis_name: &axis_name,
        x: &x,
        window: w,
        offsets,
        solo: assessed
            .iter()
            .map(|a| (a.ranked.effect, a.ranked.all_params.clone()))
            .collect(),
        forms,
    };
    let offered: Vec<Effect> = assessed.iter().map(|a| a.ranked.effect).collect();
    let first = decision
        .verdict
        .effect()
        .and_then(|e| assessed.iter().find(|a| a.ranked.effect == e));
    let (explanation_set, remainder, dropped, set_fit, explanation) = match first {
        Some(first) => {
            let set = explain(&mut stage, &base_fit.full, &base_fit.cv, first, &offered);
            let mut text = decision.explanation.clone();
            if set.members.len() > 1 || !set.dropped.is_empty() {
                text.push_str(&set_sentence(&set.members, &set.dropped));
            }
            text.push(' ');
            text.push_str(&set.remainder.note);
            let fit = (set.members.len() > 1).then_some(set.predicted);
            (set.members, set.remainder, set.dropped, fit, text)
        }
        None => {
            let remainder = remainder_of_base(&stage, &base_fit.full, &base_fit.cv, &offered);
            (
                Vec::new(),
                remainder,
                Vec::new(),
                None,
                decision.explanation.clone(),
            )
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
        base_fit: base_fit.full.predicted.clone(),
        base_residual: base_residual.clone(),
        band_mean,
        band_lower,
        band_upper,
        set_fit,
        enriched_effect: best_fit.map(|a| a.ranked.effect),
        enriched_fit: best_fit.map(|a| a.fitted.predicted.clone()),
        enriched_residual: best_fit.map(|a| residuals(observed, &a.fitted.predicted)),
        folds: folds.chunks.clone(),
        base_cv: base_fit.cv.clone(),
    };
    let explanation = match &caveat {
        Some(c) => format!("{c} {explanation}"),
        None => explanation,
    };
    let base_names = base.space().names();
    let heldout_base = residuals(observed, &base_fit.cv);
    Ok(GapReport {
        verdict: decision.verdict,
        noise_sd: sigma,
        where_: windows,
        ranking,
        failed,
        confounded: decision.confounded,
        immaterial: decision.immaterial,
        partly_explained: decision.partly,
        undetectable,
        explanation,
        explanation_set,
        dropped,
        remainder,
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
        folds: fold_count,
        caveat,
        plot,
    })
}

/// The caveat of a short record (`n` samples, `p` base parameters): the
/// power of the misfit test, the smallest RMS misfit / noise it tells from
/// the noise at level `alpha`. Under the null SSE / sigma^2 / (n - p) has
/// mean 1 and variance 2 / (n - p) plus the relative variance of the noise
/// estimate (the test of [`whiteness`]); the misfit is significant when it
/// exceeds 1 + z_alpha times that SD.
fn short_record_caveat(
    n: usize,
    p: usize,
    noise: &super::NoiseEstimate,
    alpha: f64,
    folds: usize,
) -> String {
    let dof = n.saturating_sub(p).max(1) as f64;
    let z = super::structure::chi2_isf(2.0 * alpha, 1.0).sqrt();
    let detectable = (1.0 + z * (2.0 / dof + noise.rel_var_sd2).sqrt()).sqrt();
    format!(
        "Short record: {n} samples ({SHORT_RECORD} give the diagnosis its usual power). The noise SD rests on {} \
         second differences (its square uncertain by +-{:.0} %) and the cross-validation on {folds} folds of about {} \
         samples, so only a misfit above {detectable:.2} x noise can be told from the noise at level {alpha:.0e}; a \
         smaller gap goes unseen. More samples along the same loading path (or replicates) would show smaller gaps.",
        noise.used,
        100.0 * noise.rel_var_sd2.sqrt(),
        n / folds.max(1),
    )
}

/// Whether the other forms of `effect` are tried: when its default form
/// leads the candidates (earns its parameters, matters, and has the best
/// held-out gain, as the ranking orders them: a richer law than the
/// simplest may explain more), or when the gap is significant and no
/// candidate earns its place (it would be left unexplained). Otherwise the
/// default form stands: a family of flexible laws tried beside a leading
/// effect of another kind would shape the misfit that effect leaves (a
/// relaxation, a series compliance) rather than the law's, and cost a fit
/// per form.
fn search_forms(
    effect: Effect,
    outcomes: &[(Effect, usize, String, Result<Assessed, GapError>)],
    gap_significant: bool,
) -> bool {
    let counts = |a: &Assessed| a.ranked.earns && a.ranked.practical.material;
    let leader = outcomes
        .iter()
        .filter_map(|(e, _, _, o)| o.as_ref().ok().filter(|a| counts(a)).map(|a| (*e, a)))
        .max_by(|x, y| x.1.ranked.heldout_gain.total_cmp(&y.1.ranked.heldout_gain));
    match leader {
        Some((e, _)) => e == effect,
        None => gap_significant,
    }
}

/// The assessments of the candidates, one per effect, and the form chosen
/// for each effect of several forms (index and name). Among the forms of
/// one effect, as the ranking orders effects: those that earn their
/// parameters and matter first, then by the held-out gain, here charged
/// the chi2(1) quantile at `alpha` per parameter of the form (the gain one
/// parameter must exceed to earn it), so that a form of more parameters
/// must predict the held-out samples better by that much per parameter; a
/// tie keeps the first (default) form. The chosen form's evidence lists
/// the others.
#[allow(clippy::type_complexity)]
fn choose_forms(
    outcomes: Vec<(Effect, usize, String, Result<Assessed, GapError>)>,
    alpha: f64,
) -> (
    Vec<(Effect, Result<Assessed, GapError>)>,
    BTreeMap<Effect, (usize, String)>,
) {
    let charge = super::structure::chi2_isf(alpha, 1.0);
    let mut order: Vec<Effect> = Vec::new();
    let mut groups: BTreeMap<Effect, Vec<(usize, String, Result<Assessed, GapError>)>> =
        BTreeMap::new();
    for (e, k, name, outcome) in outcomes {
        if !order.contains(&e) {
            order.push(e);
        }
        groups.entry(e).or_default().push((k, name, outcome));
    }
    let mut out = Vec::new();
    let mut forms = BTreeMap::new();
    for e in order {
        let mut group = groups.remove(&e).unwrap_or_default();
        group.sort_by_key(|g| g.0);
        if group.len() == 1 && group[0].0 == 0 {
            let (_, _, outcome) = group.remove(0);
            out.push((e, outcome));
            continue;
        }
        let score = |a: &Assessed| {
            (
                a.ranked.earns && a.ranked.practical.material,
                a.ranked.earns,
                a.ranked.heldout_gain - charge * a.ranked.params.len() as f64,
            )
        };
        let mut best: Option<usize> = None;
        for (i, g) in group.iter().enumerate() {
            let Ok(a) = &g.2 else { continue };
            let better = match best {
                None => true,
                Some(b) => {
                    let (x, y) = (score(a), score(group[b].2.as_ref().expect("ok")));
                    (x.0, x.1)
                        .cmp(&(y.0, y.1))
                        .then(x.2.total_cmp(&y.2))
                        .is_gt()
                }
            };
            if better {
                best = Some(i);
            }
        }
        let Some(b) = best else {
            // every form failed: the default form's error
            let (_, _, outcome) = group.remove(0);
            out.push((e, outcome));
            continue;
        };
        let others: Vec<String> = group
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != b)
            .map(|(_, g)| match &g.2 {
                Ok(a) => format!(
                    "{} (held-out gain {:.1} on {} parameter(s){})",
                    g.1,
                    a.ranked.heldout_gain,
                    a.ranked.params.len(),
                    if a.ranked.earns {
                        ""
                    } else {
                        ", does not earn them"
                    }
                ),
                Err(err) => format!("{} (failed: {err})", g.1),
            })
            .collect();
        let (k, name, outcome) = group.swap_remove(b);
        let chosen = outcome.map(|mut a| {
            a.ranked.evidence.push_str(&format!(
                "; form {name} (held-out gain {:.1} on {} parameter(s)), chosen among the forms by held-out gain less \
                 {charge:.1} per parameter; the others: {}",
                a.ranked.heldout_gain,
                a.ranked.params.len(),
                others.join(", ")
            ));
            a.ranked.form = Some(name.clone());
            a
        });
        forms.insert(e, (k, name));
        out.push((e, chosen));
    }
    (out, forms)
}

/// Whether a candidate's fitted zero offset lies outside what the record
/// permits.
fn offset_outside(a: &Assessed, offsets: Option<(f64, f64)>) -> bool {
    let Some((lo, hi)) = offsets else {
        return false;
    };
    a.model
        .space()
        .params
        .iter()
        .zip(&a.fitted.theta)
        .any(|(s, &v)| s.role == palpate_core::ParamRole::Offset && !(lo..=hi).contains(&v))
}

/// The sentence that names an explanation of several effects and their shares.
fn set_sentence(members: &[super::SetMember], dropped: &[Effect]) -> String {
    let parts: Vec<String> = members
        .iter()
        .map(|m| {
            let pct = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{:.0} %", 100.0 * v));
            format!(
                "`{}`{} ({} of the excess misfit in the order of selection, {} dropped one out)",
                m.effect,
                m.form.as_ref().map_or(String::new(), |f| format!(" ({f})")),
                pct(m.share_marginal),
                pct(m.share_dropped)
            )
        })
        .collect();
    let mut text = String::new();
    if members.len() > 1 {
        text.push_str(&format!(
            " Explained together by {} effects: {}; the set brings the misfit to {:.3e}, held out {:.3e}.",
            members.len(),
            parts.join(", "),
            members.last().map_or(f64::NAN, |m| m.misfit_after),
            members.last().map_or(f64::NAN, |m| m.heldout_after)
        ));
    }
    if !dropped.is_empty() {
        let names: Vec<&str> = dropped.iter().map(|e| e.name()).collect();
        text.push_str(&format!(
            " Dropped once the others were in: {} (no longer earns its place).",
            names.join(", ")
        ));
    }
    text
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
    fn the_refined_linearised_cross_validation_matches_the_refits() {
        // A nonlinear fold refit (the offset moves the kink): the chord
        // iterations from the full optimum reach the Levenberg-Marquardt
        // refits' held-out predictions, where one linear step need not.
        use super::super::crossval::cross_validate_by;
        use super::super::fit::fit_from_starts;
        let (loading, y) = data(0.3, 6);
        let model: Arc<dyn ForwardModel> = Arc::new(Spring::new(true));
        let starts = vec![vec![2.0, 0.1]];
        let full = fit_from_starts(&model, &loading, &y, None, &starts, &[], false).unwrap();
        let folds = Folds::new(super::super::FoldLayout::Stratified, &loading.drive, 8, 13);
        let cv = |linearised: bool| {
            let starts = vec![full.theta.clone()];
            cross_validate_by(
                linearised,
                &model,
                &loading,
                &y,
                &folds,
                &full,
                &starts,
                &[],
                None,
            )
            .unwrap()
        };
        let (refit, chord) = (cv(false), cv(true));
        let worst = refit
            .iter()
            .zip(&chord)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // within a hundredth of the noise SD (0.01) at every sample
        assert!(worst < 1e-4, "largest difference {worst}");
        assert!(refit
            .iter()
            .zip(&full.predicted)
            .any(|(a, b)| (a - b).abs() > 1e-4));
    }

    #[test]
    fn a_short_record_is_diagnosed_with_its_power_stated() {
        // 12 samples every 0.15 mm with a large offset: diagnosed, the
        // caveat says how large a misfit the record can show.
        let base = Spring::new(false);
        let (loading, y) = data(0.3, 4);
        let pick: Vec<usize> = (0..12).map(|i| 8 + 15 * i).collect();
        let short = Loading::quasi_static(
            Drive::DisplacementMm,
            pick.iter().map(|&i| loading.drive[i]).collect(),
        );
        let ys: Vec<f64> = pick.iter().map(|&i| y[i]).collect();
        let r = diagnose(&base, &short, &ys, &GapOptions::default()).unwrap();
        let caveat = r.caveat.as_deref().unwrap();
        assert!(caveat.contains("Short record: 12 samples"), "{caveat}");
        assert!(r.explanation.starts_with("Short record"));
        assert_eq!(r.folds, 6);
        // the smallest detectable misfit is stated and above the noise
        let at = caveat.find("misfit above ").unwrap() + "misfit above ".len();
        let ratio: f64 = caveat[at..].split(' ').next().unwrap().parse().unwrap();
        assert!(ratio > 1.2 && ratio < 3.0, "{caveat}");
        // a full-length record has no caveat; under 8 samples is refused
        let (loading, y) = data(0.0, 5);
        assert!(diagnose(&base, &loading, &y, &GapOptions::default())
            .unwrap()
            .caveat
            .is_none());
        let tiny = Loading::quasi_static(Drive::DisplacementMm, short.drive[..7].to_vec());
        let err = diagnose(&base, &tiny, &ys[..7], &GapOptions::default()).unwrap_err();
        assert!(
            matches!(err, GapError::TooFewSamples { got: 7, needed: 8 }),
            "{err}"
        );
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
