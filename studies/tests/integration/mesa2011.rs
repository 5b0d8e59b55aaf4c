//! The Mesa-Munera (2011) source study's chain on a cheap manifest: the
//! committed compression record and the phantom's needle records cut at
//! 1 mm, N1 and N3 on their coarse meshes. Calibrate -> predict (FE, cached)
//! -> factorial ANOVA beside the published table; rerun byte-identical with
//! every FE run taken from the cache, also after an edit of the anova step.
//! The full study is `studies/mesa2011.toml` (README).

use palpate_studies::study::manifest::Manifest;
use palpate_studies::study::runner::{run_study, RunObserver};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/mesa2011")
}

/// The needle records cut at `depth` mm, written into `dir`.
fn short_records(dir: &Path, depth: f64) -> Vec<PathBuf> {
    (1..=3)
        .map(|r| {
            let text = std::fs::read_to_string(data_dir().join(format!("needle-{r}.csv"))).unwrap();
            let kept: Vec<&str> = text
                .lines()
                .filter(|l| {
                    l.starts_with('#')
                        || l.starts_with("displacement")
                        || l.split(',').next().unwrap().parse::<f64>().unwrap() <= depth
                })
                .collect();
            let p = dir.join(format!("needle-{r}.csv"));
            std::fs::write(&p, kept.join("\n") + "\n").unwrap();
            p
        })
        .collect()
}

fn manifest_text(dir: &Path, alpha: f64) -> String {
    let recs = short_records(dir, 1.0);
    let d = data_dir();
    format!(
        r#"
[study]
name = "mesa-small"
seed = 1

[data.compression]
file = "{c}"
test = "C1"

[data.needle-1]
file = "{n1}"
test = "N1"

[data.needle-2]
file = "{n2}"
test = "N1"

[data.needle-3]
file = "{n3}"
test = "N1"

[models.nh.c1]
law = "neo-hookean"

[models.rp.c1]
law = "reduced-polynomial:2"

[models.nh-axi.n1_needle]
law = "neo-hookean"
mesh = "coarse"

[models.rp-axi.n1_needle]
law = "reduced-polynomial:2"
mesh = "coarse"

[models.nh-3d.n3_needle]
law = "neo-hookean"

[models.rp-3d.n3_needle]
law = "reduced-polynomial:2"

[[steps]]
[steps.calibrate]
name = "compression"
models = ["nh", "rp"]
fits = {{ c1 = ["compression"] }}

[[steps]]
[steps.predict]
name = "needle"
calibration = "compression"
models = ["nh-axi", "nh-3d", "rp-axi", "rp-3d"]
data = ["needle-1", "needle-2", "needle-3"]

[[steps]]
[steps.anova]
name = "table1"
predictions = "needle"
factors.material = {{ nh-axi = "NH", nh-3d = "NH", rp-axi = "RP", rp-3d = "RP" }}
factors.space = {{ nh-axi = "axisymmetric", nh-3d = "3D", rp-axi = "axisymmetric", rp-3d = "3D" }}
alpha = {alpha}
published = "{p}"
source = "Mesa-Munera 2011"
"#,
        c = d.join("c1-compression.csv").display(),
        n1 = recs[0].display(),
        n2 = recs[1].display(),
        n3 = recs[2].display(),
        p = d.join("published-table1.csv").display(),
    )
}

/// Records the observer's messages and the progress calls.
#[derive(Default)]
struct Log {
    messages: Mutex<Vec<String>>,
    progress: Mutex<Vec<(u64, u64)>>,
}

impl RunObserver for Log {
    fn message(&self, text: &str) {
        self.messages.lock().unwrap().push(text.to_string());
    }
    fn progress(&self, _label: &str, done: u64, total: u64) {
        self.progress.lock().unwrap().push((done, total));
    }
}

