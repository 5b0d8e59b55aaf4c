//! What the experiment allows an effect's parameters to be: an offset of
//! the recorded zero cannot put the unloaded state where the record
//! carries load.
//!
//! A zero offset d0 moves the unloaded state of the model (drive 0 for a
//! tool, stretch 1 for a homogeneous test) to the recorded drive u0 + d0.
//! Where the record shows no load (|y| within max(3 sigma, 2 % of the peak
//! |y|) of zero), the unloaded state is there or nearby; a record that
//! starts unloaded at its recorded zero and loads within a fraction of its
//! range does not allow the unloaded state anywhere else. Left free, the
//! offset of a dense smooth record (tiny noise, so every misfit is
//! significant) can buy a better fit of the loaded branch with an unloaded
//! state the record contradicts (a stretch offset of 0.14, 4 mm on a 30 mm
//! specimen whose load is zero at zero compression). The permitted range is
//! the span of the unloaded samples' drives widened by 2 % of the drive
//! range (the response of a soft contact rises slowly and stays below the
//! threshold for a while) and always holding d0 = 0, the base model.
//!
//! Only the first loading counts (the samples up to the end of the first
//! phase over which the drive moves): once loaded, a history-dependent
//! material (relaxation, an asymmetry) unloads through zero load away
//! from its unloaded state (a relaxed specimen carries compression on the
//! way back to its recorded zero), so a zero load met later says nothing
//! about where the unloaded state is. A record that starts loaded has its
//! unloaded state before its start: the offset is free on that side and
//! held at 0 on the other.

use super::crossval::phases;
use palpate_core::{Drive, Loading, ParamRole, ParamSpec};
use std::collections::BTreeMap;

/// Share of the peak |response| below which a sample counts as unloaded.
const UNLOADED_SHARE: f64 = 0.02;
/// Share of the drive range the permitted span is widened by on each side.
const SLACK_SHARE: f64 = 0.02;

/// The range of a zero offset (drive units) the record permits, or `None`
/// when it has no unloaded sample or its drive has no unloaded value (a
/// position along a path).
pub(crate) fn offset_range(loading: &Loading, observed: &[f64], sigma: f64) -> Option<(f64, f64)> {
    let u0 = match loading.drive_kind {
        Drive::DisplacementMm => 0.0,
        Drive::Stretch => 1.0,
        Drive::AmountOfShear => 0.0,
        Drive::PositionMm => return None,
    };
    let drive = &loading.drive;
    if drive.is_empty() || observed.len() != drive.len() {
        return None;
    }
    let peak = observed.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let threshold = (3.0 * sigma).max(UNLOADED_SHARE * peak);
    let (dmin, dmax) = drive
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &d| {
            (a.min(d), b.max(d))
        });
    // the first loading: up to the end of the first phase that moves
    let first = phases(drive)
        .into_iter()
        .find(|&(a, b)| (drive[b - 1] - drive[a]).abs() > 1e-9 * (dmax - dmin))
        .map_or(drive.len(), |(_, b)| b);
    let (lo, hi) = drive[..first]
        .iter()
        .zip(observed)
        .filter(|(_, y)| y.abs() <= threshold)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (&d, _)| {
            (a.min(d), b.max(d))
        });
    let slack = SLACK_SHARE * (dmax - dmin);
    if lo.is_finite() && hi.is_finite() {
        return Some(((lo - slack - u0).min(0.0), (hi + slack - u0).max(0.0)));
    }
    // loaded from the start: the unloaded state lies before it, on the
    // side the loading moves away from
    let start = drive[0] - u0;
    match drive[first - 1].partial_cmp(&drive[0]) {
        Some(std::cmp::Ordering::Greater) => Some((f64::NEG_INFINITY, start.max(0.0))),
        Some(std::cmp::Ordering::Less) => Some((start.min(0.0), f64::INFINITY)),
        _ => None,
    }
}

/// `specs` with every zero offset ([`ParamRole::Offset`]) held within
/// `range` (intersected with its own bounds; its start moved inside).
/// Returns whether a bound moved.
pub(crate) fn bound_offsets(specs: &mut [ParamSpec], range: Option<(f64, f64)>) -> bool {
    let Some((lo, hi)) = range else {
        return false;
    };
    let mut moved = false;
    for s in specs.iter_mut().filter(|s| s.role == ParamRole::Offset) {
        let (l, u) = (s.lower.max(lo), s.upper.min(hi));
        if l < u && (l > s.lower || u < s.upper) {
            s.lower = l;
            s.upper = u;
            s.initial = s.initial.clamp(l, u);
            moved = true;
        }
    }
    moved
}

