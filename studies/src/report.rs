//! Plots shared by the commands and the study runner: a calibration's data
//! against its fit, and the gap diagnosis's two panels.

use crate::calibration::Calibration;
use crate::plot::{grid_svg, Band, Plot, Series};
use palpate_uq::gap::GapReport;

/// Data (markers) against the fitted law (lines), one colour per data set.
pub fn fit_plot(c: &Calibration) -> Plot {
    let homogeneous = c
        .predictions
        .iter()
        .all(|p| p.data != "C1" && p.data != "N1");
    let (xl, yl) = if homogeneous {
        ("stretch", "nominal stress (MPa)")
    } else {
        ("displacement (mm)", "force (N)")
    };
    let mut plot = Plot::new(
        format!(
            "{} fitted to {} ({} residuals)",
            c.law,
            c.data.join(" + "),
            c.residual
        ),
        xl,
        yl,
    );
    const COLOURS: [&str; 6] = [
        "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
    ];
    for (k, p) in c.predictions.iter().enumerate() {
        let col = COLOURS[k % COLOURS.len()];
        plot.push(
            Series::markers(
                format!("{} data", p.data),
                &p.stretch_or_displacement,
                &p.observed,
            )
            .color(col),
        );
        let (x, y) = (&p.stretch_or_displacement, &p.predicted);
        let label = format!(
            "{} {} (R^2 {:.4})",
            p.data,
            if p.fitted { "fit" } else { "prediction" },
            p.r2
        );
        plot.push(
            if p.fitted {
                Series::line(label, x, y)
            } else {
                Series::dashed(label, x, y)
            }
            .color(col),
        );
    }
    plot
}

/// Two panels: data with base and enriched fits; residuals with the
/// discrepancy band and the flagged windows.
pub fn gap_svg(r: &GapReport, title: &str) -> String {
    let p = &r.plot;
    let windows: Vec<(f64, f64)> = r.where_.iter().map(|w| (w.from, w.to)).collect();
    let mut top = Plot::new("data and fits", &p.axis, "force (N)");
    top.width = 760.0;
    top.windows = windows.clone();
    top.push(Series::markers("data", &p.x, &p.observed).color("#888888"));
    top.push(Series::line("base fit", &p.x, &p.base_fit).color("#d62728"));
    if let (Some(e), Some(f)) = (&p.enriched_effect, &p.enriched_fit) {
        top.push(Series::line(format!("base + {e}"), &p.x, f).color("#2ca02c"));
    }
    let mut bottom = Plot::new(
        "residuals (flagged windows shaded)",
        &p.axis,
        "residual (N)",
    );
    bottom.width = 760.0;
    bottom.windows = windows;
    bottom.hlines = vec![0.0];
    bottom.bands.push(Band {
        label: "running mean +- 2 sigma/sqrt(w)".into(),
        x: p.x.clone(),
        lower: p.band_lower.clone(),
        upper: p.band_upper.clone(),
        color: "#1f77b4".into(),
    });
    bottom.push(Series::markers("base residual", &p.x, &p.base_residual).color("#d62728"));
    if let (Some(e), Some(res)) = (&p.enriched_effect, &p.enriched_residual) {
        bottom.push(Series::markers(format!("base + {e} residual"), &p.x, res).color("#2ca02c"));
    }
    grid_svg(
        &[Some(top), Some(bottom)],
        1,
        &format!("gap diagnosis of {title}: verdict {}", r.verdict),
    )
}
