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

use palpate_core::{Drive, Loading, ParamRole, ParamSpec};

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
    let peak = observed.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let threshold = (3.0 * sigma).max(UNLOADED_SHARE * peak);
    let (lo, hi) = loading
        .drive
        .iter()
        .zip(observed)
        .filter(|(_, y)| y.abs() <= threshold)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (&d, _)| {
            (a.min(d), b.max(d))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let (dmin, dmax) = loading
        .drive
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &d| {
            (a.min(d), b.max(d))
        });
    let slack = SLACK_SHARE * (dmax - dmin);
    Some(((lo - slack - u0).min(0.0), (hi + slack - u0).max(0.0)))
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
        // a record that is loaded everywhere permits anything
        let loaded = vec![1.0; 301];
        assert!(offset_range(&loading, &loaded, 1e-3).is_none());
    }
}
