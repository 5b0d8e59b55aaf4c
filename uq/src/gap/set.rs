//! Explanations made of several effects.
//!
//! The single-effect verdict is the first step of a forward selection: with
//! the set chosen so far as the base, every remaining candidate is added in
//! turn ([`super::compose`]) and assessed exactly as one effect is against
//! the base model ([`super::assess`]: score test, refits, blocked
//! cross-validation, likelihood ratio at alpha / candidates, held-out gain
//! above the chi2(1) quantile, materiality), the candidates ranked as in
//! the first step ([`super::rank`]), and the leader joins the set when it
//! earns its parameters and matters. The selection stops when the set's
//! residuals are consistent with the noise (the whole-record tests and the
//! windows that decide whether there is a gap at all) or when no candidate
//! earns its place. A backward check then drops, one at a time, a member
//! that no longer earns its place given the others (the set refitted
//! without it: likelihood ratio, held-out gain and materiality as above),
//! as forward selection alone can keep an early effect that a later pair
//! makes redundant (Miller, *Subset Selection in Regression*, 2002, ch. 3).
//!
//! Each member's share of the excess misfit (the base's mean square above
//! the noise variance) is reported twice: marginal, in the order of
//! selection (what it removes on top of the members before it), and
//! dropped-one-out (what the set loses without it, the others refitted).
//! The two differ when members overlap; their sum over the set need not
//! be 100 %.

use super::assess::{assess, canonical_prony, Assessed, Context};
use super::compose::{compose, enrich_form};
use super::crossval::{cross_validate_by, Folds};
use super::fit::{fit_from_starts, Fitted};
use super::rank::rank;
use super::residual::{residuals, rms, sse};
use super::structure::WhitenessTests;
use super::structure::{chi2_isf, chi2_sf, significant_windows, whiteness, GapWindow};
use palpate_core::enrichable::{embed, enrich_forms};
use palpate_core::{Effect, ForwardModel, Loading};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Largest number of effects in one explanation.
pub(crate) const MAX_SET: usize = 4;

/// One effect of the explanation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SetMember {
    pub effect: Effect,
    /// Its form, when the effect has several (the richer law of
    /// `material_form`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub form: Option<String>,
    /// Its own parameters in the fit of the whole set (physical units).
    pub params: BTreeMap<String, f64>,
    /// Their standard errors in that fit (absent where undefined).
    pub standard_errors: BTreeMap<String, Option<f64>>,
    /// Share of the excess misfit (base mean square above the noise
    /// variance) it removes on top of the members selected before it;
    /// absent when the base misfit is not above the noise.
    pub share_marginal: Option<f64>,
    /// Share of the excess misfit the set loses without it (the others
    /// refitted).
    pub share_dropped: Option<f64>,
    /// RMS misfit and held-out RMS of the set up to and including it, in
    /// the order of selection (data unit).
    pub misfit_after: f64,
    pub heldout_after: f64,
    /// When it was added: likelihood ratio against the set before it, its
    /// p-value, and the held-out gain (SSE before - after) / sigma^2.
    pub lr_statistic: f64,
    pub lr_p: f64,
    pub heldout_gain: f64,
    /// Without it, the others refitted: likelihood ratio and held-out gain
    /// of the whole set against the set without it (absent for a set of one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dropped_lr: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dropped_heldout_gain: Option<f64>,
    /// Candidates that would have done as well at its step: the data cannot
    /// tell them apart from it given the members before it.
    pub confounded_with: Vec<Effect>,
    /// The numbers behind its place, as for a single effect.
    pub evidence: String,
}

impl SetMember {
    /// Its parameters as the reports print them: `name = value +- SE`.
    pub fn params_text(&self) -> String {
        let params: Vec<String> = self
            .params
            .iter()
            .map(
                |(n, v)| match self.standard_errors.get(n).copied().flatten() {
                    Some(se) => format!("{n} = {v:.4e} +- {se:.1e}"),
                    None => format!("{n} = {v:.4e}"),
                },
            )
            .collect();
        params.join(", ")
    }
}

