//! The silicone phantom between platens: a real compression record of the
//! phantom database (`studies/data/real/phantom_dawood2026/EF10_0T/EF10_0T_A1.csv`,
//! Ecoflex 00-10, a cylinder 50 mm across and 30 mm high, testing-machine
//! format) fitted by the homogeneous model and by the finite-element
//! cylinder between platens with friction 0, 0.3, bonded and fitted, all
//! through `palpate calibrate` as a user runs it; then the same cylinder
//! simulated at friction 0.3 and bonded against the CalculiX references of
//! `docs/validation/experiments/cylinder_platens_60/`. Writes the page
//! `docs/validation/phantom-compression.md` (`--out FILE` for another).
//!
//! The record is cut at 60 % strain (18 mm) and thinned to one row every
//! 0.5 mm of compression (36 rows): the copy keeps the file's metadata
//! lines, header and columns as they are (the testing machine's format),
//! so both fits read it exactly as they read the original:
//!
//! * homogeneous: `palpate calibrate --law neo-hookean --data uniaxial=FILE`
//!   (engineering stress against stretch, from the file's own columns);
//! * FE: `palpate calibrate --experiment PLATENS.toml --data force=FILE`
//!   (load against compression), with the shipped description
//!   `studies/experiments/phantom-platens.toml` (its friction set per case):
//!   the whole specimen with `support = "symmetry"`, two identical
//!   platens, of which the model is the upper half.
//!
//! ```text
//! nice cargo run -p palpate-studies --example bench_phantom_compression -- [--level 2] [--skip-fits] [--skip-ccx] [--out PAGE.md]
//! ```

use clap::Parser;
use palpate_studies::cli::{dispatch, Cli};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[path = "../../forward/fe/examples/common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

const RECORD: &str = "studies/data/real/phantom_dawood2026/EF10_0T/EF10_0T_A1.csv";
const DESCRIPTION: &str = "studies/experiments/phantom-platens.toml";
const CCX: &str = "docs/validation/experiments/cylinder_platens_60";
const STRAIN: f64 = 0.6;
const HEIGHT: f64 = 30.0;
const STEP: f64 = 0.5;

/// The shipped description of the cylinder between two identical platens
/// (`studies/experiments/phantom-platens.toml`) with the given platen
/// friction and C10 (TOML values) and mesh level.
fn description(friction: &str, c10: &str, level: Option<usize>) -> String {
    let mut t: toml::Table =
        toml::from_str(&std::fs::read_to_string(DESCRIPTION).expect(DESCRIPTION))
            .expect("the shipped description");
    let value = |v: &str| -> toml::Value {
        toml::from_str::<toml::Table>(&format!("v = {v}")).expect("a TOML value")["v"].clone()
    };
    t["tool"]["friction"] = value(friction);
    t["materials"]["silicone"]["C10"] = value(c10);
    let mut s = toml::to_string(&t).expect("TOML");
    if let Some(l) = level {
        s += &format!("\n[mesh]\nlevel = {l}\n");
    }
    s
}

/// The record cut at `STRAIN` and thinned to a row every `STEP` mm of
/// compression, in the file's own format (metadata lines and header kept).
fn thinned(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let header = lines
        .iter()
        .position(|l| l.starts_with("Time (s)"))
        .expect("the record's header");
    let mut out: String = lines[..=header].iter().map(|l| format!("{l}\n")).collect();
    let mut next = STEP;
    for l in &lines[header + 1..] {
        let c: f64 = l
            .split(',')
            .nth(1)
            .and_then(|v| v.trim().parse().ok())
            .expect("a compression value");
        if c > STRAIN * HEIGHT + 1e-6 {
            break;
        }
        if c >= next - 1e-9 {
            out += l;
            out.push('\n');
            next += STEP;
        }
    }
    out
}

fn run(line: &[String]) -> anyhow::Result<(f64, f64)> {
    println!("$ {}", line.join(" "));
    let cli = Cli::try_parse_from(line)?;
    let (t0, w0) = (cpu_seconds(false), std::time::Instant::now());
    dispatch(cli)?;
    Ok((cpu_seconds(false) - t0, w0.elapsed().as_secs_f64()))
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("the fit's JSON")).expect("JSON")
}

/// `(displacement_mm, force_N)` rows of a CSV with `#` comments and a
/// header.
fn curve(path: &Path) -> Vec<(f64, f64)> {
    std::fs::read_to_string(path)
        .unwrap_or_default()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| {
            let mut c = l.split(',').map(|v| v.trim().parse::<f64>());
            Some((c.next()?.ok()?, c.next()?.ok()?))
        })
        .collect()
}

