//! A study manifest runs into a complete run folder, and running it again
//! (also on another thread count) gives a byte-identical `results.json`.

use palpate_studies::study::runner::run_study;
use std::path::{Path, PathBuf};

fn manifest(dir: &Path) -> PathBuf {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/treloar");
    let text = format!(
        r#"
[study]
name = "small"
seed = 3

[data.uniaxial]
file = "{u}"
test = "uniaxial"

[data.planar]
file = "{p}"
test = "planar"

[models.nh]
law = "neo-hookean"

[models.yeoh]
law = "yeoh"

[[steps]]
[steps.calibrate]
name = "fit"
models = ["nh", "yeoh"]
fits = {{ uniaxial = ["uniaxial"], both = ["uniaxial", "planar"] }}
residuals = ["absolute", "relative"]
predict = ["uniaxial", "planar"]
"#,
        u = data.join("uniaxial.csv").display(),
        p = data.join("pure_shear.csv").display()
    );
    let path = dir.join("small.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn rerun_is_byte_identical_and_folder_is_complete() {
    let dir = tempfile::tempdir().unwrap();
    let m = manifest(dir.path());
    let quiet = |_: &str| {};
    let a = run_study(&m, Some(&dir.path().join("a")), &quiet).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = one
        .install(|| run_study(&m, Some(&dir.path().join("b")), &quiet))
        .unwrap();
    let ra = std::fs::read(a.join("results.json")).unwrap();
    let rb = std::fs::read(b.join("results.json")).unwrap();
    assert!(ra == rb, "results.json differs between runs");
    for f in [
        "report.md",
        "provenance.json",
        "plots/fit-yeoh-both-relative.svg",
    ] {
        assert!(a.join(f).is_file(), "{f} missing");
    }
    let report = std::fs::read_to_string(a.join("report.md")).unwrap();
    assert!(
        report.contains("| yeoh") && report.contains("Drucker"),
        "{report}"
    );
    let prov: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("provenance.json")).unwrap()).unwrap();
    assert_eq!(prov["seed"], 3);
    assert_eq!(prov["data"].as_array().unwrap().len(), 2);
    assert_eq!(prov["manifest"]["sha256"].as_str().unwrap().len(), 64);
}

#[test]
fn bad_manifest_is_a_clear_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let m = manifest(dir.path());
    let text = std::fs::read_to_string(&m)
        .unwrap()
        .replace("residuals =", "residual =");
    std::fs::write(&m, text).unwrap();
    let e = run_study(&m, Some(&dir.path().join("x")), &|_: &str| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("small.toml") && e.contains("residual") && e.contains("line"),
        "{e}"
    );
    assert!(!dir.path().join("x/results.json").exists());
}

/// A C1 record of ecoflex-nh with a deterministic pseudo-random error.
fn c1_record(dir: &Path) -> PathBuf {
    let area = std::f64::consts::PI * 19.0 * 19.0;
    let mut csv = String::from("time_s,displacement_mm,force_N\n");
    for i in 0..=60 {
        let d = 0.03 * i as f64;
        let s: f64 = 1.0 - d / 9.0;
        let f = 2.0 * 1.101295e-3 * (1.0 / (s * s) - s) * area;
        let noise = 0.002 * ((i as f64 * 12.9898).sin() * 43758.5453).fract();
        csv.push_str(&format!("{},{d},{}\n", 0.5 * i as f64, f + noise));
    }
    let p = dir.join("c1.csv");
    std::fs::write(&p, csv).unwrap();
    p
}

#[test]
fn a_named_model_gives_the_same_results_as_the_law_form() {
    let dir = tempfile::tempdir().unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/treloar");
    let study = |models: &str, calibrate: &str, diagnose: &str| {
        let text = format!(
            "[study]\nname = \"s\"\n\n[data.uniaxial]\nfile = \"{u}\"\ntest = \"uniaxial\"\n\n\
             [data.rec]\nfile = \"{c}\"\ntest = \"C1\"\n\n{models}\n\
             [[steps]]\n[steps.calibrate]\nname = \"fit\"\nmodels = [\"{calibrate}\"]\n\
             fits = {{ u = [\"uniaxial\"] }}\n\n\
             [[steps]]\n[steps.diagnose]\nname = \"gap\"\ndata = [\"rec\"]\n{diagnose}\n",
            u = data.join("uniaxial.csv").display(),
            c = c1_record(dir.path()).display(),
        );
        let path = dir.path().join("s.toml");
        std::fs::write(&path, text).unwrap();
        let out = run_study(&path, Some(&dir.path().join("out")), &|_: &str| {}).unwrap();
        let v: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("results.json")).unwrap()).unwrap();
        v["steps"].clone()
    };
    let law_form = study(
        "[models.nh]\nlaw = \"neo-hookean\"\n",
        "nh",
        "base = \"neo-hookean\"",
    );
    let named = study(
        "[models.nh.homogeneous]\nlaw = \"neo-hookean\"\nmode = \"uniaxial\"\n\n\
         [models.press.c1]\nlaw = \"neo-hookean\"\n",
        "nh",
        "model = \"press\"",
    );
    assert_eq!(law_form, named);
    assert!(law_form[1]["diagnose"]["cases"][0]["report"]["verdict"].is_string());
}

#[test]
fn a_model_that_does_not_predict_its_data_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let m = manifest(dir.path());
    let text = std::fs::read_to_string(&m).unwrap().replace(
        "[models.yeoh]\nlaw = \"yeoh\"",
        "[models.yeoh.n1_needle]\nlaw = \"yeoh\"",
    );
    std::fs::write(&m, text).unwrap();
    let e = run_study(&m, Some(&dir.path().join("x")), &|_: &str| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("\"yeoh\"") && e.contains("n1_needle") && e.contains("uniaxial"),
        "{e}"
    );
}