#[test]
fn the_chain_runs_reruns_byte_identical_and_caches_the_fe_runs() {
    let dir = tempfile::tempdir().unwrap();
    let m = dir.path().join("mesa-small.toml");
    std::fs::write(&m, manifest_text(dir.path(), 0.05)).unwrap();
    let out = dir.path().join("run");

    let first = Log::default();
    run_study(&m, Some(&out), &first).unwrap();
    let results = std::fs::read(out.join("results.json")).unwrap();
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    // four FE runs of 5 load steps each, counted to the end
    let progress = first.progress.lock().unwrap().clone();
    assert_eq!(progress.last(), Some(&(20, 20)), "{progress:?}");
    assert!(
        first
            .messages
            .lock()
            .unwrap()
            .iter()
            .any(|m| m.contains("running")),
        "the first run computes"
    );

    // The calibrated parameters reach the predictions: ecoflex of docs/benchmarks.md.
    let json: serde_json::Value = serde_json::from_slice(&results).unwrap();
    let runs = json["steps"][1]["predict"]["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 4);
    let c10_nh = runs[0]["params"]["C10"].as_f64().unwrap();
    assert!(
        (c10_nh / 1101.295e-6 - 1.0).abs() < 0.005,
        "NH C10 {c10_nh}"
    );
    let rp = &runs[2]["params"];
    let (c10, c20) = (rp["C10"].as_f64().unwrap(), rp["C20"].as_f64().unwrap());
    assert!((c10 / 686.428e-6 - 1.0).abs() < 0.03, "RP C10 {c10}");
    assert!((c20 / 1929.606e-6 - 1.0).abs() < 0.05, "RP C20 {c20}");
    assert_eq!(runs[1]["kind"], "n3_needle");
    // 12 comparisons (4 models x 3 records) in the factorial
    let comps = json["steps"][1]["predict"]["comparisons"]
        .as_array()
        .unwrap();
    assert_eq!(comps.len(), 12);
    let anova = &json["steps"][2]["anova"];
    let terms = anova["analysis"]["terms"].as_array().unwrap();
    let names: Vec<&str> = terms.iter().map(|t| t["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["material", "space", "material:space"]);
    assert_eq!(anova["analysis"]["residual"]["df"], 8);
    assert_eq!(anova["published"]["residual"]["df"], 4);
    assert!(anova["analysis"]["ryan_joiner"]["r"].is_number());
    // the report: Table 1 layout beside the paper, the conclusion in words
    for needle in [
        "| material | space | ours 1 | ours 2 | ours 3 | ours mean | Mesa-Munera 2011 1 | Mesa-Munera 2011 2 | Mesa-Munera 2011 mean |",
        "| NH | axisymmetric |",
        "0.98024 | 0.97516",
        "### Conclusion",
        "**Agreement**",
        "Ryan-Joiner R =",
        "Bartlett statistic",
    ] {
        assert!(report.contains(needle), "{needle} not in\n{report}");
    }
    for plot in [
        "plots/needle.svg",
        "plots/table1-main_effects.svg",
        "plots/table1-interaction.svg",
        "plots/table1-published-main_effects.svg",
    ] {
        assert!(out.join(plot).is_file(), "{plot}");
    }

    // A rerun: byte-identical, every FE run from the cache.
    let second = Log::default();
    run_study(&m, Some(&out), &second).unwrap();
    assert_eq!(std::fs::read(out.join("results.json")).unwrap(), results);
    assert_eq!(
        std::fs::read_to_string(out.join("report.md")).unwrap(),
        report
    );
    let msgs = second.messages.lock().unwrap().clone();
    assert_eq!(
        msgs.iter().filter(|m| m.ends_with("(cached)")).count(),
        6,
        "2 fits + 4 FE runs cached: {msgs:?}"
    );
    assert!(second.progress.lock().unwrap().is_empty());

    // An edit of the anova step: the FE runs are not computed again.
    std::fs::write(&m, manifest_text(dir.path(), 0.1)).unwrap();
    let third = Log::default();
    run_study(&m, Some(&out), &third).unwrap();
    assert!(third.progress.lock().unwrap().is_empty());
    let after = std::fs::read(out.join("results.json")).unwrap();
    assert_ne!(after, results, "alpha is in the analysis");
}

#[test]
fn new_steps_are_validated_naming_the_manifest_and_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let good = manifest_text(dir.path(), 0.05);
    let p = dir.path().join("m.toml");
    let check = |text: &str| -> String {
        let m = Manifest::parse(&p, text).unwrap();
        m.validate(&p).unwrap_err().to_string()
    };
    Manifest::parse(&p, &good).unwrap().validate(&p).unwrap();
    for (from, to, needle) in [
        (
            "calibration = \"compression\"",
            "calibration = \"compresion\"",
            "steps[1].predict (\"needle\").calibration: no step named \"compresion\"",
        ),
        (
            "calibration = \"compression\"",
            "calibration = \"table1\"",
            "not before this one",
        ),
        (
            "models = [\"nh-axi\", \"nh-3d\", \"rp-axi\", \"rp-3d\"]",
            "models = [\"nh-axi\", \"nh\"]",
            "does not predict data set",
        ),
        (
            "[models.rp-3d.n3_needle]\nlaw = \"reduced-polynomial:2\"",
            "[models.rp-3d.n3_needle]\nlaw = \"yeoh\"",
            "fits no model of that law",
        ),
        (
            "nh-3d = \"3D\", rp-axi",
            "rp-axi",
            "steps[2].anova (\"table1\").factors.space: no level for model \"nh-3d\"",
        ),
        (
            "predictions = \"needle\"",
            "predictions = \"compression\"",
            "is a calibrate step; expected a predict step",
        ),
        (
            "alpha = 0.05",
            "alpha = 5",
            "steps[2].anova (\"table1\").alpha",
        ),
        (
            "published = \"",
            "published = \"nowhere/",
            "steps[2].anova (\"table1\").published: no such file",
        ),
    ] {
        assert!(good.contains(from), "{from}");
        let e = check(&good.replacen(from, to, 1));
        assert!(e.contains("m.toml") && e.contains(needle), "{needle}: {e}");
    }
    // a misspelled field of a new step is refused with its line
    let e = Manifest::parse(&p, &good.replace("calibration =", "calibraton ="))
        .unwrap_err()
        .to_string();
    assert!(e.contains("m.toml") && e.contains("calibraton"), "{e}");
}