fn interpolate(c: &[(f64, f64)], d: f64) -> Option<f64> {
    c.windows(2)
        .find(|w| w[0].0 <= d + 1e-9 && d <= w[1].0 + 1e-9)
        .map(|w| w[0].1 + (w[1].1 - w[0].1) * (d - w[0].0) / (w[1].0 - w[0].0))
}

struct Fit {
    label: String,
    c10: f64,
    se: f64,
    friction: Option<(f64, f64)>,
    rms: f64,
    evaluations: String,
    iterations: String,
    cpu: f64,
}

/// The fits as a Markdown table.
fn fits_table(fits: &[Fit], c10_h: f64) -> String {
    let mut t = String::from(
        "## Fits\n\nNeo-Hookean C10 by each model; the ratio is the FE fit's C10 over the \
         homogeneous fit's. The homogeneous fit's RMS is in MPa (engineering stress), the \
         FE fits' in N (load). CPU: seconds of the bench's process for the fit.\n\n\
         | model | C10 (MPa) | SE | ratio to homogeneous | platen friction | RMS | evaluations | iterations | CPU s |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for f in fits {
        t += &format!(
            "| {} | {:.5e} | {:.2e} | {:.4} | {} | {:.4} | {} | {} | {:.0} |\n",
            f.label,
            f.c10,
            f.se,
            f.c10 / c10_h,
            f.friction
                .map_or("-".into(), |(v, s)| format!("{v:.4} +- {s:.1e}")),
            f.rms,
            f.evaluations,
            f.iterations,
            f.cpu
        );
    }
    t + "\n"
}

/// The CalculiX decks of `CCX`: palpate's description, its label, the
/// curve CalculiX wrote, how far the deck went (mm) and its stated error
/// there (fraction; the README's).
const DECKS: [(&str, &str, &str, f64, &str); 3] = [
    (
        "experiment_mu0.toml",
        "frictionless",
        "ccx_mu0_level1.csv",
        16.5,
        "-0.19 % (3 mm) to -0.44 % (16.5 mm) from the homogeneous force",
    ),
    (
        "experiment_mu03.toml",
        "friction 0.3",
        "ccx_mu03_level1.csv",
        18.0,
        "3 % to 9 mm (measured), 3 % to 18 mm (estimated from the trend)",
    ),
    (
        "experiment_bonded.toml",
        "bonded",
        "ccx_bonded_level1.csv",
        14.5,
        "3.5 % to 5 mm, 5 % to 11.5 mm (measured), 5 % to 14.5 mm (estimated from the trend)",
    ),
];

/// The travels of the comparison table (mm).
const TRAVELS: [f64; 12] = [
    1.0, 2.0, 3.0, 4.0, 5.0, 6.5, 8.0, 10.0, 12.0, 14.5, 16.5, 18.0,
];

/// The homogeneous force of the frictionless cylinder (incompressible
/// neo-Hookean, whole-body travel `d`): `2 C10 (1/l^2 - l) pi R^2`,
/// `l = 1 - d / H`, with the decks' C10 = 2e-2 MPa and R = 25 mm.
fn homogeneous_force(d: f64) -> f64 {
    let l = 1.0 - d / HEIGHT;
    2.0 * 2e-2 * (1.0 / (l * l) - l) * std::f64::consts::PI * 25.0 * 25.0
}

/// The CalculiX stated error (fraction) of deck `label` at travel `d`
/// (README of `CCX`): frictionless 0.5 % (its distance from the
/// homogeneous force), friction 0.3 3 %, bonded 3.5 % to 5 mm and 5 %
/// beyond.
fn ccx_error(label: &str, d: f64) -> f64 {
    match label {
        "frictionless" => 0.005,
        "bonded" if d > 5.0 + 1e-9 => 0.05,
        "bonded" => 0.035,
        _ => 0.03,
    }
}

/// palpate's estimated discretisation error (fraction) at the deepest
/// sample, from the `# discretisation error (...): +X % at D mm` comment of
/// `simulate --csv`, if any.
fn palpate_error(comments: &[String]) -> Option<f64> {
    comments
        .iter()
        .filter(|l| l.starts_with("discretisation error"))
        .find_map(|l| {
            let before = l.split_once(" % at ")?.0;
            let v: f64 = before.split_whitespace().last()?.parse().ok()?;
            Some(v.abs() / 100.0)
        })
}

