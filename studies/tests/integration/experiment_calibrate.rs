//! `palpate calibrate --experiment FILE --data force=RECORD.csv` end to
//! end, on synthetic records made on a finer mesh than the fit's, with
//! seeded noise: the fitted parameters recover the truth within 2 standard
//! errors. Small versions (shallow depths, coarse meshes, few samples) of
//! the cases `studies/examples/bench_calibrate_experiment.rs` runs.

use std::path::Path;
use std::process::{Command, Output};

fn palpate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(args)
        .output()
        .expect("run palpate")
}

fn record(text: &str, theta: &[f64], depths: &[f64], noise: f64, seed: u64) -> String {
    crate::common::experiment_record(text, theta, depths, noise, seed)
}

/// Runs `palpate calibrate --experiment` on the description and record in
/// `dir`; the JSON it writes.
fn calibrate(dir: &Path, description: &str, record: &str) -> serde_json::Value {
    let (file, data, json) = (
        dir.join("experiment.toml"),
        dir.join("record.csv"),
        dir.join("fit.json"),
    );
    std::fs::write(&file, description).unwrap();
    std::fs::write(&data, record).unwrap();
    let o = palpate(&[
        "calibrate",
        "--experiment",
        file.to_str().unwrap(),
        "--data",
        &format!("force={}", data.display()),
        "--json",
        json.to_str().unwrap(),
    ]);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "calibrate failed:\n{out}\n{err}");
    eprintln!("{out}");
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

/// Each (name, truth) is recovered within 2 standard errors (and the
/// standard error is a real one: finite, > 0).
fn assert_recovered(fit: &serde_json::Value, truth: &[(&str, f64)]) {
    assert_eq!(fit["converged"], true, "{fit}");
    for (name, t) in truth {
        let p = &fit["params"][name];
        let v = p["value"].as_f64().unwrap_or_else(|| panic!("{name}: {p}"));
        let se = p["standard_error"]
            .as_f64()
            .unwrap_or_else(|| panic!("{name}: no standard error: {p}"));
        eprintln!(
            "{name}: {v:.6e} +- {se:.2e} (truth {t:.6e}, {:+.2} SE)",
            (v - t) / se
        );
        assert!(se > 0.0 && se.is_finite(), "{name}: SE {se}");
        assert!((v - t).abs() < 2.0 * se, "{name}: {v} +- {se}, truth {t}");
    }
}

/// The gel disc as shipped (`studies/experiments/gel-disc.toml`).
const GEL: &str = include_str!("../../experiments/gel-disc.toml");

/// The `[mesh]` table of the fit (4-node elements at level 1, the
/// coarsest) and of the record (level 2: elements half as large).
const FIT_MESH: &str = "\n[mesh]\nlevel = 1\nelement = \"quad4\"\n";
const RECORD_MESH: &str = "\n[mesh]\nlevel = 2\nelement = \"quad4\"\n";

/// A 2.5 mm sphere on a bonded 10 mm disc 40 mm across: the modulus from
/// a record to 0.5 mm made on a mesh twice as fine as the fit's, with
/// noise of 1 % of the largest force.
#[test]
fn the_modulus_of_a_gel_disc_from_a_sphere_record() {
    let truth = 5.0e-3;
    let depths: Vec<f64> = (1..=5).map(|k| 0.1 * k as f64).collect();
    let fine = format!("{GEL}\n[protocol]\nsegments = [{{ ramp_to = 0.5 }}]\n{RECORD_MESH}");
    let rec = record(&fine, &[truth], &depths, 0.01, 7);
    let dir = tempfile::tempdir().unwrap();
    let fit = calibrate(dir.path(), &format!("{GEL}{FIT_MESH}"), &rec);
    assert_recovered(&fit, &[("C10", truth)]);
}

/// `--method` is `--estimator` under another name (lm, bfgs, lbfgs).
#[test]
fn method_names_the_estimator() {
    use clap::Parser;
    use palpate_studies::cli::{Cli, Command};
    for (option, value) in [("--method", "bfgs"), ("--estimator", "lbfgs")] {
        let cli = Cli::try_parse_from([
            "palpate",
            "calibrate",
            "--experiment",
            "gel-disc.toml",
            "--data",
            "force=record.csv",
            option,
            value,
        ])
        .unwrap();
        match cli.command {
            Command::Calibrate(a) => assert_eq!(a.estimator, value, "{option}"),
            other => panic!("{other:?}"),
        }
    }
}
