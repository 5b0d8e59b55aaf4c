//! Ranking of the assessed candidates: sensitivity overlap between effects,
//! order, confounding, and the profile-likelihood intervals of the leader.

use super::assess::Assessed;
use super::profile::profile_interval;
use super::score::sensitivity_overlap;
use super::structure::chi2_isf;
use palpate_core::{Effect, Loading};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Orders `assessed` best first and fills in overlap, confounding and the
/// leader's profile intervals (`p` base parameters, noise `sigma`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn rank(
    assessed: &mut Vec<Assessed>,
    loading: &Loading,
    observed: &[f64],
    p: usize,
    sigma: f64,
    confound_alpha: f64,
    expensive: bool,
) {
    // Local identifiability between effects: overlap of their sensitivity
    // directions at "off" once the base parameters are refitted.
    for a in 0..assessed.len() {
        let overlaps: BTreeMap<Effect, f64> = (0..assessed.len())
            .filter(|&b| b != a)
            .map(|b| {
                (
                    assessed[b].ranked.effect,
                    sensitivity_overlap(&assessed[a].projected, &assessed[b].projected),
                )
            })
            .collect();
        assessed[a].ranked.sensitivity_overlap = overlaps;
    }
    // Rank: effects that earn their parameters and matter first, then those
    // that earn them, then by the held-out (cross-validated) gain, which
    // charges every extra parameter through its prediction error rather than
    // through a fixed penalty; AR(1) BIC breaks ties.
    assessed.sort_by(|a, b| {
        let key = |x: &Assessed| {
            (
                x.ranked.earns && x.ranked.practical.material,
                x.ranked.earns,
            )
        };
        key(b)
            .cmp(&key(a))
            .then(b.ranked.heldout_gain.total_cmp(&a.ranked.heldout_gain))
            .then(a.ranked.delta_bic_ar1.total_cmp(&b.ranked.delta_bic_ar1))
    });

    // Confounding: two earning effects the data cannot tell apart, because
    // their fits (in sample) or their held-out predictions differ by less
    // than a chi2(1) quantile of the noise: the likelihood ratio between the
    // two enriched models is not decisive.
    let confound_threshold = chi2_isf(confound_alpha, 1.0);
    let sigma2 = sigma * sigma;
    for a in 0..assessed.len() {
        let mut with = Vec::new();
        for b in 0..assessed.len() {
            if a != b && assessed[a].ranked.earns && assessed[b].ranked.earns {
                let fit = (assessed[a].fitted.sse - assessed[b].fitted.sse).abs() / sigma2;
                let held_out =
                    (assessed[a].ranked.heldout_gain - assessed[b].ranked.heldout_gain).abs();
                if fit < confound_threshold || held_out < confound_threshold {
                    with.push(assessed[b].ranked.effect);
                }
            }
        }
        let ranked = &mut assessed[a].ranked;
        if !with.is_empty() {
            ranked.identifiable = false;
            let overlaps: Vec<String> = with
                .iter()
                .map(|e| {
                    format!(
                        "{e}: {:.3}",
                        ranked
                            .sensitivity_overlap
                            .get(e)
                            .copied()
                            .unwrap_or(f64::NAN)
                    )
                })
                .collect();
            let names: Vec<&str> = with.iter().map(|e| e.name()).collect();
            ranked.evidence.push_str(&format!(
                "; sensitivity overlap at off {}; the data cannot tell it apart from {} (fitted or \
                 held-out SSE difference below chi2(1) quantile {:.1} x noise^2)",
                overlaps.join(", "),
                names.join(", "),
                confound_threshold
            ));
        }
        ranked.confounded_with = with;
    }

    // Within the leading group of effects the held-out predictions cannot
    // separate, the likelihood on all the data decides the order (they stay
    // flagged as confounded).
    if let Some(first) = assessed.first() {
        if first.ranked.earns && !first.ranked.confounded_with.is_empty() {
            let group = first.ranked.confounded_with.clone();
            let material = first.ranked.practical.material;
            let lead = (0..assessed.len())
                .filter(|&k| {
                    k == 0
                        || (group.contains(&assessed[k].ranked.effect)
                            && assessed[k].ranked.practical.material == material)
                })
                .max_by(|&a, &b| {
                    assessed[a]
                        .ranked
                        .lr_statistic
                        .total_cmp(&assessed[b].ranked.lr_statistic)
                })
                .unwrap_or(0);
            let moved = assessed.remove(lead);
            assessed.insert(0, moved);
        }
    }
    // Identifiability of the leading effect's parameters by their profile
    // likelihood (its other parameters refitted at each point).
    if let Some(first) = assessed.first_mut() {
        if first.ranked.earns {
            let names = first.model.space().names();
            let own: Vec<usize> = (p..names.len()).collect();
            let (model, fitted) = (&first.model, &first.fitted);
            first.ranked.profile = own
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
            if !first.ranked.profile.is_empty() {
                let text: Vec<String> = first.ranked.profile.iter().map(|i| i.describe()).collect();
                first
                    .ranked
                    .evidence
                    .push_str(&format!("; {}", text.join(", ")));
            }
        }
    }
}
