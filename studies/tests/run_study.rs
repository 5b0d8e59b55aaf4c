//! A study manifest runs into a complete run folder, and running it again
//! (also on another thread count) gives a byte-identical `results.json`.

use palpate_studies::runner::run_study;
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