/// What the explanation leaves unexplained.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Remainder {
    /// RMS misfit and held-out RMS of the whole set (data unit).
    pub misfit: f64,
    pub heldout: f64,
    /// RMS misfit / noise SD.
    pub misfit_over_noise: f64,
    /// Share of the excess misfit left, (MS_set - sigma^2) / (MS_base -
    /// sigma^2), at least 0; absent when the base misfit is not above the noise.
    pub share_unexplained: Option<f64>,
    /// Whether the set's residuals pass the tests that decide whether there
    /// is a gap (misfit, runs, lag-1 autocorrelation, windows).
    pub consistent_with_noise: bool,
    pub tests: WhitenessTests,
    /// Windows of significant misfit left by the set.
    #[serde(rename = "where")]
    pub where_: Vec<GapWindow>,
    /// One paragraph: how large the remainder is, where it lies, and what
    /// it may mean.
    pub note: String,
}

/// What the diagnosis shares with the selection.
pub(crate) struct Stage<'a> {
    pub base: &'a dyn ForwardModel,
    pub base_theta: &'a [f64],
    pub loading: &'a Loading,
    pub observed: &'a [f64],
    pub sigma: f64,
    pub folds: &'a Folds,
    pub later: usize,
    pub alpha: f64,
    pub confound_alpha: f64,
    pub rel_var_sd2: f64,
    pub materiality: f64,
    pub linearised: bool,
    pub expensive: bool,
    pub axis_name: &'a str,
    pub x: &'a [f64],
    pub window: usize,
    /// The zero offsets the record permits.
    pub offsets: Option<(f64, f64)>,
    /// Each candidate's parameters fitted alone (the first step): starts
    /// for its parameters when it joins a set.
    pub solo: BTreeMap<Effect, BTreeMap<String, f64>>,
    /// The form of each effect that has several, chosen in the first step
    /// (index among `enrich_forms`), and its name.
    pub forms: BTreeMap<Effect, (usize, String)>,
}

/// A set of effects fitted to the record.
#[derive(Clone)]
struct SetFit {
    /// In the order of selection.
    effects: Vec<Effect>,
    /// The enriched model (none for the base fit, the set of no effect).
    model: Option<Arc<dyn ForwardModel>>,
    /// Its parameter names.
    names: Vec<String>,
    fitted: Fitted,
    cv: Vec<f64>,
}

/// The step at which a member joined: its assessment against the set before it.
struct Joined {
    effect: Effect,
    lr_statistic: f64,
    lr_p: f64,
    heldout_gain: f64,
    confounded_with: Vec<Effect>,
    evidence: String,
}

/// The explanation: members in the order of selection, the remainder and
/// the effects the backward check dropped.
pub(crate) struct Explanation {
    pub members: Vec<SetMember>,
    pub remainder: Remainder,
    pub dropped: Vec<Effect>,
    /// Predictions of the whole set.
    pub predicted: Vec<f64>,
}

