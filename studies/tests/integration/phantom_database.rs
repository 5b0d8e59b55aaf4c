//! The `replicates` step on the phantom database of Dawood et al. 2026
//! (`studies/data/real/phantom_dawood2026`, CC BY 4.0): the mean curve of a
//! phantom's ten tests on the database's grid, each law fitted to it
//! beside the database's own fit, and a rerun that is byte-identical.

use palpate_studies::study::runner::run_study;
use std::path::{Path, PathBuf};

fn database() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/real/phantom_dawood2026")
}

fn manifest(dir: &Path, name: &str, body: &str) -> PathBuf {
    let text = format!("[study]\nname = \"{name}\"\nseed = 1\n{body}",);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// A `replicates` step over the files `names` (a pattern or several) of
/// a phantom's folder.
fn step(phantom: &str, names: &[&str], laws: &str, per_record: &str) -> String {
    let db = database();
    let path = |n: &str| format!("\"{}\"", db.join(phantom).join(n).display());
    let data = match names {
        [one] => path(one),
        many => format!(
            "[{}]",
            many.iter().map(|n| path(n)).collect::<Vec<_>>().join(", ")
        ),
    };
    format!(
        r#"
[[steps]]
[steps.replicates]
name = "{phantom}"
data = {data}
laws = {laws}
per_record_laws = {per_record}
published = {{ file = "{table}", format = "dawood2026", material = "{phantom}" }}
"#,
        table = db.join("hyperelastic_parameters.json").display(),
    )
}

fn results(folder: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(folder.join("results.json")).unwrap()).unwrap()
}

/// On EF10_0T's ten tests, palpate's fits to the mean curve reach the
/// database's: neo-Hookean, Yeoh of order 2, Ogden of order 2 and Humphrey
/// with the same parameters to 4 significant digits and the same SSE.
#[test]
fn mean_curve_fits_reach_the_databases() {
    let dir = tempfile::tempdir().unwrap();
    let m = manifest(
        dir.path(),
        "db",
        &step(
            "EF10_0T",
            &["*.csv"],
            r#"["neo-hookean", "reduced-polynomial:2", "ogden:2", "humphrey"]"#,
            "[]",
        ),
    );
    let out = run_study(&m, Some(&dir.path().join("run")), &|_: &str| {}).unwrap();
    let r = results(&out);
    let step = &r["steps"][0]["replicates"];
    assert_eq!(step["records"].as_array().unwrap().len(), 10, "{step}");
    assert_eq!(step["mean_curve"]["points"], 1000);
    for law in step["laws"].as_array().unwrap() {
        let c = &law["published"];
        let verdict = c["verdict"].as_str().unwrap();
        assert!(verdict == "same", "{}: {verdict}: {law}", law["law"]);
        // the curve is the database's: its own SSE within 1e-5
        let (sse, published) = (
            c["sse_palpate"].as_f64().unwrap(),
            c["sse"].as_f64().unwrap(),
        );
        assert!(
            (sse / published - 1.0).abs() < 1e-5,
            "{}: {sse} {published}",
            law["law"]
        );
    }
    // neo-Hookean: C10 = mu / 2 of the database's 21.961397925705736 kPa
    let nh = &step["laws"][0];
    assert_eq!(nh["law"], "neo-hookean");
    let c10 = nh["mean_curve"][0].as_f64().unwrap();
    assert!(
        (c10 / (21.961_397_925_705_736e-3 / 2.0) - 1.0).abs() < 1e-6,
        "{c10}"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("published laws palpate does not have: Mooney Rivlin_o2"),
        "{report}"
    );
    // no pooled or per-record fits asked for
    assert!(step["laws"][0]["replicates"].is_null());
}

/// Three tests of a phantom, two laws, pooled and per record: a second run
/// writes the same results, report and table, byte for byte.
#[test]
fn replicates_rerun_byte_identically() {
    let dir = tempfile::tempdir().unwrap();
    let m = manifest(
        dir.path(),
        "small",
        &step(
            "EF10_0T",
            &["EF10_0T_A1.csv", "EF10_0T_A2.csv", "EF10_0T_B1.csv"],
            r#"["neo-hookean", "ogden:1"]"#,
            r#"["neo-hookean"]"#,
        ),
    );
    let quiet = |_: &str| {};
    let a = run_study(&m, Some(&dir.path().join("a")), &quiet).unwrap();
    let b = run_study(&m, Some(&dir.path().join("b")), &quiet).unwrap();
    for f in ["results.json", "report.md", "EF10_0T-fits.csv"] {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs between runs");
    }
    let r = results(&a);
    let step = &r["steps"][0]["replicates"];
    assert_eq!(step["records"].as_array().unwrap().len(), 3);
    let nh = &step["laws"][0];
    // three records: the replicate fits and the batch test (A: 2, B: 1: no test)
    let reps = &nh["replicates"];
    assert_eq!(reps["fits"].as_array().unwrap().len(), 3, "{reps}");
    let mean = nh["mu0_records_mean"].as_f64().unwrap();
    let curve = nh["mu0_mean_curve"].as_f64().unwrap();
    assert!((mean / curve - 1.0).abs() < 0.01, "{mean} {curve}");
}

/// `palpate sample --hierarchical` on EF10_0T's ten tests: the between-test
/// SD of C10 holds the spread of the per-test fits, and the chains converge.
#[test]
fn hierarchical_posterior_holds_the_spread_of_the_tests() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("h.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(["sample", "--law", "neo-hookean", "--hierarchical", "--data"])
        .arg(format!(
            "uniaxial={}",
            database().join("EF10_0T/*.csv").display()
        ))
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let h: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let post = &h["hierarchical"];
    assert_eq!(post["tests"], 10);
    assert!(post["converged"].as_bool().unwrap() && post["rhat_max"].as_f64().unwrap() < 1.01);
    let c10 = &post["parameters"][0];
    let sd = c10["estimates_sd"].as_f64().unwrap();
    let (lo, hi) = (
        c10["tau"]["hdi_3"].as_f64().unwrap(),
        c10["tau"]["hdi_97"].as_f64().unwrap(),
    );
    assert!(lo < sd && sd < hi, "tau [{lo}, {hi}], per-test SD {sd}");
    let mu = c10["mu"]["mean"].as_f64().unwrap();
    assert!(
        (mu / c10["estimates_mean"].as_f64().unwrap() - 1.0).abs() < 0.01,
        "{mu}"
    );
}
