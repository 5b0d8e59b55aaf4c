//! `palpate sample --experiment` and `palpate doe --experiment` on the
//! gel disc (`studies/experiments/gel-disc.toml`, a 2.5 mm sphere on a
//! bonded 10 mm layer), meshed coarse (4-node elements at level 1) for a
//! record to 0.5 mm: the posterior through the description's surrogate
//! holds the truth, a design whose factor is the description's parameter
//! scores each level against a reference, and options or fields the
//! description holds are refused by name.

use crate::common::{refused, Scratch};

const GEL: &str = include_str!("../../experiments/gel-disc.toml");
const MESH: &str = "\n[mesh]\nlevel = 1\nelement = \"quad4\"\n";
const TRUTH: f64 = 5.0e-3;

/// The gel disc's force at [`TRUTH`] on 10 depths to 0.5 mm, on the mesh a
/// command sizes for that record (a ramp to 0.5 mm), with noise of `noise`
/// times the largest force (alternating signs, deterministic).
fn record(noise: f64) -> String {
    let text = format!("{GEL}{MESH}\n[protocol]\nsegments = [{{ ramp_to = 0.5 }}]\n");
    let depths: Vec<f64> = (1..=10).map(|k| 0.05 * k as f64).collect();
    let f = crate::common::experiment_forces(&text, &[TRUTH], &depths);
    let top = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut csv = String::from("displacement_mm,force_N\n");
    for (k, (d, f)) in depths.iter().zip(&f).enumerate() {
        let e = if k % 2 == 0 { noise } else { -noise };
        csv += &format!("{d},{:.12e}\n", f + e * top);
    }
    csv
}

/// The posterior of C10 through the surrogate of the described model
/// (8 training runs, 3 held out), its 94 % HDI holding the truth.
#[test]
fn sample_takes_an_experiment() {
    let s = Scratch::new();
    let gel = s.file("gel.toml", &format!("{GEL}{MESH}"));
    let data = s.file("rec.csv", &record(0.01));
    let json = s.path("post.json").display().to_string();
    let cache = s.path("cache").display().to_string();
    let o = s.run(&[
        "sample",
        "--experiment",
        &gel,
        "--data",
        &format!("force={data}"),
        "--box",
        "C10=0.002,0.01",
        "--design",
        "8",
        "--holdout",
        "3",
        "--cache",
        &cache,
        "--draws",
        "300",
        "--max-draws",
        "300",
        "--tune",
        "300",
        "--json",
        &json,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let p = &v["params"]["C10"];
    let (lo, hi) = (p["hdi_3"].as_f64().unwrap(), p["hdi_97"].as_f64().unwrap());
    assert!(lo < TRUTH && TRUTH < hi, "C10 94 % HDI [{lo}, {hi}]");
    assert!(hi - lo < 0.2 * TRUTH, "C10 94 % HDI [{lo}, {hi}]");
    assert!(v["surrogate"]["model"]
        .as_str()
        .unwrap()
        .contains("Experiment"));
    // the settings the description holds are not options
    let o = s.run(&[
        "sample",
        "--experiment",
        &gel,
        "--data",
        &data,
        "--box",
        "C10=0.002,0.01",
        "--friction",
        "0.3",
    ]);
    refused(&o, &["--friction", "tool.friction"]);
    let o = s.run(&[
        "sample",
        "--experiment",
        &gel,
        "--data",
        &data,
        "--law",
        "neo-hookean",
    ]);
    refused(&o, &["--law", "--experiment"]);
}

/// A design over the description's C10: each run simulates the
/// experiment, scored against a reference made at the truth; a factor that
/// is not one of its parameters, and N1's settings, are refused.
#[test]
fn doe_takes_an_experiment() {
    let s = Scratch::new();
    let gel = s.file("gel.toml", &format!("{GEL}{MESH}"));
    s.file("ref.csv", &record(0.0));
    let manifest = |factor: &str, levels: &str, extra: &str| {
        format!(
            "[[factors]]\nname = \"{factor}\"\nlevels = {levels}\n\n\
             [response.simulation]\nmetric = \"rms\"\nreference = \"ref.csv\"\n{extra}"
        )
    };
    let m = s.file("doe.toml", &manifest("C10", "[\"3e-3\", \"5e-3\"]", ""));
    let out = s.path("out").display().to_string();
    let o = s.run(&["doe", "--manifest", &m, "--experiment", &gel, "--out", &out]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(s.path("out/design.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    assert_eq!(rows.len(), 2, "{csv}");
    let rms = |level: &str| -> f64 {
        let r = rows.iter().find(|r| r.iter().any(|c| c == level)).unwrap();
        r.last().unwrap().parse().unwrap()
    };
    // the truth's run reproduces the reference; the other misses it
    assert!(rms("3e-3") > 0.0, "{csv}");
    assert!(rms("5e-3") < 1e-6 * rms("3e-3"), "{csv}");
    let bad = s.file("bad.toml", &manifest("friction", "[\"0\", \"0.3\"]", ""));
    refused(
        &s.run(&["doe", "--manifest", &bad, "--experiment", &gel]),
        &["factor `friction`", "C10"],
    );
    let bad = s.file(
        "bad2.toml",
        &manifest("C10", "[\"3e-3\", \"5e-3\"]", "law = \"yeoh\"\n"),
    );
    refused(
        &s.run(&["doe", "--manifest", &bad, "--experiment", &gel]),
        &["response.simulation.law", "--experiment"],
    );
}
