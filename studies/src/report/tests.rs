use super::*;
use crate::model::calibration::{calibrate, parse_method, Request};
use crate::records::TestData;
use palpate_material::Law;
use std::path::Path;

fn treloar(name: &str, file: &str, test: &str) -> TestData {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/treloar")
        .join(file);
    TestData::read(name, TestKind::parse(test).unwrap(), &path).unwrap()
}

/// Treloar's three modes.
fn modes() -> Vec<TestData> {
    vec![
        treloar("uniaxial", "uniaxial.csv", "uniaxial"),
        treloar("biaxial", "biaxial.csv", "biaxial"),
        treloar("planar", "pure_shear.csv", "planar"),
    ]
}

/// `law` fitted to Treloar's uniaxial data (absolute residuals), predicting all three modes.
fn uniaxial_fit(law: &str) -> Calibration {
    let all = modes();
    calibrate(Request {
        law: law.parse::<Law>().unwrap(),
        model: None,
        fitted: &all[..1],
        predict: &all,
        residual: ResidualKind::Absolute,
        method: parse_method("lm").unwrap(),
        fixed: vec![],
        observer: None,
        viscous: None,
    })
    .unwrap()
}

/// Every number in `text` (tokens of digits, `.`, `e`, signs).
fn numbers(text: &str) -> Vec<f64> {
    text.split(|c: char| !(c.is_ascii_digit() || "+-.eE".contains(c)))
        .filter_map(|t| t.trim_start_matches(['e', 'E']).parse::<f64>().ok())
        .collect()
}