/// Relaxation weights summing to at least this leave no equilibrium
/// stiffness: total relaxation, the simplex's bound.
const TOTAL_RELAXATION: f64 = 1.0 - 1e-4;
/// A Prony term whose time constant is below this share of the shortest
/// sample interval relaxes between two samples (a copy of the modulus).
const FASTEST_RESOLVED: f64 = 0.1;
/// A relaxation weight below this does nothing the record can show; a
/// term that relaxes less than this share of the modulus within the record,
/// `g (1 - exp(-T / tau))` over its duration T, is too slow to show (a copy
/// of the modulus). A slow term with a large weight that does relax a
/// share within the record (a softening during loading that a series
/// spring could also give) is not degenerate: its g / tau is what the
/// record determines.
const NEGLIGIBLE_WEIGHT: f64 = 1e-3;

/// Why the fitted own parameters of an effect (`theta[p..]`, `specs[p..]`)
/// are a degenerate member the record cannot support, or `None`: a
/// weighted Prony term whose time constant the record cannot resolve (so
/// slow that it relaxes under [`NEGLIGIBLE_WEIGHT`] of the modulus within
/// the record, or under [`FASTEST_RESOLVED`] of the shortest sample
/// interval); the reason also says when the weights sum to 1 (total
/// relaxation, their bound). Such a fit buys its misfit reduction by
/// trading the modulus for a relaxation that never shows in the record; it
/// is reported and earns nothing.
pub(crate) fn degenerate(
    specs: &[ParamSpec],
    theta: &[f64],
    p: usize,
    loading: &Loading,
) -> Option<String> {
    let mut weights: BTreeMap<usize, (String, f64)> = BTreeMap::new();
    let mut taus: BTreeMap<usize, (String, f64)> = BTreeMap::new();
    for (s, &v) in specs.iter().zip(theta).skip(p) {
        match s.role {
            ParamRole::RelaxationWeight { term } => {
                weights.insert(term, (s.name.clone(), v));
            }
            ParamRole::TimeConstant { term } => {
                taus.insert(term, (s.name.clone(), v));
            }
            _ => {}
        }
    }
    if weights.is_empty() {
        return None;
    }
    let mut why = Vec::new();
    let total: f64 = weights.values().map(|(_, g)| g).sum();
    let total_note = (total >= TOTAL_RELAXATION).then(|| {
        format!("relaxation weights sum to {total:.4} (total relaxation, no equilibrium stiffness: their bound)")
    });
    if let Some(t) = loading.time.as_ref().filter(|t| t.len() > 1) {
        let duration = t[t.len() - 1] - t[0];
        let dt_min = t
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|d| *d > 0.0)
            .fold(f64::INFINITY, f64::min);
        for (term, (g_name, g)) in &weights {
            let Some((t_name, tau)) = taus.get(term) else {
                continue;
            };
            if *g < NEGLIGIBLE_WEIGHT {
                continue;
            }
            let relaxed = g * (1.0 - (-duration / tau).exp());
            if duration > 0.0 && relaxed < NEGLIGIBLE_WEIGHT {
                why.push(format!(
                    "{g_name} = {g:.4} with {t_name} = {tau:.3e} s relaxes {relaxed:.1e} of the modulus over the record's {duration:.3e} s: it relaxes nothing within the record"
                ));
            } else if dt_min.is_finite() && *tau < FASTEST_RESOLVED * dt_min {
                why.push(format!(
                    "{g_name} = {g:.4} with {t_name} = {tau:.3e} s, under {FASTEST_RESOLVED} of the shortest sample interval ({dt_min:.3e} s): it relaxes between samples"
                ));
            }
        }
    }
    // total relaxation alone is a bound, not a degenerate fit: over a short
    // record a fully relaxing term still shapes the curve (and may be
    // confounded with another effect); it is named with an unresolved term
    if why.is_empty() {
        return None;
    }
    why.extend(total_note);
    Some(why.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_unloaded_at_its_zero_permits_a_small_offset_only() {
        // Compression in stretch from 1 to 0.7, zero stress at the start,
        // loaded from 0.99 on.
        let s: Vec<f64> = (0..=300).map(|i| 1.0 - 0.001 * i as f64).collect();
        let y: Vec<f64> = s
            .iter()
            .map(|&l| if l > 0.99 { 0.0 } else { -(0.99 - l) })
            .collect();
        let loading = Loading::quasi_static(Drive::Stretch, s);
        let (lo, hi) = offset_range(&loading, &y, 1e-5).unwrap();
        // unloaded down to stretch ~0.984 (2 % of the peak), widened by 0.006
        assert!(lo < -0.015 && lo > -0.03, "{lo}");
        assert!((0.0..0.01).contains(&hi), "{hi}");
        let mut specs =
            vec![ParamSpec::new("d0_stretch", "1", -0.5, 0.5, 0.0).with_role(ParamRole::Offset)];
        assert!(bound_offsets(&mut specs, Some((lo, hi))));
        assert_eq!((specs[0].lower, specs[0].upper), (lo, hi));
        // a record that is loaded everywhere, its drive falling from the
        // start: the unloaded state lies above its start, anywhere there
        let loaded = vec![1.0; 301];
        assert_eq!(
            offset_range(&loading, &loaded, 1e-3),
            Some((0.0, f64::INFINITY))
        );
    }

    #[test]
    fn only_the_first_loading_locates_the_unloaded_state() {
        // Tension from stretch 1 to 1.4 and back, loaded at the start (the
        // unloaded state lies below stretch 1), crossing zero load on the
        // way back at 1.04 as a relaxed specimen does.
        let mut s: Vec<f64> = (0..=200).map(|i| 1.0 + 0.002 * i as f64).collect();
        s.extend((1..=200).map(|i| 1.4 - 0.002 * i as f64));
        let y: Vec<f64> = s
            .iter()
            .enumerate()
            .map(|(i, &l)| if i <= 200 { l - 0.975 } else { l - 1.04 })
            .collect();
        let loading = Loading::quasi_static(Drive::Stretch, s);
        // the zero load at 1.04 on the way back does not count: below the
        // start anything, above it nothing
        assert_eq!(
            offset_range(&loading, &y, 1e-4),
            Some((f64::NEG_INFINITY, 0.0))
        );
        // unloaded at the start: the same record permits a small range
        // around its first zero load only
        let y0: Vec<f64> = y.iter().map(|v| v - 0.025).collect();
        let (lo, hi) = offset_range(&loading, &y0, 1e-4).unwrap();
        assert!(lo <= 0.0 && lo > -0.02, "{lo}");
        assert!((0.0..0.03).contains(&hi), "{hi}");
    }

    fn prony_specs() -> Vec<ParamSpec> {
        vec![
            ParamSpec::new("C10", "MPa", 0.0, f64::INFINITY, 1.0).with_role(ParamRole::Modulus),
            ParamSpec::new("g1", "1", 0.0, 1.0, 0.1)
                .with_role(ParamRole::RelaxationWeight { term: 1 }),
            ParamSpec::new("tau1_s", "s", 0.0, f64::INFINITY, 1.0)
                .with_role(ParamRole::TimeConstant { term: 1 }),
        ]
    }

    #[test]
    fn a_prony_member_on_its_bound_or_unresolved_is_degenerate() {
        // 100 s sampled every 0.1 s
        let t: Vec<f64> = (0..=1000).map(|i| 0.1 * i as f64).collect();
        let loading = Loading::timed(Drive::DisplacementMm, t.clone(), t);
        let specs = prony_specs();
        // a relaxation the record resolves
        assert_eq!(degenerate(&specs, &[1.0, 0.3, 5.0], 1, &loading), None);
        // the phantom's member: total relaxation with tau = 8.9e47 s
        let why = degenerate(&specs, &[1.0, 1.0, 8.9e47], 1, &loading).unwrap();
        assert!(
            why.contains("total relaxation") && why.contains("relaxes nothing"),
            "{why}"
        );
        // each condition alone
        assert!(degenerate(&specs, &[1.0, 0.3, 1e6], 1, &loading)
            .unwrap()
            .contains("tau1_s"));
        // slow, but relaxing 1.5 % of the modulus within the record
        assert_eq!(degenerate(&specs, &[1.0, 0.3, 2e3], 1, &loading), None);
        assert!(degenerate(&specs, &[1.0, 0.3, 1e-3], 1, &loading)
            .unwrap()
            .contains("between samples"));
        // total relaxation alone, resolved by the record, is not degenerate
        assert_eq!(degenerate(&specs, &[1.0, 1.0, 5.0], 1, &loading), None);
        // a negligible weight's time constant is not judged
        assert_eq!(degenerate(&specs, &[1.0, 1e-5, 1e60], 1, &loading), None);
        // the base's parameters are not the effect's
        assert_eq!(degenerate(&specs, &[1.0, 1.0, 8.9e47], 3, &loading), None);
    }
}