impl Stage<'_> {
    fn mean_square(&self, total: f64) -> f64 {
        total / self.observed.len() as f64
    }

    /// Whether residuals `r` of a fit with `params` parameters look like noise.
    fn consistent(&self, r: &[f64], params: usize) -> bool {
        let t = whiteness(r, params, self.sigma, self.rel_var_sd2);
        t.misfit_p >= self.alpha
            && t.runs_p >= self.alpha
            && t.lag1_p >= self.alpha
            && significant_windows(
                r,
                self.axis_name,
                self.x,
                self.sigma,
                self.window,
                self.alpha,
            )
            .is_empty()
    }

    /// The chosen forms by index, as [`compose`] takes them.
    fn form_index(&self) -> BTreeMap<Effect, usize> {
        self.forms.iter().map(|(e, (k, _))| (*e, *k)).collect()
    }

    /// The effects' own parameter names: those the effect adds to the base
    /// alone.
    fn own_names(&self, effect: Effect) -> Vec<String> {
        let base_names = self.base.space().names();
        enrich_form(self.base, effect, &self.form_index())
            .map(|m| {
                m.space()
                    .names()
                    .into_iter()
                    .filter(|n| !base_names.contains(n))
                    .collect()
            })
            .unwrap_or_default()
    }

    /// `effects` fitted to the record, starting from the parameters of
    /// `donor` (by name; the others at "off"), cross-validated.
    fn fit_set(&self, effects: &[Effect], donor: &SetFit) -> Option<SetFit> {
        self.fit_set_with(effects, donor, &self.form_index())
    }

    /// [`Self::fit_set`] with the effects of several forms in the forms
    /// `forms` (by index).
    fn fit_set_with(
        &self,
        effects: &[Effect],
        donor: &SetFit,
        forms: &BTreeMap<Effect, usize>,
    ) -> Option<SetFit> {
        let prefix = self.base.space().names();
        let model: Arc<dyn ForwardModel> = Arc::new(compose(
            self.base,
            effects,
            &prefix,
            self.base_theta,
            self.offsets,
            forms,
        )?);
        let names = model.space().names();
        let donor_names = &donor.names;
        let mut start = embed(model.as_ref(), self.base_theta);
        for (j, n) in names.iter().enumerate() {
            if let Some(k) = donor_names.iter().position(|d| d == n) {
                start[j] = donor.fitted.theta[k];
            }
        }
        let starts = vec![start, embed(model.as_ref(), self.base_theta)];
        let fitted = fit_from_starts(
            &model,
            self.loading,
            self.observed,
            None,
            &starts,
            &[],
            self.expensive,
        )
        .ok()?;
        let mut cv_starts = vec![fitted.theta.clone()];
        cv_starts.extend(starts);
        let cv = cross_validate_by(
            self.linearised,
            &model,
            self.loading,
            self.observed,
            self.folds,
            &fitted,
            &cv_starts,
            &[],
            None,
        )
        .ok()?;
        Some(SetFit {
            effects: effects.to_vec(),
            names,
            model: Some(model),
            fitted,
            cv,
        })
    }

    /// One step of the forward selection: every remaining candidate added
    /// to `current` and assessed against it; the leader when it earns its
    /// parameters and is material.
    fn forward_step(&self, current: &SetFit, remaining: &[Effect]) -> Option<(Assessed, SetFit)> {
        let prefix = current.names.clone();
        let theta = &current.fitted.theta;
        let forms = self.form_index();
        let built: Vec<(Effect, Arc<dyn ForwardModel>, Vec<f64>)> = remaining
            .par_iter()
            .filter_map(|&e| {
                let mut effects = current.effects.clone();
                effects.push(e);
                let rich: Arc<dyn ForwardModel> = Arc::new(compose(
                    self.base,
                    &effects,
                    &prefix,
                    self.base_theta,
                    self.offsets,
                    &forms,
                )?);
                let f_off = rich
                    .predict(&embed(rich.as_ref(), theta), self.loading)
                    .ok()?;
                Some((e, rich, f_off))
            })
            .collect();
        if built.is_empty() {
            return None;
        }
        let p = prefix.len();
        let base_residual = residuals(self.observed, &current.fitted.predicted);
        let ctx = Context {
            loading: self.loading,
            observed: self.observed,
            sigma: self.sigma,
            folds: self.folds,
            later: self.later,
            p,
            base_theta: theta.clone(),
            base_full: &current.fitted,
            base_cv: current.cv.clone(),
            base_residual,
            base_jac: None,
            candidates: built.len(),
            alpha: self.alpha,
            rel_var_sd2: self.rel_var_sd2,
            materiality: self.materiality,
            linearised: self.linearised,
            expensive: self.expensive,
            solo: self.solo.clone(),
        };
        let mut assessed: Vec<Assessed> = built
            .into_par_iter()
            .filter_map(|(e, rich, f_off)| assess(e, rich, &f_off, &ctx).ok())
            .collect();
        rank(
            &mut assessed,
            self.loading,
            self.observed,
            p,
            self.sigma,
            self.confound_alpha,
            self.expensive,
        );
        let best = assessed.into_iter().next()?;
        if !(best.ranked.earns && best.ranked.practical.material) {
            return None;
        }
        let mut effects = current.effects.clone();
        effects.push(best.ranked.effect);
        let next = SetFit {
            effects,
            names: best.model.space().names(),
            model: Some(best.model.clone()),
            fitted: best.fitted.clone(),
            cv: best.cv.clone(),
        };
        Some((best, next))
    }

    /// The form of every member of several forms (the law of
    /// `material_form`) chosen again given the other members of `current`,
    /// by the rule of the first step (the held-out misfit, each parameter
    /// charged the chi2(1) quantile at alpha): the form chosen against the
    /// base alone shapes what the other effects leave there (an Ogden law
    /// bends to mimic a zero offset), and once the offset is in the set a
    /// simpler law may predict better. Returns the set refitted in the new
    /// forms and the members whose form changed, or `None` when every form
    /// stands.
    fn rechoose_forms(&mut self, current: &SetFit) -> Option<(SetFit, Vec<Effect>)> {
        if current.effects.len() < 2 {
            return None;
        }
        let s2 = self.sigma * self.sigma;
        let charge = chi2_isf(self.alpha, 1.0);
        let score =
            |s: &SetFit| sse(&residuals(self.observed, &s.cv)) / s2 + charge * s.names.len() as f64;
        let mut best = current.clone();
        let mut changed = Vec::new();
        for &e in &current.effects {
            let Some(&(k0, _)) = self.forms.get(&e) else {
                continue;
            };
            let names: Vec<String> = enrich_forms(self.base, e)
                .map(|f| f.into_iter().map(|f| f.name).collect())
                .unwrap_or_default();
            if names.len() < 2 {
                continue;
            }
            let tried: Vec<(usize, SetFit)> = (0..names.len())
                .into_par_iter()
                .filter(|&k| k != k0)
                .filter_map(|k| {
                    let mut forms = self.form_index();
                    forms.insert(e, k);
                    self.fit_set_with(&best.effects, &best, &forms)
                        .map(|s| (k, s))
                })
                .collect();
            let winner = tried
                .into_iter()
                .min_by(|a, b| score(&a.1).total_cmp(&score(&b.1)));
            if let Some((k, s)) = winner {
                if score(&s) < score(&best) {
                    self.forms.insert(e, (k, names[k].clone()));
                    best = s;
                    changed.push(e);
                }
            }
        }
        (!changed.is_empty()).then_some((best, changed))
    }

    /// Whether `member` earns its place in `set` against `without` (the set
    /// refitted without it): likelihood ratio, held-out gain, materiality.
    /// Returns (earns, likelihood ratio, held-out gain).
    fn earns_place(&self, set: &SetFit, without: &SetFit, size: usize) -> (bool, f64, f64) {
        let s2 = self.sigma * self.sigma;
        let q = set.names.len().saturating_sub(without.names.len());
        let lr = (without.fitted.sse - set.fitted.sse) / s2;
        let lr_p = chi2_sf(lr, q.max(1) as f64);
        let gain = (sse(&residuals(self.observed, &without.cv))
            - sse(&residuals(self.observed, &set.cv)))
            / s2;
        let removed = (self.mean_square(without.fitted.sse) - self.mean_square(set.fitted.sse))
            .max(0.0)
            .sqrt()
            / self.sigma;
        let earns = lr_p < self.alpha / size.max(1) as f64
            && gain > chi2_isf(self.alpha, 1.0)
            && removed >= self.materiality;
        (earns, lr, gain)
    }
}