/// The header rows of the markdown tables in `md`.
fn headers(md: &str) -> Vec<Vec<String>> {
    let lines: Vec<&str> = md.lines().collect();
    lines
        .windows(2)
        .filter(|w| w[1].starts_with("|---"))
        .map(|w| {
            w[0].trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

const UNITS: [&str; 6] = ["MPa", "N^2", "(N", "mm", "(s)", "dimensionless"];

#[test]
fn the_mooney_rivlin_uniaxial_treloar_fit_is_flagged_not_identifiable() {
    let c = uniaxial_fit("mooney-rivlin");
    // The fit ends on C10 + C01 > 0: zero initial shear modulus, and
    // the planar prediction is 2 (C10 + C01) (lambda - lambda^-3) = 0.
    assert!(c.fit.on_limit, "{:?}", c.fit.termination);
    assert!(
        c.degenerate
            .iter()
            .any(|d| d.contains("initial shear modulus"))
            && c.degenerate.iter().any(|d| d.contains("`planar`")),
        "{:?}",
        c.degenerate
    );
    let verdict = identifiable_text(&c);
    assert!(verdict.starts_with("no ("), "{verdict}");
    assert!(
        verdict.contains("admissibility limit of the law"),
        "{verdict}"
    );
    let row = fit_row("mr", "uniaxial", "absolute", &c);
    assert!(row.contains("| **no ("), "{row}");
    // No standard error beside a value held by the limit.
    assert!(!row.contains('±'), "{row}");
    let table = calibration_table(&c);
    assert!(table.contains("DEGENERATE OR HELD BY A LIMIT"), "{table}");
    let json = serde_json::to_value(&c).unwrap();
    assert_eq!(json["fit"]["on_limit"], true);
    assert!(json["degenerate"].as_array().is_some_and(|a| a.len() == 2));
}

#[test]
fn a_clean_fit_is_identifiable_and_carries_no_new_fields() {
    let c = uniaxial_fit("neo-hookean");
    assert!(c.degenerate.is_empty() && !c.fit.on_limit);
    assert_eq!(identifiable_text(&c), "yes");
    let json = serde_json::to_string(&c).unwrap();
    assert!(!json.contains("degenerate") && !json.contains("on_limit"));
}

#[test]
fn no_r2_below_minus_100_is_printed_as_a_number() {
    assert_eq!(r2_text(-9.6e41, 4), "< -100 (diverges)");
    assert_eq!(r2_text(-99.5, 1), "-99.5");
    assert_eq!(r2_text(0.98765, 3), "0.988");
    let mut c = uniaxial_fit("neo-hookean");
    // A prediction that diverges: 3e21 MPa at the last stretch.
    let p = &mut c.predictions[1];
    p.predicted = p
        .stretch_or_displacement
        .iter()
        .map(|l| l.powf(140.0))
        .collect();
    let (r2, rms) = crate::model::calibration::r2_rms(&p.observed, &p.predicted);
    (p.r2, p.rms) = (r2, rms);
    assert!(p.r2 < -1e30, "{}", p.r2);
    c.r2 = -9.6e41;
    let (row, cells) = (fit_row("nh", "uniaxial", "absolute", &c), r2_cells(&c));
    let rows = [(("nh", "uniaxial", "absolute"), row.as_str(), &cells[..])];
    let md = calibrate_tables("laws", "lm", &rows);
    let table = calibration_table(&c);
    for text in [&md, &table] {
        assert!(text.contains("< -100 (diverges)"), "{text}");
        // Every number in them is at least -100 (the floor itself is
        // said, a parameter's value is positive).
        let low: Vec<f64> = numbers(text).into_iter().filter(|v| *v < -100.0).collect();
        assert!(low.is_empty(), "{low:?} in {text}");
    }
    // The plot keeps the data's scale: no tick near 1e21, and a marker
    // where the prediction leaves the frame.
    let svg = fit_plot(&c).to_svg();
    assert!(svg.contains("off-frame") && svg.contains("leaves the frame"));
    let ticks: Vec<f64> = svg
        .lines()
        .filter(|l| l.contains(r#"font-size="11" text-anchor="end""#))
        .filter_map(|l| l.split('>').nth(1)?.split('<').next()?.parse().ok())
        .collect();
    assert!(
        !ticks.is_empty() && ticks.iter().all(|t| t.abs() < 100.0),
        "{ticks:?}"
    );
}

#[test]
fn every_table_header_of_a_calibration_report_carries_a_unit() {
    let fits = [uniaxial_fit("neo-hookean"), uniaxial_fit("mooney-rivlin")];
    let rows: Vec<(String, Vec<(String, String)>)> = fits
        .iter()
        .map(|c| (fit_row("m", "uniaxial", "absolute", c), r2_cells(c)))
        .collect();
    let rows: Vec<FitRow> = rows
        .iter()
        .map(|(r, cells)| (("m", "uniaxial", "absolute"), r.as_str(), &cells[..]))
        .collect();
    let md = calibrate_tables("laws", "lm", &rows);
    let hs = headers(&md);
    assert_eq!(hs.len(), 2, "{md}");
    let labels = ["model", "fitted to", "residual", "identifiable"];
    for h in &hs {
        for cell in h.iter().filter(|c| !labels.contains(&c.as_str())) {
            assert!(
                UNITS.iter().any(|u| cell.contains(u)),
                "header `{cell}` has no unit"
            );
        }
    }
    // The Drucker column says what it scanned.
    assert!(md.contains("scanned over [0.1, 10]"), "{md}");
    // The terminal table: its column headers and the summary line.
    let t = calibration_table(&fits[0]);
    assert!(t.contains("unit (of value and std. error)"), "{t}");
    assert!(
        t.contains("R^2 (dimensionless)") && t.contains("RMS (MPa)"),
        "{t}"
    );
    assert!(
        t.contains("MPa^2") && t.contains("scanned over [0.1, 10]"),
        "{t}"
    );
}

/// A uniaxial record of 1,200 timed samples, one way (a ramp), or
/// loaded and held (a relaxation).
fn timed(c: &Calibration, hold: bool) -> Calibration {
    let mut c = c.clone();
    let n = 1200;
    let stretch: Vec<f64> = (0..n)
        .map(|i| {
            let s = i as f64 / (n - 1) as f64;
            1.0 + if hold { s.min(0.3) } else { s }
        })
        .collect();
    let p = &mut c.predictions[0];
    p.time = Some((0..n).map(|i| 0.1 * i as f64).collect());
    p.predicted = stretch.iter().map(|l| 0.4 * (l - l.powi(-2))).collect();
    p.observed = p.predicted.iter().map(|v| v * 1.01).collect();
    p.stretch_or_displacement = stretch;
    c.predictions.truncate(1);
    c
}

#[test]
fn a_timed_ramp_is_plotted_against_its_stretch_with_thinned_data_and_residuals() {
    let c = uniaxial_fit("neo-hookean");
    let f = fit_plot(&timed(&c, false));
    assert_eq!(f.fit.x_label, "stretch (dimensionless)");
    assert_eq!(f.fit.y_label, "nominal stress (MPa)");
    let data = &f.fit.series[0];
    assert_eq!(data.style, Style::Markers);
    assert!(data.x.len() <= MAX_MARKERS + 1, "{} markers", data.x.len());
    // Data and fit are told apart: light markers, a line in full colour.
    let fit = &f.fit.series[1];
    assert_eq!(fit.style, Style::Line);
    assert_ne!(data.color, fit.color);
    assert_eq!(fit.x.len(), 1200);
    // The residual panel.
    assert_eq!(f.residuals.y_label, "residual (MPa)");
    assert!(f.to_svg().contains("residual = data - fit (MPa)"));
    // A relaxation (a hold) keeps time.
    let held = fit_plot(&timed(&c, true));
    assert_eq!(held.fit.x_label, "time (s)");
}

#[test]
fn the_diagnosis_plot_of_a_stress_record_is_labelled_in_mpa() {
    let all = modes();
    let d = &all[0];
    let spec = crate::model::record_spec(d, Law::NeoHookean, None);
    let model = crate::model::build(&spec).unwrap();
    let options = palpate_uq::gap::GapOptions {
        effects: Some(vec![]),
        ..Default::default()
    };
    let gap = palpate_uq::gap::diagnose(model.as_ref(), &d.loading, &d.observed, &options).unwrap();
    let svg = gap_svg(&gap, "uniaxial");
    assert!(svg.contains("nominal stress (MPa)") && svg.contains("residual (MPa)"));
    assert!(!svg.contains("(N)"), "a stress record labelled as a force");
    assert!(svg.contains("stretch (dimensionless)"));
    let summary = gap_summary(&gap);
    assert!(
        summary.contains("noise SD") && summary.contains(" MPa"),
        "{summary}"
    );
    assert!(gap.to_markdown().contains("MPa"));
    assert!(gap_table_header(&["MPa"]).contains("noise SD (MPa)"));
}
