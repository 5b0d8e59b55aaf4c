//! Text and plots shared by the commands and the study runner: a
//! calibration's table and its data against the fit with the residuals;
//! the gap diagnosis's terminal summary and two panels.
//!
//! What a user reads at a glance holds without the JSON beside it: every
//! column and axis says its unit, a fit held by a limit or degenerate says
//! so where it would otherwise read as identifiable, an R^2 below -100 is
//! said to diverge instead of printed, and a diverging prediction leaves
//! the plot's frame (marked) instead of stretching its axis.

pub mod anova;
pub mod plot;

use crate::model::calibration::{Calibration, Prediction};
use crate::records::TestKind;
use palpate_core::Observable;
use palpate_inverse::{BoundSide, ResidualKind};
use palpate_uq::gap::GapReport;
use palpate_uq::likelihood::{predictive_band, Posterior};
use palpate_uq::mcmc::Chains;
use plot::{grid_svg, thinned, Band, Plot, Series, Style};

/// R^2 below which a prediction is said to diverge rather than printed.
pub const R2_FLOOR: f64 = -100.0;

/// Where the Drucker stability scan looks ([`palpate_material::stability`]):
/// stretches of each mode from 1 out to these ends.
pub const DRUCKER_SCAN: (f64, f64) = (0.1, 10.0);

/// Data markers drawn per data set at most (the fit is a line over them).
const MAX_MARKERS: usize = 60;

/// An R^2 for reading: the number to `decimals` places down to
/// [`R2_FLOOR`], below it `< -100 (diverges)`, `n/a` when undefined.
pub fn r2_text(r2: f64, decimals: usize) -> String {
    if r2.is_nan() {
        "n/a".to_string()
    } else if r2 < R2_FLOOR {
        "< -100 (diverges)".to_string()
    } else {
        format!("{r2:.decimals$}")
    }
}

/// The unit of a record's observable: MPa for the homogeneous tests'
/// stresses, N for the benchmarks' forces.
pub fn data_unit(test: TestKind) -> &'static str {
    if test.is_homogeneous() {
        "MPa"
    } else {
        "N"
    }
}

/// A parameter unit for reading: `dimensionless` for `1` or none.
fn unit_text(unit: &str) -> &str {
    match unit {
        "" | "1" | "-" => "dimensionless",
        u => u,
    }
}

/// The unit of a calibration's SSE (and `rms`): the data's unit squared
/// for absolute residuals, dimensionless for relative and normalised ones.
fn sse_unit(c: &Calibration) -> String {
    match c.residual {
        ResidualKind::Absolute => format!("{}^2", fitted_unit(c)),
        _ => "dimensionless".to_string(),
    }
}

/// The unit of the fitted data (`MPa`, `N`, or `MPa, N` for a mixed fit).
fn fitted_unit(c: &Calibration) -> String {
    let mut units: Vec<&str> = Vec::new();
    for p in c.predictions.iter().filter(|p| p.fitted) {
        let u = data_unit(p.test);
        if !units.contains(&u) {
            units.push(u);
        }
    }
    if units.is_empty() {
        "MPa".to_string()
    } else {
        units.join(", ")
    }
}

/// Why the data alone do not determine a calibration although the Jacobian
/// says they do, one phrase each: the fit held by the law's admissibility
/// limit or a parameter's bound, a degenerate law. Empty for a clean fit.
pub fn doubts(c: &Calibration) -> Vec<String> {
    let mut out: Vec<String> = c
        .fit
        .constraints()
        .into_iter()
        .map(|t| t.replace("of the model", "of the law"))
        .collect();
    out.extend(c.degenerate.iter().cloned());
    out
}

/// The identifiability verdict for reading: `yes`, or `no` with why
/// (rank or correlation, a limit or bound holding the fit, degeneracy).
pub fn identifiable_text(c: &Calibration) -> String {
    let doubts = doubts(c);
    match (c.identifiable, doubts.is_empty()) {
        (true, true) => "yes".to_string(),
        (false, _) => {
            let mut why = vec![format!(
                "not determined: {}",
                c.fit.identifiability.involved.join(", ")
            )];
            why.extend(doubts);
            format!("no ({})", why.join("; "))
        }
        (true, false) => format!("no ({})", doubts.join("; ")),
    }
}