impl Joined {
    fn from(a: &Assessed) -> Self {
        Joined {
            effect: a.ranked.effect,
            lr_statistic: a.ranked.lr_statistic,
            lr_p: a.ranked.lr_p,
            heldout_gain: a.ranked.heldout_gain,
            confounded_with: a.ranked.confounded_with.clone(),
            evidence: a.ranked.evidence.clone(),
        }
    }
}

/// The fit of the set `effects` (any order) among `cache`.
fn cached<'c>(cache: &'c [SetFit], effects: &[Effect]) -> Option<&'c SetFit> {
    cache
        .iter()
        .find(|s| s.effects.len() == effects.len() && effects.iter().all(|e| s.effects.contains(e)))
}

/// A drop-one-out of the current set: the member, the set refitted
/// without it, whether the member earns its place, the likelihood ratio
/// and held-out gain of keeping it.
type Drop = (Effect, SetFit, bool, f64, f64);

/// The explanation that starts from the verdict's assessment `first` and
/// draws further members from `offered` (forward selection, then the
/// backward check); `base_full` and `base_cv` are the base fit and its
/// held-out predictions.
pub(crate) fn explain(
    stage: &mut Stage<'_>,
    base_full: &Fitted,
    base_cv: &[f64],
    first: &Assessed,
    offered: &[Effect],
) -> Explanation {
    let base = SetFit {
        effects: Vec::new(),
        model: None,
        names: stage.base.space().names(),
        fitted: base_full.clone(),
        cv: base_cv.to_vec(),
    };
    let mut current = SetFit {
        effects: vec![first.ranked.effect],
        names: first.model.space().names(),
        model: Some(first.model.clone()),
        fitted: first.fitted.clone(),
        cv: first.cv.clone(),
    };
    let mut cache = vec![base.clone(), current.clone()];
    let mut joined = vec![Joined::from(first)];
    // Forward selection.
    while current.effects.len() < MAX_SET
        && !stage.consistent(
            &residuals(stage.observed, &current.fitted.predicted),
            current.names.len(),
        )
    {
        let remaining: Vec<Effect> = offered
            .iter()
            .copied()
            .filter(|e| !current.effects.contains(e))
            .collect();
        if remaining.is_empty() {
            break;
        }
        let Some((best, next)) = stage.forward_step(&current, &remaining) else {
            break;
        };
        joined.push(Joined::from(&best));
        cache.push(next.clone());
        current = next;
        // The set changed: the forms of its members are chosen again, and
        // the fits made in the old forms are forgotten.
        if let Some((refit, changed)) = stage.rechoose_forms(&current) {
            cache.retain(|s| !s.effects.iter().any(|e| changed.contains(e)));
            for j in joined.iter_mut().filter(|j| changed.contains(&j.effect)) {
                let name = stage.forms.get(&j.effect).map_or("", |f| f.1.as_str());
                j.evidence.push_str(&format!(
                    "; form chosen again once {{{}}} were in the set: {name}",
                    refit
                        .effects
                        .iter()
                        .filter(|e| **e != j.effect)
                        .map(|e| e.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            cache.push(refit.clone());
            current = refit;
        }
    }
    // Backward check: drop the weakest member that no longer earns its
    // place, until every one does.
    let mut dropped = Vec::new();
    let drops: Vec<Drop> = loop {
        let size = current.effects.len();
        let drops: Vec<Drop> = current
            .effects
            .par_iter()
            .filter_map(|&m| {
                let rest: Vec<Effect> = current
                    .effects
                    .iter()
                    .copied()
                    .filter(|e| *e != m)
                    .collect();
                let without = match cached(&cache, &rest) {
                    Some(s) => s.clone(),
                    None => stage.fit_set(&rest, &current)?,
                };
                let (earns, lr, gain) = stage.earns_place(&current, &without, size);
                Some((m, without, earns, lr, gain))
            })
            .collect();
        if size < 2 {
            break drops;
        }
        for d in &drops {
            if cached(&cache, &d.1.effects).is_none() {
                cache.push(d.1.clone());
            }
        }
        let weakest = drops
            .iter()
            .filter(|d| !d.2)
            .min_by(|a, b| a.4.total_cmp(&b.4));
        match weakest {
            None => break drops,
            Some(d) => {
                dropped.push(d.0);
                current = d.1.clone();
            }
        }
    };
    // Marginal shares in the order of selection: the prefixes of the set.
    let ms_base = stage.mean_square(base.fitted.sse);
    let s2 = stage.sigma * stage.sigma;
    let excess = ms_base - s2;
    let share = |drop_ms: f64| (excess > 0.0).then(|| drop_ms / excess);
    let prefixes: Vec<Option<SetFit>> = (1..=current.effects.len())
        .map(|k| {
            let effects = &current.effects[..k];
            match cached(&cache, effects) {
                Some(s) => Some(s.clone()),
                None => stage.fit_set(effects, &current),
            }
        })
        .collect();
    let final_names = &current.names;
    let final_theta = &current.fitted.theta;
    let mut all: BTreeMap<String, f64> = final_names
        .iter()
        .cloned()
        .zip(final_theta.iter().copied())
        .collect();
    let mut errors: BTreeMap<String, Option<f64>> = final_names
        .iter()
        .map(|n| (n.clone(), current.fitted.report.standard_error(n)))
        .collect();
    if let Some(model) = &current.model {
        let specs = &model.space().params;
        canonical_prony(&mut all, specs, final_theta);
        canonical_prony(&mut errors, specs, final_theta);
    }
    let mut before_ms = ms_base;
    let mut members = Vec::new();
    for (k, &effect) in current.effects.iter().enumerate() {
        let own = stage.own_names(effect);
        let (ms_after, misfit_after, heldout_after) = match &prefixes[k] {
            Some(p) => (
                stage.mean_square(p.fitted.sse),
                rms(&residuals(stage.observed, &p.fitted.predicted)),
                rms(&residuals(stage.observed, &p.cv)),
            ),
            None => (f64::NAN, f64::NAN, f64::NAN),
        };
        let share_marginal = if ms_after.is_finite() {
            share(before_ms - ms_after)
        } else {
            None
        };
        before_ms = ms_after;
        let drop = drops.iter().find(|d| d.0 == effect);
        let j = joined.iter().find(|j| j.effect == effect);
        members.push(SetMember {
            effect,
            form: stage.forms.get(&effect).map(|(_, n)| n.clone()),
            params: own
                .iter()
                .filter_map(|n| all.get(n).map(|v| (n.clone(), *v)))
                .collect(),
            standard_errors: own
                .iter()
                .filter_map(|n| errors.get(n).map(|v| (n.clone(), *v)))
                .collect(),
            share_marginal,
            share_dropped: drop.and_then(|d| {
                share(stage.mean_square(d.1.fitted.sse) - stage.mean_square(current.fitted.sse))
            }),
            misfit_after,
            heldout_after,
            lr_statistic: j.map_or(f64::NAN, |j| j.lr_statistic),
            lr_p: j.map_or(f64::NAN, |j| j.lr_p),
            heldout_gain: j.map_or(f64::NAN, |j| j.heldout_gain),
            dropped_lr: drop.filter(|_| current.effects.len() > 1).map(|d| d.3),
            dropped_heldout_gain: drop.filter(|_| current.effects.len() > 1).map(|d| d.4),
            confounded_with: j.map(|j| j.confounded_with.clone()).unwrap_or_default(),
            evidence: j.map(|j| j.evidence.clone()).unwrap_or_default(),
        });
    }
    let remainder = remainder(stage, &current, ms_base, offered);
    Explanation {
        members,
        remainder,
        dropped,
        predicted: current.fitted.predicted.clone(),
    }
}

/// The remainder of the base fit alone (a verdict of `none`).
pub(crate) fn remainder_of_base(
    stage: &Stage<'_>,
    base_full: &Fitted,
    base_cv: &[f64],
    offered: &[Effect],
) -> Remainder {
    let base = SetFit {
        effects: Vec::new(),
        model: None,
        names: stage.base.space().names(),
        fitted: base_full.clone(),
        cv: base_cv.to_vec(),
    };
    remainder(stage, &base, stage.mean_square(base_full.sse), offered)
}

/// Above this RMS misfit / noise, a structured remainder is called large:
/// the base model family may be wrong.
pub(crate) const LARGE_REMAINDER: f64 = 3.0;

/// How large the remainder of `set` is, where it lies, and what it may mean.
fn remainder(stage: &Stage<'_>, set: &SetFit, ms_base: f64, offered: &[Effect]) -> Remainder {
    let r = residuals(stage.observed, &set.fitted.predicted);
    let p = set.names.len();
    let tests = whiteness(&r, p, stage.sigma, stage.rel_var_sd2);
    let windows = significant_windows(
        &r,
        stage.axis_name,
        stage.x,
        stage.sigma,
        stage.window,
        stage.alpha,
    );
    let consistent = stage.consistent(&r, p);
    let s2 = stage.sigma * stage.sigma;
    let ms = stage.mean_square(set.fitted.sse);
    let share_unexplained = (ms_base > s2).then(|| ((ms - s2) / (ms_base - s2)).clamp(0.0, 1.0));
    let misfit = rms(&r);
    let over = misfit / stage.sigma;
    let what = if set.effects.is_empty() {
        "The base model".to_string()
    } else {
        let names: Vec<&str> = set.effects.iter().map(|e| e.name()).collect();
        format!("The set {{{}}}", names.join(", "))
    };
    let mut note = if consistent {
        format!(
            "{what} leaves a misfit of {over:.2} x noise, consistent with the noise (misfit p = {:.2}, runs p = {:.2}, lag-1 p = {:.2}, no window).",
            tests.misfit_p, tests.runs_p, tests.lag1_p
        )
    } else {
        let share = share_unexplained
            .map(|s| format!(", {:.0} % of the excess misfit", 100.0 * s))
            .unwrap_or_default();
        format!(
            "{what} leaves a misfit of {over:.2} x noise{share}, not noise: misfit p = {:.1e}, {} runs for {:.0} expected (p = {:.1e}), lag-1 autocorrelation {:.2} (p = {:.1e}).",
            tests.misfit_p, tests.runs, tests.runs_expected, tests.runs_p, tests.lag1_autocorrelation, tests.lag1_p
        )
    };
    if !windows.is_empty() {
        let shown: Vec<String> = windows
            .iter()
            .take(4)
            .map(|w| {
                format!(
                    "{} {:.3} .. {:.3} (model {} the data, mean residual {:+.2e}, RMS {:.2e})",
                    w.axis,
                    w.from,
                    w.to,
                    if w.mean_residual > 0.0 {
                        "below"
                    } else {
                        "above"
                    },
                    w.mean_residual,
                    w.misfit_rms
                )
            })
            .collect();
        note.push_str(&format!(
            " It lies in {} window(s): {}{}.",
            windows.len(),
            shown.join("; "),
            if windows.len() > 4 { "; ..." } else { "" }
        ));
    }
    if !consistent && over > LARGE_REMAINDER {
        let tried: Vec<&str> = offered.iter().map(|e| e.name()).collect();
        let untried: Vec<&str> = Effect::ALL
            .iter()
            .filter(|e| !offered.contains(e))
            .map(|e| e.name())
            .collect();
        note.push_str(&format!(
            " The remainder is large (over {LARGE_REMAINDER} x noise) and structured: the base model family may be wrong, \
             or the cause is not among the candidates tried ({}){}. What the members remove is what these candidates \
             can shape, not a measure of the cause.",
            if tried.is_empty() { "none".to_string() } else { tried.join(", ") },
            if untried.is_empty() {
                String::new()
            } else {
                format!("; not among them: {}", untried.join(", "))
            }
        ));
    }
    Remainder {
        misfit,
        heldout: rms(&residuals(stage.observed, &set.cv)),
        misfit_over_noise: over,
        share_unexplained,
        consistent_with_noise: consistent,
        tests,
        where_: windows,
        note,
    }
}