/// The section comparing `palpate simulate` with the CalculiX curves.
fn ccx_section(dir: &Path, level: Option<usize>) -> anyhow::Result<String> {
    let mut page = String::new();
    writeln!(
        page,
        "## The same cylinder against CalculiX\n\n\
         `palpate simulate --experiment {CCX}/experiment_<case>.toml` (the description above \
         with C10 = 2e-2 MPa and `bulk = 1000.0` as the decks' K = 1000 mu, asked to 18 mm, 60 % \
         strain) against the CalculiX curves committed beside those files (CalculiX 2.20, \
         CAX8, level 1 of the decks' mesh; the folder's README gives the decks, how far each \
         went and its error from a second mesh level). Relative difference (palpate - \
         CalculiX) / CalculiX; \"within\" when it is inside the sum of the two solvers' \
         stated errors.\n\n\
         With friction 0.3 the deck reaches 18 mm (60 %); the side rolls onto the platen from \
         7 mm. Bonded, it stops at 14.5 mm (48 %): from 8.5 mm (`fold.py`) the bulging side \
         folds over onto the platen, and Newton diverges as the next side node reaches it. \
         palpate holds the folded side in contact with the platen with the platen's friction, \
         CalculiX frictionless beyond the bonded face, so past 8.5 mm the bonded curves differ \
         by that model too. The frictionless deck stops at 16.5 mm (55 %). Beyond each deck's \
         reach only palpate's curve is shown.\n\n\
         palpate's stated error of a platen run comes from the tool's own mesh levels: \
         `palpate simulate` solves the levels half and twice the run's (the two below it at \
         level 2 and finer) and compares them at the run's samples, Richardson with the order \
         they show where their changes shrink, else a bound (the run's distance from the \
         finest level plus the largest change between levels). The needle's order does not \
         carry over to the platens: at friction 0.28, level 1 is 8.4 % below level 2 at 18 mm, \
         far more than Richardson with that order states \
         (docs/notes/2026-11-29-platen-friction-level1.md).\n"
    )?;
    let mut cols = Vec::new();
    for (experiment, label, ccx, reach, stated) in DECKS {
        let mut file = Path::new(CCX).join(experiment);
        if let Some(l) = level {
            let text = std::fs::read_to_string(&file)? + &format!("\n[mesh]\nlevel = {l}\n");
            file = dir.join(experiment);
            std::fs::write(&file, text)?;
        }
        let csv = dir.join(format!("sim_{label}.csv").replace(' ', "_"));
        let line: Vec<String> = [
            "palpate",
            "simulate",
            "--experiment",
            &file.display().to_string(),
            "--csv",
            &csv.display().to_string(),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let (cpu, failed) = match run(&line) {
            Ok((cpu, _)) => (cpu, None),
            Err(e) => (f64::NAN, Some(format!("{e:#}"))),
        };
        let comments: Vec<String> = std::fs::read_to_string(&csv)
            .unwrap_or_default()
            .lines()
            .filter(|l| l.starts_with("# discretisation error") || l.starts_with("# mesh"))
            .map(|l| l.trim_start_matches("# ").to_string())
            .collect();
        let sim = curve(&csv);
        let reached = sim.last().map_or(0.0, |r| r.0);
        writeln!(
            page,
            "- {label}: palpate reached {reached:.1} mm ({cpu:.0} s CPU){}; {}. CalculiX reached \
             {reach:.1} mm, stated error {stated}.",
            failed.map_or(String::new(), |e| format!(", then failed: {e}")),
            if comments.is_empty() {
                "no estimate".to_string()
            } else {
                comments.join("; ")
            }
        )?;
        let err = palpate_error(&comments);
        cols.push((label, sim, curve(&Path::new(CCX).join(ccx)), err));
    }
    let mut table = String::from("\n| travel (mm) | strain |");
    for (label, ..) in &cols {
        table += &format!(" palpate {label} (N) | CalculiX (N) | difference | within |");
    }
    table += " homogeneous (N) |\n|---|---|";
    for _ in &cols {
        table += "---|---|---|---|";
    }
    table += "---|\n";
    // per curve: travels compared, those within the stated errors, the
    // largest difference and where
    let mut verdicts: Vec<(usize, usize, f64, f64)> = vec![(0, 0, 0.0, 0.0); cols.len()];
    for d in TRAVELS {
        table += &format!("| {d:.1} | {:.0} % |", 100.0 * d / HEIGHT);
        for ((label, p, c, err), verdict) in cols.iter().zip(verdicts.iter_mut()) {
            match (interpolate(p, d), c.iter().find(|r| (r.0 - d).abs() < 1e-6)) {
                (Some(fp), Some(&(_, fc))) => {
                    let diff = fp / fc - 1.0;
                    if diff.abs() >= verdict.2.abs() {
                        (verdict.2, verdict.3) = (diff, d);
                    }
                    let within = err.map_or("-".to_string(), |e| {
                        verdict.0 += 1;
                        if diff.abs() <= e + ccx_error(label, d) {
                            verdict.1 += 1;
                            "yes".into()
                        } else {
                            "no".into()
                        }
                    });
                    table += &format!(" {fp:.3} | {fc:.3} | {:+.2} % | {within} |", 100.0 * diff)
                }
                (Some(fp), None) => table += &format!(" {fp:.3} | - | - | - |"),
                _ => table += " - | - | - | - |",
            }
        }
        table += &format!(" {:.3} |\n", homogeneous_force(d));
    }
    writeln!(
        page,
        "{table}\nhomogeneous: the incompressible neo-Hookean force of homogeneous compression, \
         `2 C10 (1/l^2 - l) pi R^2` with `l = 1 - travel / 30 mm` (the frictionless cylinder's \
         exact answer up to the decks' compressibility K = 1000 mu).\n"
    )?;
    writeln!(
        page,
        "Each curve against CalculiX (\"within\": inside the sum of palpate's stated error at \
         its deepest sample and CalculiX's stated error at that travel):\n"
    )?;
    for ((label, ..), (compared, within, worst, at)) in cols.iter().zip(&verdicts) {
        let verdict = if *compared == 0 {
            "not judged: palpate stated no error".to_string()
        } else if within == compared {
            format!("**agrees** within the two solvers' stated errors at all {compared} travels both reached")
        } else {
            format!(
                "**does not agree** within the two solvers' stated errors at {} of the {compared} travels both reached",
                compared - within
            )
        };
        writeln!(
            page,
            "- {label}: {verdict} (largest difference {:+.2} % at {at:.1} mm).",
            100.0 * worst
        )?;
    }
    writeln!(page)?;
    Ok(page)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|k| args.get(k + 1))
            .cloned()
    };
    let level: Option<usize> = opt("--level").map(|v| v.parse().expect("--level: 1, 2, ..."));
    let out =
        PathBuf::from(opt("--out").unwrap_or("docs/validation/phantom-compression.md".into()));
    let skip_fits = args.iter().any(|a| a == "--skip-fits");
    let skip_ccx = args.iter().any(|a| a == "--skip-ccx");
    let dir = tempfile::tempdir()?;
    let record = dir.path().join("EF10_0T_A1_to60.csv");
    std::fs::write(&record, thinned(&std::fs::read_to_string(RECORD)?))?;
    let rows = curve(&record).len();
    let mut page = String::new();
    writeln!(
        page,
        "# The phantom cylinder between platens: FE against the homogeneous fit\n\n\
         Generated by `nice cargo run -p palpate-studies --example bench_phantom_compression{}` \
         (do not edit: rerun it). Dev profile, a 2-core machine shared with other builds: CPU \
         seconds of the bench's process.\n",
        {
            // the options that shape the page (not where it is written)
            let shown: Vec<&str> = args
                .iter()
                .enumerate()
                .filter(|&(k, a)| a != "--out" && (k == 0 || args[k - 1] != "--out"))
                .map(|(_, a)| a.as_str())
                .collect();
            if shown.is_empty() {
                String::new()
            } else {
                format!(" -- {}", shown.join(" "))
            }
        }
    )?;
    writeln!(
        page,
        "Record: `{RECORD}` (Ecoflex 00-10, no thinner, cast A, test 1; Dawood et al. 2026, CC BY \
         4.0), a cylinder 50 mm across and 30 mm high compressed at 10 mm/min; cut at {:.0} % \
         strain ({} mm) and thinned to one row every {STEP} mm of compression ({rows} rows), \
         in the file's own format (its metadata lines, header and seven columns kept). The \
         platens' lubrication is not stated by the database.\n",
        100.0 * STRAIN,
        STRAIN * HEIGHT
    )?;
    if !skip_fits {
        let mut fits: Vec<Fit> = Vec::new();
        // the homogeneous fit
        let h_json = dir.path().join("homogeneous.json");
        let line: Vec<String> = [
            "palpate",
            "calibrate",
            "--law",
            "neo-hookean",
            "--data",
            &format!("uniaxial={}", record.display()),
            "--json",
            &h_json.display().to_string(),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let (cpu, _) = run(&line)?;
        let h = json(&h_json);
        let c10_h = h["params"]["C10"]["value"].as_f64().unwrap_or(f64::NAN);
        fits.push(Fit {
            label: "homogeneous (uniaxial stress, `--data uniaxial=FILE`)".into(),
            c10: c10_h,
            se: h["params"]["C10"]["standard_error"]
                .as_f64()
                .unwrap_or(f64::NAN),
            friction: None,
            rms: h["rms"].as_f64().unwrap_or(f64::NAN),
            evaluations: h["evaluations"].to_string(),
            iterations: h["iterations"].to_string(),
            cpu,
        });
        for (label, friction) in [
            ("FE, platen friction 0.3", "0.3"),
            ("FE, bonded platens", "\"bonded\""),
            (
                "FE, platen friction fitted",
                "{ start = 0.3, lower = 0.0, upper = 2.0 }",
            ),
            ("FE, frictionless platens", "0.0"),
        ] {
            let file = dir.path().join("platens.toml");
            let fe_json = dir.path().join("fe.json");
            std::fs::write(
                &file,
                description(friction, &format!("{{ start = {c10_h:.4e} }}"), level),
            )?;
            let line: Vec<String> = [
                "palpate",
                "calibrate",
                "--experiment",
                &file.display().to_string(),
                "--data",
                &format!("force={}", record.display()),
                "--json",
                &fe_json.display().to_string(),
            ]
            .iter()
            .map(|s| s.to_string())
            .collect();
            let (cpu, wall) = match run(&line) {
                Ok(t) => t,
                Err(e) => {
                    println!("{label}: calibrate failed: {e:#}");
                    writeln!(page, "{label}: calibrate failed: {e:#}\n")?;
                    continue;
                }
            };
            let f = json(&fe_json);
            let p = |n: &str, k: &str| f["params"][n][k].as_f64().unwrap_or(f64::NAN);
            let fit = Fit {
                label: label.into(),
                c10: p("C10", "value"),
                se: p("C10", "standard_error"),
                friction: f["params"]
                    .get("friction")
                    .map(|_| (p("friction", "value"), p("friction", "standard_error"))),
                rms: f["rms"].as_f64().unwrap_or(f64::NAN),
                evaluations: f["evaluations"].to_string(),
                iterations: f["iterations"].to_string(),
                cpu,
            };
            println!(
                "{label}: C10 {:.5e} +- {:.2e}, ratio {:.4}, RMS {:.3} N; {} FE runs, {} iterations, {cpu:.0} s CPU ({wall:.0} s wall)",
                fit.c10, fit.se, fit.c10 / c10_h, fit.rms, fit.evaluations, fit.iterations
            );
            fits.push(fit);
            // the page so far, should a later fit be stopped
            std::fs::write(&out, format!("{page}{}", fits_table(&fits, c10_h)))?;
        }
        page += &fits_table(&fits, c10_h);
        // a fitted friction that fits worse than a fixed one is no optimum
        let fixed_rms = fits
            .iter()
            .filter(|f| f.label.starts_with("FE") && f.friction.is_none())
            .map(|f| f.rms)
            .fold(f64::INFINITY, f64::min);
        if let Some(f) = fits
            .iter()
            .find(|f| f.friction.is_some() && f.rms > fixed_rms)
        {
            writeln!(
                page,
                "The fit with the platen friction fitted is **not an optimum**: it ended at \
                 friction {:.4} with an RMS of {:.3} N, above the {fixed_rms:.3} N of a fit with \
                 the friction held. At this mesh level the force is not monotone in the friction: \
                 it drops as the friction passes about 0.28, where the bulging side starts to roll \
                 onto the platen's edge, a jump that the next level does not have (no FE run \
                 fails; docs/notes/2026-11-29-platen-friction-level1.md). Levenberg-Marquardt \
                 stops below the jump, and its standard errors there mean nothing. At level 1, \
                 fit C10 at a few fixed frictions (the rows above), or fit the friction at the \
                 description's default level.\n",
                f.friction.map_or(f64::NAN, |x| x.0),
                f.rms
            )?;
        }
    }
    std::fs::write(&out, &page)?;
    if !skip_ccx {
        page += &ccx_section(dir.path(), level)?;
    }
    std::fs::write(&out, &page)?;
    println!("wrote {}", out.display());
    Ok(())
}
