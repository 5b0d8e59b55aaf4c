//! The plot of the modulus against a numeric factor.

use super::{MaterialModulus, RecordModulus, ReplicatesSummaryStep};
use crate::report::plot::{Plot, Series, PALETTE};
use std::collections::BTreeMap;

/// mu0 against the numeric factor `x`, one colour per combination of the
/// other factors: each record's fit (markers) and the mean-curve fit (line).
pub(super) fn modulus_plot(
    step: &ReplicatesSummaryStep,
    x: &str,
    law: &str,
    materials: &[MaterialModulus],
    records: &[RecordModulus],
) -> String {
    let group = |levels: &BTreeMap<String, String>| -> String {
        levels
            .iter()
            .filter(|(f, _)| f.as_str() != x)
            .map(|(f, l)| format!("{f} {l}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut groups: Vec<String> = materials.iter().map(|m| group(&m.levels)).collect();
    groups.dedup();
    let mut unique = Vec::new();
    for g in groups {
        if !unique.contains(&g) {
            unique.push(g);
        }
    }
    let value = |m: &MaterialModulus| m.levels[x].parse::<f64>().unwrap_or(f64::NAN);
    let mut plot = Plot::new(
        format!("initial shear modulus of {law} against {x}"),
        x.to_string(),
        "mu0 (kPa)",
    );
    for (k, g) in unique.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let mut line: Vec<(f64, f64)> = materials
            .iter()
            .filter(|m| &group(&m.levels) == g)
            .map(|m| (value(m), m.mean_curve_kpa))
            .collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (lx, ly): (Vec<f64>, Vec<f64>) = line.into_iter().unzip();
        let (px, py): (Vec<f64>, Vec<f64>) = records
            .iter()
            .filter_map(|r| {
                let m = materials.iter().find(|m| m.step == r.step)?;
                (&group(&m.levels) == g).then(|| (value(m), r.mu0_kpa))
            })
            .unzip();
        let name = if g.is_empty() {
            step.name.clone()
        } else {
            g.clone()
        };
        plot.push(Series::line(format!("{name}: mean curve"), &lx, &ly).color(color));
        plot.push(Series::markers(format!("{name}: each record"), &px, &py).color(color));
    }
    plot.to_svg()
}