/// Whether a record's samples follow its deformation closely enough to
/// plot against it: the drive moves one way (back-steps under 1 % of its
/// span) and does not hold (under 10 % of the steps at rest). A
/// relaxation or a load-unload record is plotted against time instead.
fn follows_deformation(drive: &[f64]) -> bool {
    let (lo, hi) = drive
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let span = hi - lo;
    if !(span > 0.0 && span.is_finite()) {
        return false;
    }
    let sign = (drive[drive.len() - 1] - drive[0]).signum();
    let back: f64 = drive
        .windows(2)
        .map(|w| ((w[1] - w[0]) * sign).min(0.0).abs())
        .sum();
    let still = drive
        .windows(2)
        .filter(|w| (w[1] - w[0]).abs() <= 1e-9 * span)
        .count();
    back <= 0.01 * span && still * 10 <= drive.len()
}

/// The y range of a plot whose curves may diverge: `None` when every
/// curve stays within the data's range widened by half its span each way
/// (the plot then covers everything), else that widened range.
fn clip_to_data(observed: &[&[f64]], curves: &[&[f64]]) -> Option<(f64, f64)> {
    let finite = |v: &&f64| v.is_finite();
    let (lo, hi) = observed
        .iter()
        .flat_map(|o| o.iter())
        .filter(finite)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let pad = 0.5 * (hi - lo).max(1e-12 * hi.abs().max(lo.abs()).max(1e-300));
    let (lo, hi) = (lo - pad, hi + pad);
    let inside = curves
        .iter()
        .flat_map(|c| c.iter())
        .filter(finite)
        .all(|v| (lo..=hi).contains(v));
    (!inside).then_some((lo, hi))
}

/// A light tint of a `#rrggbb` colour (for data beneath a fit line).
fn tint(hex: &str) -> String {
    let c = |k: usize| u8::from_str_radix(&hex[k..k + 2], 16).unwrap_or(0);
    if hex.len() != 7 {
        return hex.to_string();
    }
    let mix = |v: u8| (f64::from(v) + 0.55 * (255.0 - f64::from(v))).round() as u8;
    format!("#{:02x}{:02x}{:02x}", mix(c(1)), mix(c(3)), mix(c(5)))
}

/// A calibration's figure: data (thinned, light markers) against the fit
/// (lines; dashed where predicted) above, the residuals below, both
/// against the deformation (stretch, amount of shear or displacement), or
/// against time for records that hold or reverse.
#[derive(Debug, Clone)]
pub struct FitFigure {
    pub title: String,
    pub fit: Plot,
    pub residuals: Plot,
}

impl FitFigure {
    /// The two panels as one SVG document.
    pub fn to_svg(&self) -> String {
        grid_svg(
            &[Some(self.fit.clone()), Some(self.residuals.clone())],
            1,
            &self.title,
        )
    }
}

/// The x values of a prediction on the figure's axis.
fn x_of(p: &Prediction, by_time: bool) -> &[f64] {
    match (&p.time, by_time) {
        (Some(t), true) => t,
        _ => &p.stretch_or_displacement,
    }
}

