//! The tables of the fits beside the published ones and of the modulus
//! per material.

use super::{MaterialModulus, ReplicatesSummaryStep};
use crate::steps::replicates::sig4;
use std::collections::BTreeMap;
use std::fmt::Write;

pub(super) fn verdict_table(
    report: &mut String,
    laws: &[String],
    verdicts: &BTreeMap<String, BTreeMap<String, Vec<String>>>,
) {
    let columns = [
        "same",
        "lower SSE",
        "same SSE, other parameters",
        "higher SSE",
        "not in the table",
    ];
    let _ = writeln!(
        report,
        "Fits to the mean curves beside the published table, per law: how many materials give each verdict \
         (`same`: every parameter within 5e-4 relative and the SSE within 1e-4; `lower SSE`: palpate's optimum \
         is better on the same curve).\n"
    );
    let _ = writeln!(
        report,
        "| law | {} | materials with `higher SSE` |",
        columns.join(" | ")
    );
    let _ = writeln!(report, "|---|{}---|", "---|".repeat(columns.len()));
    for l in laws {
        let v = &verdicts[l];
        let counts: Vec<String> = columns
            .iter()
            .map(|c| v.get(*c).map(|s| s.len().to_string()).unwrap_or_default())
            .collect();
        let higher = v
            .get("higher SSE")
            .map(|s| s.join(", "))
            .unwrap_or_default();
        let _ = writeln!(report, "| {l} | {} | {higher} |", counts.join(" | "));
    }
}

pub(super) fn modulus_table(
    report: &mut String,
    step: &ReplicatesSummaryStep,
    law: &str,
    m: &[MaterialModulus],
) {
    let _ = writeln!(
        report,
        "\nInitial shear modulus mu0 of {law} (kPa): its fit to the mean curve, and the mean and SD of the \
         per-record fits.\n"
    );
    let f: Vec<&String> = step.factors.keys().collect();
    let _ = writeln!(
        report,
        "| material | {} | mean curve | per-record mean | per-record SD | records |",
        f.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(" | ")
    );
    let _ = writeln!(report, "|---|{}---|---|---|---|", "---|".repeat(f.len()));
    for x in m {
        let levels: Vec<&str> = f.iter().map(|k| x.levels[*k].as_str()).collect();
        let _ = writeln!(
            report,
            "| {} | {} | {} | {} | {} | {} |",
            x.step,
            levels.join(" | "),
            sig4(x.mean_curve_kpa),
            sig4(x.records_mean_kpa),
            sig4(x.records_sd_kpa),
            x.records
        );
    }
}
