//! Text and plots shared by the commands and the study runner: a
//! calibration's table and its data against the fit; the gap diagnosis's
//! terminal summary and two panels.

pub mod anova;
pub mod plot;

use crate::model::calibration::Calibration;
use crate::records::TestKind;
use palpate_uq::gap::GapReport;
use plot::{grid_svg, Band, Plot, Series};

/// Data (markers) against the fitted law (lines), one colour per data set.
pub fn fit_plot(c: &Calibration) -> Plot {
    let homogeneous = c.predictions.iter().all(|p| p.test.is_homogeneous());
    let timed = c.predictions.iter().all(|p| p.time.is_some());
    let shear = c
        .predictions
        .iter()
        .filter(|p| p.test == TestKind::SimpleShear)
        .count();
    let (xl, yl) = if !homogeneous {
        ("displacement (mm)", "force (N)")
    } else if timed {
        ("time (s)", "nominal stress (MPa)")
    } else if shear == c.predictions.len() {
        ("amount of shear", "nominal shear stress (MPa)")
    } else if shear > 0 {
        ("stretch, or amount of shear", "nominal stress (MPa)")
    } else {
        ("stretch", "nominal stress (MPa)")
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
        let x = match (&p.time, timed) {
            (Some(t), true) => t,
            _ => &p.stretch_or_displacement,
        };
        plot.push(Series::markers(format!("{} data", p.data), x, &p.observed).color(col));
        let y = &p.predicted;
        let label = format!(
            "{} {} (R^2 {:.4})",
            p.data,
            if p.fitted { "fit" } else { "prediction" },
            p.r2
        );
        // General biaxial: (lambda_a, P_a) pairs are not a curve; each predicted
        // point is drawn as a marker in the fit's colour, darker.
        plot.push(if p.test == TestKind::GeneralBiaxial {
            Series::markers(label, x, y).color("#000000")
        } else if p.fitted {
            Series::line(label, x, y).color(col)
        } else {
            Series::dashed(label, x, y).color(col)
        });
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

/// A readable table of a calibration.
pub fn calibration_table(c: &Calibration) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "law {} fitted to {} ({} residuals, {})",
        c.law,
        c.data.join(" + "),
        c.residual,
        c.estimator
    );
    let _ = writeln!(
        s,
        "{:<10} {:>14} {:>14} {:>8}",
        "parameter", "value", "std. error", "unit"
    );
    for (name, p) in c.params.iter() {
        let se = match (p.fixed, p.standard_error) {
            (true, _) => "fixed".to_string(),
            (false, Some(e)) => format!("{e:.6e}"),
            (false, None) => "n/a".to_string(),
        };
        let _ = writeln!(
            s,
            "{:<10} {:>14.6e} {:>14} {:>8}",
            name, p.value, se, p.unit
        );
    }
    let _ = writeln!(
        s,
        "R^2 {:.6}  RMS {:.4e}  SSE {:.6e}  iterations {}  evaluations {}  converged {}",
        c.r2, c.rms, c.sse, c.iterations, c.evaluations, c.converged
    );
    if !c.identifiable {
        let _ = writeln!(
            s,
            "NOT IDENTIFIABLE from these data: {} (condition number {:.2e}); values above are one of many equally good fits",
            c.fit.identifiability.involved.join(", "),
            c.fit.identifiability.condition_number
        );
    }
    let d = &c.drucker;
    let _ = writeln!(
        s,
        "Drucker stable stretch ranges: uniaxial [{:.3}, {:.3}]  biaxial [{:.3}, {:.3}]  planar [{:.3}, {:.3}]",
        d.uniaxial.lower, d.uniaxial.upper, d.biaxial.lower, d.biaxial.upper, d.planar.lower, d.planar.upper
    );
    for p in &c.predictions {
        let _ = writeln!(
            s,
            "  {:<12} {:<10} R^2 {:.5}  RMS {:.4e}",
            p.data,
            if p.fitted { "fitted" } else { "predicted" },
            p.r2,
            p.rms
        );
    }
    s
}

/// A few lines of a gap diagnosis for the terminal.
pub fn gap_summary(r: &GapReport) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(s, "verdict: {}", r.verdict);
    if !r.confounded.is_empty() {
        let names: Vec<&str> = r.confounded.iter().map(|e| e.name()).collect();
        let _ = writeln!(s, "cannot be told apart from: {}", names.join(", "));
    }
    if !r.immaterial.is_empty() {
        let names: Vec<&str> = r.immaterial.iter().map(|e| e.name()).collect();
        let _ = writeln!(s, "detectable but immaterial: {}", names.join(", "));
    }
    let _ = writeln!(
        s,
        "noise SD {:.4} (estimated from the data); base misfit RMS {:.4}, held-out {:.4}",
        r.noise_sd, r.base.misfit, r.base.heldout
    );
    for w in &r.where_ {
        let _ = writeln!(
            s,
            "  misfit window {} {:.3} .. {:.3}: RMS {:.4}",
            w.axis, w.from, w.to, w.misfit_rms
        );
    }
    let _ = writeln!(
        s,
        "{:<18} {:>10} {:>10} {:>10} {:>10}  identifiable",
        "effect", "fit before", "after", "held-out", "after"
    );
    for e in &r.ranking {
        let _ = writeln!(
            s,
            "{:<18} {:>10.4} {:>10.4} {:>10.4} {:>10.4}  {}",
            e.effect,
            e.misfit_before,
            e.misfit_after,
            e.heldout_before,
            e.heldout_after,
            e.identifiable
        );
    }
    for u in &r.undetectable {
        let moves: Vec<String> = u
            .base_params
            .iter()
            .map(|(k, v)| {
                format!(
                    "{k} {:.4e} .. {:.4e} ({:+.1} %)",
                    v[0],
                    v[1],
                    100.0 * u.relative_shift[k]
                )
            })
            .collect();
        let _ = writeln!(
            s,
            "not seen: {} with {} in [{}, {}] would move {}",
            u.effect,
            u.param,
            u.range[0],
            u.range[1],
            moves.join(", ")
        );
    }
    let _ = write!(s, "{}", r.explanation);
    s
}