/// Data against the fitted law and the residuals, one colour per data set.
pub fn fit_plot(c: &Calibration) -> FitFigure {
    let homogeneous = c.predictions.iter().all(|p| p.test.is_homogeneous());
    // Timed records are plotted against time only when one of them holds
    // or reverses (a relaxation); a monotone ramp reads against its stretch.
    let by_time = c.predictions.iter().all(|p| p.time.is_some())
        && c.predictions
            .iter()
            .any(|p| !follows_deformation(&p.stretch_or_displacement));
    let shear = c
        .predictions
        .iter()
        .filter(|p| p.test == TestKind::SimpleShear)
        .count();
    let xl = if by_time {
        "time (s)"
    } else if !homogeneous {
        "displacement (mm)"
    } else if shear == c.predictions.len() {
        "amount of shear (dimensionless)"
    } else if shear > 0 {
        "stretch, or amount of shear (dimensionless)"
    } else {
        "stretch (dimensionless)"
    };
    let yl = if !homogeneous {
        "force (N)"
    } else if shear == c.predictions.len() {
        "nominal shear stress (MPa)"
    } else {
        "nominal stress (MPa)"
    };
    let unit = if homogeneous { "MPa" } else { "N" };
    let doubts = doubts(c);
    let mut plot = Plot::new(
        if doubts.is_empty() {
            "data (markers) and fit (lines)".to_string()
        } else {
            format!(
                "data (markers) and fit (lines): NOT IDENTIFIABLE, {}",
                if c.degenerate.is_empty() {
                    "held by a limit or bound"
                } else {
                    "degenerate"
                }
            )
        },
        xl,
        yl,
    );
    plot.width = 720.0;
    let mut res = Plot::new(
        format!("residual = data - fit ({unit})"),
        xl,
        format!("residual ({unit})"),
    );
    res.width = 720.0;
    res.height = 260.0;
    res.hlines = vec![0.0];
    const COLOURS: [&str; 6] = [
        "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b",
    ];
    let mut residuals = Vec::new();
    for (k, p) in c.predictions.iter().enumerate() {
        let col = COLOURS[k % COLOURS.len()];
        let x = x_of(p, by_time);
        let (tx, ty) = thinned(x, &p.observed, MAX_MARKERS);
        plot.push(Series::markers(format!("{} data", p.data), &tx, &ty).color(tint(col)));
        let y = &p.predicted;
        let label = format!(
            "{} {} (R^2 {})",
            p.data,
            if p.fitted { "fit" } else { "prediction" },
            r2_text(p.r2, 4)
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
        let r: Vec<f64> = p
            .observed
            .iter()
            .zip(&p.predicted)
            .map(|(o, f)| o - f)
            .collect();
        let (rx, ry) = thinned(x, &r, 2 * MAX_MARKERS);
        res.push(Series::markers(p.data.clone(), &rx, &ry).color(col));
        residuals.push(r);
    }
    let observed: Vec<&[f64]> = c.predictions.iter().map(|p| &p.observed[..]).collect();
    let predicted: Vec<&[f64]> = c.predictions.iter().map(|p| &p.predicted[..]).collect();
    plot.y_range = clip_to_data(&observed, &predicted);
    // Residuals beyond the data's own span are off the scale that matters.
    let span = observed
        .iter()
        .flat_map(|o| o.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let big = residuals
        .iter()
        .flatten()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if span > 0.0 && big > span {
        res.y_range = Some((-1.05 * span, 1.05 * span));
    }
    FitFigure {
        title: format!(
            "{} fitted to {} ({} residuals)",
            c.law,
            c.data.join(" + "),
            c.residual
        ),
        fit: plot,
        residuals: res,
    }
}

/// One row of a study's fit table ([`calibrate_tables`]).
pub fn fit_row(model: &str, group: &str, residual: &str, c: &Calibration) -> String {
    let params: Vec<String> = c
        .params
        .iter()
        .map(|(n, p)| {
            // A parameter the fit left on a bound of its range (e.g. an Ogden
            // exponent on ±OGDEN_ALPHA_BOUND) is said to be there.
            let bound = c
                .fit
                .parameters
                .iter()
                .find(|q| &q.name == n)
                .and_then(|q| q.at_bound)
                .map(|side| match side {
                    BoundSide::Lower => " (on its lower bound)".to_string(),
                    BoundSide::Upper => " (on its upper bound)".to_string(),
                })
                .unwrap_or_default();
            let unit = match unit_text(&p.unit) {
                "dimensionless" => String::new(),
                u => format!(" {u}"),
            };
            match p.standard_error {
                Some(se) if c.identifiable && doubts(c).is_empty() => {
                    format!("{n} = {:.5e} ± {:.2e}{unit}{bound}", p.value, se)
                }
                _ => format!("{n} = {:.5e}{unit}{bound}", p.value),
            }
        })
        .collect();
    let d = &c.drucker;
    let identifiable = match identifiable_text(c) {
        yes if yes == "yes" => yes,
        no => format!("**{no}**"),
    };
    format!(
        "| {} (`{}`) | {} | {} | {:.6e} {} | {} | {} | {} | [{:.2}, {:.2}] / [{:.2}, {:.2}] / [{:.2}, {:.2}] |",
        model,
        c.law,
        group,
        residual,
        c.sse,
        sse_unit(c),
        r2_text(c.r2, 5),
        identifiable,
        params.join("<br>"),
        d.uniaxial.lower,
        d.uniaxial.upper,
        d.biaxial.lower,
        d.biaxial.upper,
        d.planar.lower,
        d.planar.upper
    )
}

/// The R^2 cell of each data set of a fit ([`calibrate_tables`]): the
/// number, *italic* when predicted, `< -100 (diverges)` below -100.
pub fn r2_cells(c: &Calibration) -> Vec<(String, String)> {
    c.predictions
        .iter()
        .map(|p| {
            let r2 = r2_text(p.r2, 4);
            let cell = if p.fitted { r2 } else { format!("*{r2}*") };
            (p.data.clone(), cell)
        })
        .collect()
}

/// A fit in a study's tables: (model, group, residual), its row
/// ([`fit_row`]) and its R^2 cells ([`r2_cells`]).
pub type FitRow<'a> = ((&'a str, &'a str, &'a str), &'a str, &'a [(String, String)]);

