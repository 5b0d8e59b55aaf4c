//! The plot of a localisation: the record, the fit and the nodules, and
//! each nodule's posterior draws.

use super::posterior::LocRun;
use super::record::Record;
use super::LocModel;
use crate::report::plot::{grid_svg, Plot, Series};

/// Force against position with the fit and the nodules (posterior means,
/// with their 94 % x intervals), plus one cell per nodule with its (x,
/// depth) draws.
pub fn plot_svg(
    model: &LocModel,
    record: &Record,
    run: &LocRun,
    truth: Option<&[(f64, f64)]>,
) -> String {
    let mut main = Plot::new(
        format!("R2 record and fit, RD {} mm", model.rd),
        "wheel position x (mm)",
        "force (N)",
    )
    .with(Series::markers("record", &record.positions, &record.force))
    .with(Series::line(
        "posterior-mean fit",
        &record.positions,
        &run.fit,
    ));
    let lo = record.force.iter().cloned().fold(f64::INFINITY, f64::min);
    let xs: Vec<f64> = run.result.nodules.iter().map(|n| n.x_mm.mean).collect();
    main = main.with(Series::markers(
        "nodules (posterior mean x)",
        &xs,
        &vec![lo; xs.len()],
    ));
    for n in &run.result.nodules {
        main = main.with(Series::line("", &[n.x_mm.hdi_3, n.x_mm.hdi_97], &[lo, lo]));
    }
    if let Some(t) = truth {
        let tx: Vec<f64> = t.iter().map(|p| p.0).collect();
        main = main.with(Series::markers("true x", &tx, &vec![lo; tx.len()]));
    }
    let mut cells = vec![Some(main)];
    let n = run.result.nodules.len();
    for j in 0..n {
        let xd = run.chains.param(2 * j);
        let dd = run.chains.param(2 * j + 1);
        let flat_x: Vec<f64> = xd.iter().flatten().copied().collect();
        let flat_d: Vec<f64> = dd.iter().flatten().copied().collect();
        let stride = (flat_x.len() / 600).max(1);
        let px: Vec<f64> = flat_x.iter().step_by(stride).copied().collect();
        let pd: Vec<f64> = flat_d.iter().step_by(stride).copied().collect();
        let mut p = Plot::new(
            format!(
                "nodule {} posterior{}",
                j + 1,
                if run.result.nodules[j].identifiable {
                    ""
                } else {
                    " (depth NI)"
                }
            ),
            "x (mm)",
            "depth (mm)",
        )
        .with(Series::markers("draws", &px, &pd));
        if let Some(t) = truth.and_then(|t| t.get(j)) {
            p = p.with(Series::markers("truth", &[t.0], &[t.1]));
        }
        cells.push(Some(p));
    }
    grid_svg(&cells, 2, "R2 localisation")
}
