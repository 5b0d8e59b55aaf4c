//! A lab's own experiment from the command line: `palpate experiment
//! list|show|check`, `--experiment` on simulate and calibrate, and a study
//! manifest's `[experiments.NAME]` tables.

use std::path::Path;
use std::process::{Command, Output};

fn palpate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(args)
        .output()
        .expect("run palpate")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn assert_clean_failure(o: &Output, needles: &[&str]) {
    let e = stderr(o);
    assert!(!o.status.success(), "should fail: {}", stdout(o));
    assert!(!e.contains("panicked"), "panic: {e}");
    for n in needles {
        assert!(e.contains(n), "`{n}` not in: {e}");
    }
}

#[test]
fn every_preset_is_listed() {
    let o = palpate(&["experiment", "list"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("N1") && out.contains("needle"), "{out}");
}

#[test]
fn a_preset_shown_is_a_file_check_accepts_with_the_same_parameters() {
    let o = palpate(&["experiment", "show", "N1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.starts_with("# palpate experiment preset N1"), "{text}");
    assert!(text.contains("docs/benchmarks.md"), "{text}");
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("n1.toml");
    std::fs::write(&file, &text).unwrap();
    let from_file = palpate(&["experiment", "check", file.to_str().unwrap()]);
    let from_preset = palpate(&["experiment", "check", "N1"]);
    // the same parameter table from the file and from the preset (the
    // model line may say the description cannot be built yet: then both say so)
    let table = |o: &Output| {
        let s = stdout(o);
        s.split_once("parameters")
            .map(|(_, t)| t.to_string())
            .unwrap_or(stderr(o))
    };
    assert_eq!(
        from_file.status.success(),
        from_preset.status.success(),
        "{} / {}",
        stderr(&from_file),
        stderr(&from_preset)
    );
    if from_file.status.success() {
        assert_eq!(table(&from_file), table(&from_preset));
        assert!(table(&from_file).contains("C10"), "{}", stdout(&from_file));
    }
}

#[test]
fn check_names_the_file_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("gel.toml");
    std::fs::write(
        &file,
        "[specimen]\nshape = \"cylinder\"\nradius = 20.0\nheight = 10.0\n\n\
         [materials.gel]\nlaw = \"neo-hookean\"\nC01 = { start = 2e-3 }\n\n\
         [tool]\nshape = \"sphere\"\nradius = 2.5\n",
    )
    .unwrap();
    let o = palpate(&["experiment", "check", file.to_str().unwrap()]);
    assert_clean_failure(&o, &["gel.toml", "materials.gel.C01"]);
    std::fs::write(
        &file,
        "[specimen]\nshape = \"cylinder\"\nradius = 20.0\nhieght = 10.0\n",
    )
    .unwrap();
    let o = palpate(&["experiment", "check", file.to_str().unwrap()]);
    assert_clean_failure(&o, &["gel.toml", "hieght"]);
    let o = palpate(&["experiment", "show", "N9"]);
    assert_clean_failure(&o, &["N9", "N1"]);
}

#[test]
fn simulate_refuses_benchmark_options_with_an_experiment() {
    for extra in [
        &["--mesh", "fine"][..],
        &["--law", "yeoh"],
        &["--benchmark", "N1"],
    ] {
        let mut args = vec!["simulate", "--experiment", "N1"];
        args.extend_from_slice(extra);
        let o = palpate(&args);
        assert_clean_failure(&o, &["--experiment", extra[0]]);
    }
    let o = palpate(&[
        "calibrate",
        "--experiment",
        "N1",
        "--law",
        "yeoh",
        "--data",
        "x.csv",
    ]);
    assert_clean_failure(&o, &["--experiment", "--law"]);
}

/// The gel disc as shipped (`studies/experiments/gel-disc.toml`).
const GEL: &str = include_str!("../../experiments/gel-disc.toml");

fn manifest(dir: &Path, experiment: &str, model: &str) -> std::path::PathBuf {
    std::fs::write(
        dir.join("r.csv"),
        "displacement_mm,force_N\n0,0\n0.5,0.01\n",
    )
    .unwrap();
    let table = GEL.replace("\n[", "\n[experiments.gel.");
    let text = format!(
        "[study]\nname = \"t\"\n\n[data.rec]\nfile = \"r.csv\"\ntest = \"N1\"\n\n\
         {}\n[models.disc]\n{model}\n\n\
         [[steps]]\n[steps.calibrate]\nname = \"fit\"\nmodels = [\"disc\"]\nfits = {{ r = [\"rec\"] }}\n",
        if experiment.is_empty() { table } else { experiment.to_string() }
    );
    let p = dir.join("study.toml");
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_manifest_refers_to_its_experiment_tables_and_names_a_bad_field() {
    use palpate_studies::study::manifest::Manifest;
    let dir = tempfile::tempdir().unwrap();
    let p = manifest(dir.path(), "", "experiment = \"gel\"");
    let m = Manifest::parse(&p, &std::fs::read_to_string(&p).unwrap()).unwrap();
    assert_eq!(m.experiments.len(), 1);
    let spec = match &m.models["disc"].model {
        palpate_studies::model::ModelForm::Spec(palpate_studies::model::ModelSpec::Experiment(
            s,
        )) => s.clone(),
        other => panic!("{other:?}"),
    };
    assert!(
        spec.source.to_string().contains("experiments.gel"),
        "{}",
        spec.source
    );
    assert_eq!(spec.law_text(), "neo-hookean");
    // an unknown name: the table, the presets and the file are named
    let p = manifest(dir.path(), "", "experiment = \"gle\"");
    let e = Manifest::parse(&p, &std::fs::read_to_string(&p).unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("study.toml") && e.contains("gle") && e.contains("gel"),
        "{e}"
    );
    // a bad field of the table: the manifest and the field
    let bad = GEL
        .replace("C10 =", "C01 =")
        .replace("\n[", "\n[experiments.gel.");
    let p = manifest(dir.path(), &bad, "experiment = \"gel\"");
    let m = Manifest::parse(&p, &std::fs::read_to_string(&p).unwrap()).unwrap();
    let e = m.validate(&p).unwrap_err().to_string();
    assert!(
        e.contains("study.toml") && e.contains("experiments.gel") && e.contains("C01"),
        "{e}"
    );
    // a misspelled field inside the table: the manifest's file and line
    let bad = GEL
        .replace("radius = 20.0", "raduis = 20.0")
        .replace("\n[", "\n[experiments.gel.");
    let p = manifest(dir.path(), &bad, "experiment = \"gel\"");
    let e = Manifest::parse(&p, &std::fs::read_to_string(&p).unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("study.toml") && e.contains("raduis") && e.contains("line"),
        "{e}"
    );
}