/// A calibrate step's section of report.md: the fit table and the R^2 of
/// every fit on every data set.
pub fn calibrate_tables(step: &str, estimator: &str, fits: &[FitRow]) -> String {
    use std::fmt::Write;
    let mut r = String::new();
    let _ = writeln!(
        r,
        "## Calibration `{step}`
"
    );
    let _ = writeln!(r, "Estimator `{estimator}`. R^2 = 1 - SS_res/SS_tot on the fitted data; predictions of the other tests use the fitted parameters. Stresses are nominal, in MPa; forces in N. A fit is identifiable when the data determine every parameter at an interior minimum: one held by the law's admissibility limit or a bound, or whose law is degenerate there (initial shear modulus ~0, a test predicted as 0), is not.
");
    let (lo, hi) = DRUCKER_SCAN;
    let _ = writeln!(r, "| model | fitted to | residual | SSE (data unit^2: MPa^2 or N^2; relative, normalised: dimensionless) | R^2 of the fit (dimensionless) | identifiable | parameters (value ± std. error, unit; none: dimensionless) | Drucker-stable stretch (dimensionless; scanned over [{lo}, {hi}]): uniaxial / biaxial / planar |");
    let _ = writeln!(r, "|---|---|---|---|---|---|---|---|");
    for (_, row, _) in fits {
        let _ = writeln!(r, "{row}");
    }
    // The data sets in order of first appearance.
    let mut names: Vec<&String> = Vec::new();
    for (d, _) in fits.iter().flat_map(|(_, _, cells)| cells.iter()) {
        if !names.contains(&d) {
            names.push(d);
        }
    }
    let _ = writeln!(
        r,
        "\nR^2 on each data set (dimensionless; *italic*: predicted, not fitted; below -100: diverges):\n"
    );
    let header: Vec<String> = names
        .iter()
        .map(|n| format!("{n} R^2 (dimensionless)"))
        .collect();
    let _ = writeln!(
        r,
        "| model | fitted to | residual | {} |",
        header.join(" | ")
    );
    let _ = writeln!(r, "|---|---|---|{}", "---|".repeat(names.len()));
    for ((model, group, residual), _, cells) in fits {
        let row: Vec<&str> = names
            .iter()
            .map(|n| {
                cells
                    .iter()
                    .find(|(d, _)| d == *n)
                    .map(|(_, c)| c.as_str())
                    .unwrap_or("")
            })
            .collect();
        let _ = writeln!(
            r,
            "| {model} | {group} | {residual} | {} |",
            row.join(" | ")
        );
    }
    let _ = writeln!(
        r,
        "\nPlots: `plots/{step}-<model>-<group>-<residual>.svg` (data and fit against the deformation, residuals below).\n"
    );
    r
}

/// The header of a diagnose step's table, in the records' unit (`units`:
/// each record's, [`data_unit`]).
pub fn gap_table_header(units: &[&str]) -> String {
    let mut u: Vec<&str> = Vec::new();
    for x in units {
        if !u.contains(x) {
            u.push(x);
        }
    }
    let u = if u.is_empty() {
        "N".to_string()
    } else {
        u.join(" or ")
    };
    format!(
        "| data | verdict | noise SD ({u}) | base misfit RMS ({u}) | best effect | misfit RMS after ({u}) | held-out RMS before / after ({u}) |\n|---|---|---|---|---|---|---|\n"
    )
}

/// The axis label of a gap diagnosis's horizontal axis (a column name).
fn axis_label(column: &str) -> String {
    match column {
        "time_s" => "time (s)".to_string(),
        "displacement_mm" => "displacement (mm)".to_string(),
        "position_mm" => "position (mm)".to_string(),
        "stretch" => "stretch (dimensionless)".to_string(),
        "amount_of_shear" => "amount of shear (dimensionless)".to_string(),
        other => other.to_string(),
    }
}

/// Two panels: data with base and enriched fits; residuals with the
/// discrepancy band and the flagged windows.
pub fn gap_svg(r: &GapReport, title: &str) -> String {
    let p = &r.plot;
    let windows: Vec<(f64, f64)> = r.where_.iter().map(|w| (w.from, w.to)).collect();
    // The observable follows from the record's drive (GapPlot::data_unit).
    let unit = p.data_unit();
    let observable = match unit {
        "MPa" => "nominal stress (MPa)",
        _ => "force (N)",
    };
    let axis = axis_label(&p.axis);
    let mut top = Plot::new("data and fits", &axis, observable);
    top.width = 760.0;
    top.windows = windows.clone();
    let (tx, ty) = thinned(&p.x, &p.observed, 2 * MAX_MARKERS);
    top.push(Series::markers("data", &tx, &ty).color("#999999"));
    top.push(Series::line("base fit", &p.x, &p.base_fit).color("#d62728"));
    if let (Some(e), Some(f)) = (&p.enriched_effect, &p.enriched_fit) {
        top.push(Series::line(format!("base + {e}"), &p.x, f).color("#2ca02c"));
    }
    let mut bottom = Plot::new(
        "residuals (flagged windows shaded)",
        &axis,
        format!("residual ({unit})"),
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
    let (rx, ry) = thinned(&p.x, &p.base_residual, 2 * MAX_MARKERS);
    bottom.push(Series::markers("base residual", &rx, &ry).color("#d62728"));
    if let (Some(e), Some(res)) = (&p.enriched_effect, &p.enriched_residual) {
        let (rx, ry) = thinned(&p.x, res, 2 * MAX_MARKERS);
        bottom.push(Series::markers(format!("base + {e} residual"), &rx, &ry).color("#2ca02c"));
    }
    grid_svg(
        &[Some(top), Some(bottom)],
        1,
        &format!("gap diagnosis of {title}: verdict {}", r.verdict),
    )
}

/// A readable table of a calibration, every quantity with its unit.
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
        "{:<10} {:>14} {:>14}  unit (of value and std. error)",
        "parameter", "value", "std. error"
    );
    for (name, p) in c.params.iter() {
        let se = match (p.fixed, p.standard_error) {
            (true, _) => "fixed".to_string(),
            (false, Some(e)) => format!("{e:.6e}"),
            (false, None) => "n/a".to_string(),
        };
        let _ = writeln!(
            s,
            "{:<10} {:>14.6e} {:>14}  {}",
            name,
            p.value,
            se,
            unit_text(&p.unit)
        );
    }
    let sse = sse_unit(c);
    let rms = match c.residual {
        ResidualKind::Absolute => fitted_unit(c),
        _ => "dimensionless".to_string(),
    };
    let doubts = doubts(c);
    let _ = writeln!(
        s,
        "R^2 {} (dimensionless)  RMS {:.4e} {rms}  SSE {:.6e} {sse}  iterations {}  evaluations {}  converged {}{}",
        r2_text(c.r2, 6),
        c.rms,
        c.sse,
        c.iterations,
        c.evaluations,
        c.converged,
        if doubts.is_empty() { "" } else { " (but see below)" }
    );
    if !c.identifiable {
        let _ = writeln!(
            s,
            "NOT IDENTIFIABLE from these data: {} (condition number {:.2e}); values above are one of many equally good fits",
            c.fit.identifiability.involved.join(", "),
            c.fit.identifiability.condition_number
        );
    }
    if !doubts.is_empty() {
        let _ = writeln!(
            s,
            "NOT IDENTIFIABLE, DEGENERATE OR HELD BY A LIMIT: {}; the standard errors assume an interior minimum and do not hold",
            doubts.join("; ")
        );
    }
    let d = &c.drucker;
    let (lo, hi) = DRUCKER_SCAN;
    let _ = writeln!(
        s,
        "Drucker-stable stretch ranges (dimensionless, scanned over [{lo}, {hi}]): uniaxial [{:.3}, {:.3}]  biaxial [{:.3}, {:.3}]  planar [{:.3}, {:.3}]",
        d.uniaxial.lower, d.uniaxial.upper, d.biaxial.lower, d.biaxial.upper, d.planar.lower, d.planar.upper
    );
    let units: Vec<&str> = c.predictions.iter().map(|p| data_unit(p.test)).collect();
    let one_unit = units.windows(2).all(|w| w[0] == w[1]);
    let _ = writeln!(
        s,
        "  {:<12} {:<10} {:>24} {}",
        "data set",
        "role",
        "R^2 (dimensionless)",
        match (one_unit, units.first()) {
            (true, Some(u)) => format!("RMS ({u})"),
            _ => "RMS (MPa or N, as given)".to_string(),
        }
    );
    for (p, u) in c.predictions.iter().zip(&units) {
        let _ = writeln!(
            s,
            "  {:<12} {:<10} {:>24} {:.4e}{}",
            p.data,
            if p.fitted { "fitted" } else { "predicted" },
            r2_text(p.r2, 5),
            p.rms,
            if one_unit {
                String::new()
            } else {
                format!(" {u}")
            }
        );
    }
    s
}

