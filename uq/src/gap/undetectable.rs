//! What an effect the record cannot see would do to the base parameters:
//! the base model refitted with the effect held at each end of its
//! plausible range: undetectable does not mean harmless.
//!
//! A likelihood-ratio or cross-validation test that does not reject "off"
//! says the data are consistent with the effect being absent, not that it
//! is absent: over its plausible range the effect may be absorbed by the
//! base parameters (friction at a needle by a stiffer C10). Holding the
//! effect's parameter at the ends (lo, hi) of its plausible range
//! ([`palpate_core::ParamSpec::plausible`]) and refitting the base
//! parameters gives the range of base estimates the record cannot
//! discriminate between: a sensitivity analysis of the estimate to an
//! unidentified nuisance parameter (in the spirit of the "partial
//! identification" bounds of Manski 2003 and of the omitted-variable
//! sensitivity analyses of Rosenbaum 2002). The misfit at each end says
//! whether the data would reject that end (its likelihood ratio against the
//! base fit, (SSE_end - SSE_base) / sigma^2).

use super::assess::Assessed;
use super::fit::{fit_from_starts, scale_moduli};
use super::residual::rms;
use super::structure::chi2_sf;
use super::GapError;
use palpate_core::{Effect, Loading};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One undetected effect held at the ends of its plausible range.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Undetectable {
    pub effect: Effect,
    /// The effect's parameter held fixed.
    pub param: String,
    /// Its plausible range, [lo, hi], the two values tried.
    pub range: [f64; 2],
    /// Each base parameter's fitted value with the effect at lo and at hi.
    pub base_params: BTreeMap<String, [f64; 2]>,
    /// Relative change of each base parameter between the two ends,
    /// (at hi - at lo) / |at lo|.
    pub relative_shift: BTreeMap<String, f64>,
    /// RMS misfit of the refit at each end (data unit).
    pub misfit: [f64; 2],
    /// p-value of the likelihood ratio of each end against the base fit
    /// (chi2 on 1 dof): near 1, the data cannot reject that end.
    pub p_value: [f64; 2],
}

/// For every assessed effect not in `detected` (the verdict, the effects
/// confounded with it and the immaterial ones) that has parameters with a
/// plausible range: the base refitted at the ends.
#[allow(clippy::too_many_arguments)]
pub(crate) fn undetectable(
    assessed: &[Assessed],
    detected: &[Effect],
    loading: &Loading,
    observed: &[f64],
    p: usize,
    base_sse: f64,
    sigma: f64,
    expensive: bool,
) -> Vec<Undetectable> {
    let jobs: Vec<(usize, usize)> = assessed
        .iter()
        .enumerate()
        .filter(|(_, a)| !detected.contains(&a.ranked.effect))
        .flat_map(|(k, a)| {
            let specs = &a.model.space().params;
            (p..specs.len())
                .filter(|&j| specs[j].plausible.is_some())
                .map(move |j| (k, j))
                .collect::<Vec<_>>()
        })
        .collect();
    jobs.par_iter()
        .filter_map(|&(k, j)| {
            at_ends(
                &assessed[k],
                j,
                loading,
                observed,
                p,
                base_sse,
                sigma,
                expensive,
            )
            .ok()
        })
        .collect()
}

/// The base parameters refitted with parameter `j` of the enriched model
/// at each end of its plausible range (its other own parameters at "off").
#[allow(clippy::too_many_arguments)]
fn at_ends(
    a: &Assessed,
    j: usize,
    loading: &Loading,
    observed: &[f64],
    p: usize,
    base_sse: f64,
    sigma: f64,
    expensive: bool,
) -> Result<Undetectable, GapError> {
    let specs = &a.model.space().params;
    let (lo, hi) = specs[j].plausible.expect("filtered on a plausible range");
    let mut thetas = Vec::new();
    let mut misfits = [0.0; 2];
    let mut p_values = [0.0; 2];
    for (e, x) in [lo, hi].into_iter().enumerate() {
        let mut start = a.off.clone();
        start[j] = x;
        let fixed: Vec<(String, f64)> = (p..specs.len())
            .map(|k| (specs[k].name.clone(), start[k]))
            .collect();
        let mut starts = vec![start.clone()];
        if let Ok(f) = a.model.predict(&start, loading) {
            if let Some((_, scaled)) = scale_moduli(specs, &start, &f, observed) {
                starts.insert(0, scaled);
            }
        }
        if expensive {
            starts.truncate(1);
        }
        let fitted = fit_from_starts(
            &a.model, loading, observed, None, &starts, &fixed, expensive,
        )?;
        let r: Vec<f64> = observed
            .iter()
            .zip(&fitted.predicted)
            .map(|(y, f)| y - f)
            .collect();
        misfits[e] = rms(&r);
        let lr = ((fitted.sse - base_sse) / (sigma * sigma)).max(0.0);
        p_values[e] = chi2_sf(lr, 1.0);
        thetas.push(fitted.theta);
    }
    let names = a.model.space().names();
    let base_params = (0..p)
        .map(|k| (names[k].clone(), [thetas[0][k], thetas[1][k]]))
        .collect();
    let relative_shift = (0..p)
        .map(|k| {
            (
                names[k].clone(),
                (thetas[1][k] - thetas[0][k]) / thetas[0][k].abs(),
            )
        })
        .collect();
    Ok(Undetectable {
        effect: a.ranked.effect,
        param: specs[j].name.clone(),
        range: [lo, hi],
        base_params,
        relative_shift,
        misfit: misfits,
        p_value: p_values,
    })
}