/// A few lines of a gap diagnosis for the terminal.
pub fn gap_summary(r: &GapReport) -> String {
    use std::fmt::Write;
    let unit = r.plot.data_unit();
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
        "noise SD {:.4e} {unit} (estimated from the data); base misfit RMS {:.4e} {unit}, held-out {:.4e} {unit}",
        r.noise_sd, r.base.misfit, r.base.heldout
    );
    for w in &r.where_ {
        let _ = writeln!(
            s,
            "  misfit window {} {:.3} .. {:.3}: RMS {:.4e} {unit}",
            w.axis, w.from, w.to, w.misfit_rms
        );
    }
    let _ = writeln!(
        s,
        "{:<18} {:>16} {:>16} {:>16} {:>16}  identifiable",
        "effect (RMS misfit)",
        format!("fit before ({unit})"),
        format!("after ({unit})"),
        format!("held-out ({unit})"),
        format!("after ({unit})")
    );
    for e in &r.ranking {
        let _ = writeln!(
            s,
            "{:<18} {:>16.4e} {:>16.4e} {:>16.4e} {:>16.4e}  {}",
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

/// Every `step`-th point of the chains (for scatter plots).
fn thinned_draws(x: &Chains, max_points: usize) -> Vec<&[f64]> {
    let total = x.n_chains * x.n_draws;
    let step = total.div_ceil(max_points.max(1)).max(1);
    x.points().step_by(step).collect()
}

fn histogram(v: &[f64], bins: usize) -> (Vec<f64>, Vec<f64>, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let w = ((hi - lo) / bins as f64).max(1e-300);
    let mut counts = vec![0.0; bins];
    for &x in v {
        let b = (((x - lo) / w) as usize).min(bins - 1);
        counts[b] += 1.0;
    }
    let centres = (0..bins).map(|b| lo + (b as f64 + 0.5) * w).collect();
    (centres, counts, w)
}

/// The plots of a posterior, as (file name, SVG): `corner.svg` (marginal
/// histograms and pairwise draws, each axis with its parameter's unit) and
/// `predictive_<data>.svg` per data set (the 94 % bands of the model and of
/// a new observation, the posterior median as a line, the data as thinned
/// light markers), against the deformation or, for a record that holds or
/// reverses, against time. `x`: the draws in physical units.
pub fn posterior_plots(
    post: &Posterior,
    x: &Chains,
    seed: u64,
) -> anyhow::Result<Vec<(String, String)>> {
    let names = post.names();
    let space = post.space();
    let label = |k: usize| {
        let unit = space.params.get(k).map_or("", |p| p.unit.as_str());
        format!("{} ({})", names[k], unit_text(unit))
    };
    let d = x.dim;
    let pts = thinned_draws(x, 2000);
    let mut cells = Vec::with_capacity(d * d);
    for i in 0..d {
        for j in 0..d {
            cells.push(if i == j {
                let v: Vec<f64> = x.points().map(|p| p[i]).collect();
                let (c, n, w) = histogram(&v, 40);
                let mut p = Plot::new(names[i].clone(), label(i), "draws (count)");
                p.push(Series::line(names[i].clone(), &c, &n).style(Style::Bars(w)));
                Some(p)
            } else if i > j {
                let xs: Vec<f64> = pts.iter().map(|p| p[j]).collect();
                let ys: Vec<f64> = pts.iter().map(|p| p[i]).collect();
                let mut p = Plot::new(format!("{} vs {}", names[i], names[j]), label(j), label(i));
                p.push(Series::markers("draws", &xs, &ys));
                Some(p)
            } else {
                None
            });
        }
    }
    let mut out = vec![("corner.svg".to_string(), grid_svg(&cells, d, "posterior"))];
    for (s, ds) in post.datasets().iter().enumerate() {
        let band = predictive_band(post, s, x, 400, 0.94, seed)?;
        let y_label = match ds.model.observable() {
            Observable::ForceN => "force (N)",
            Observable::NominalStressMPa => "nominal stress (MPa)",
        };
        let by_time = match &ds.loading.time {
            Some(_) => !follows_deformation(&ds.loading.drive),
            None => false,
        };
        let (xs, x_label) = match (&ds.loading.time, by_time) {
            (Some(t), true) => (t.clone(), "time (s)".to_string()),
            _ => (
                band.drive.clone(),
                axis_label(ds.loading.drive_kind.column()),
            ),
        };
        let mut p = Plot::new(
            format!("posterior predictive: {}", ds.name),
            x_label,
            y_label,
        );
        p.bands.push(Band {
            label: "94 % new observation".into(),
            x: xs.clone(),
            lower: band.lower_observed.clone(),
            upper: band.upper_observed.clone(),
            color: "#9ecae1".into(),
        });
        p.bands.push(Band {
            label: "94 % model".into(),
            x: xs.clone(),
            lower: band.lower.clone(),
            upper: band.upper.clone(),
            color: "#d62728".into(),
        });
        let (tx, ty) = thinned(&xs, &ds.observed, 2 * MAX_MARKERS);
        p.push(Series::markers("data", &tx, &ty).color("#777777"));
        p.push(Series::line("posterior median", &xs, &band.median).color("#d62728"));
        let file = format!(
            "predictive_{}.svg",
            ds.name.replace(|c: char| !c.is_ascii_alphanumeric(), "_")
        );
        out.push((file, p.to_svg()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests;
