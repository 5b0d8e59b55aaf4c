//! `palpate sample` on finite-element benchmarks through the cached
//! surrogate, and sampling until converged. Cheap models: the coarse N1 mesh
//! to 3 mm, Q1 to 0.1 mm with a 10-sample history.

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_studies::model::{build, Mesh, ModelSpec, N1NeedleSpec, Q1Spec};
use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

fn palpate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_palpate"))
        .args(args)
        .output()
        .expect("run palpate")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Fixed standard-normal deviates (seeded Box-Muller, written out so the
/// record does not depend on a random-number crate's version).
const NOISE: [f64; 12] = [
    0.496, -1.372, 0.212, 1.031, -0.640, -0.127, 1.718, -0.904, 0.355, -0.289, 0.802, -1.150,
];

/// Writes `model`'s curve at `theta` plus 1 % of the peak force of noise.
fn record(model: &dyn ForwardModel, theta: &[f64], loading: &Loading, path: &Path) {
    let f = model.predict(theta, loading).unwrap();
    let peak = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut s = String::new();
    if loading.time.is_some() {
        s.push_str("time_s,");
    }
    s.push_str("displacement_mm,force_N\n");
    for (i, v) in f.iter().enumerate() {
        if let Some(t) = &loading.time {
            s.push_str(&format!("{},", t[i]));
        }
        s.push_str(&format!(
            "{},{:.9e}\n",
            loading.drive[i],
            v + 0.01 * peak * NOISE[i % NOISE.len()]
        ));
    }
    std::fs::write(path, s).unwrap();
}

/// Mooney-Rivlin on N1 (coarse mesh, friction 0.8, 4 mm): the surrogate
/// (12 training + 3 held-out FE runs) is within 0.5 % of the peak force on
/// the held-out runs, the posterior covers the truth, a second run reuses
/// the cached surrogate and gives the same posterior.
#[test]
fn n1_posterior_through_a_cached_surrogate() {
    let dir = tempfile::tempdir().unwrap();
    let truth = [6e-4, 3e-4];
    let spec = ModelSpec::N1Needle(N1NeedleSpec {
        law: "mooney-rivlin".into(),
        mesh: Some(Mesh::Level(1)),
        ..Default::default()
    });
    let model = build(&spec).unwrap();
    let loading = Loading::quasi_static(
        Drive::DisplacementMm,
        (0..=8).map(|i| 0.5 * i as f64).collect(),
    );
    let rec = dir.path().join("n1.csv");
    record(model.as_ref(), &truth, &loading, &rec);
    let cache = dir.path().join("cache");
    let post = dir.path().join("post.json");
    let chains = dir.path().join("chains.csv");
    let args = |out: &Path| {
        vec![
            "sample".to_string(),
            "--benchmark".into(),
            "N1".into(),
            "--law".into(),
            "mooney-rivlin".into(),
            "--data".into(),
            rec.display().to_string(),
            "--box".into(),
            "C10=0.0003,0.0009".into(),
            "--box".into(),
            "C01=0,0.0006".into(),
            "--design".into(),
            "12".into(),
            "--holdout".into(),
            "3".into(),
            "--cache".into(),
            cache.display().to_string(),
            "--json".into(),
            out.display().to_string(),
            "--chains".into(),
            chains.display().to_string(),
        ]
    };
    let a = args(&post);
    let o = palpate(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("surrogate built from 15 FE runs"),
        "{}",
        stderr(&o)
    );
    let v = json(&post);
    let s = &v["surrogate"];
    assert_eq!(s["cache"], "built");
    assert_eq!(s["held_out_runs"], 3);
    let err = s["max_rel_error"].as_f64().unwrap();
    assert!(err < 5e-3, "held-out error {err}");
    assert!(v["convergence"]["converged"].as_bool().unwrap());
    for (k, name) in ["C10", "C01"].iter().enumerate() {
        let p = &v["params"][name];
        let (lo, hi) = (p["hdi_3"].as_f64().unwrap(), p["hdi_97"].as_f64().unwrap());
        assert!(lo < truth[k] && truth[k] < hi, "{name}: {lo} .. {hi}");
    }
    // C10 and C01 trade off (correlation near -1); their sum, the
    // small-strain shear modulus / 2, is what the curve fixes: within 3 %.
    let text = std::fs::read_to_string(&chains).unwrap();
    let sums: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<f64> = l.split(',').skip(2).map(|x| x.parse().unwrap()).collect();
            f[0] + f[1]
        })
        .collect();
    let mean = sums.iter().sum::<f64>() / sums.len() as f64;
    assert!((mean / 9e-4 - 1.0).abs() < 0.03, "C10 + C01 = {mean}");

    // Second run: the cache is hit, no FE run, the same posterior.
    let post2 = dir.path().join("post2.json");
    let a = args(&post2);
    let o = palpate(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("loaded from the cache"),
        "{}",
        stderr(&o)
    );
    let w = json(&post2);
    assert_eq!(w["surrogate"]["cache"], "hit");
    assert_eq!(w["surrogate"]["key"], s["key"]);
    assert_eq!(w["params"]["C10"]["mean"], v["params"]["C10"]["mean"]);
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 1);
}

/// A box that misses the posterior is reported as truncating it; bad boxes
/// are refused by name.
#[test]
fn the_box_is_checked_and_its_edge_reported() {
    let dir = tempfile::tempdir().unwrap();
    let spec = ModelSpec::N1Needle(N1NeedleSpec {
        law: "neo-hookean".into(),
        mesh: Some(Mesh::Level(1)),
        ..Default::default()
    });
    let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.5, 1.0, 1.5]);
    let rec = dir.path().join("n1.csv");
    record(build(&spec).unwrap().as_ref(), &[1e-3], &loading, &rec);
    let cache = dir.path().join("cache");
    let run = |b: &[&str]| {
        let mut a = vec![
            "sample",
            "--benchmark",
            "N1",
            "--law",
            "neo-hookean",
            "--data",
            rec.to_str().unwrap(),
            "--design",
            "5",
            "--holdout",
            "2",
            "--draws",
            "500",
            "--cache",
            cache.to_str().unwrap(),
        ];
        a.extend_from_slice(b);
        palpate(&a)
    };
    // Truth 1e-3 outside [4e-4, 8e-4]: the posterior piles up at the edge.
    let o = run(&["--box", "C10=0.0004,0.0008"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("posterior of C10 reaches the edge of the surrogate's box"),
        "{}",
        stderr(&o)
    );
    for (b, says) in [
        (vec![], "--box C10="),
        (vec!["--box", "C10=0.002,0.001"], "lower < upper"),
        (vec!["--box", "C10=-0.001,0.001"], "model's bounds"),
        (vec!["--box", "mu=0,1"], "unknown parameter `mu`"),
        (vec!["--box", "C10=0.001"], "NAME=LO,HI"),
    ] {
        let o = run(&b);
        assert!(
            !o.status.success() && stderr(&o).contains(says),
            "{b:?}: {}",
            stderr(&o)
        );
        assert!(!stderr(&o).contains("panicked"));
    }
    // FE options without an FE benchmark, or of another one.
    let o = palpate(&[
        "sample",
        "--benchmark",
        "C1",
        "--law",
        "neo-hookean",
        "--data",
        "x.csv",
        "--box",
        "C10=0,1",
    ]);
    assert!(
        stderr(&o).contains("--box: an option of --benchmark N1, N3, Q1"),
        "{}",
        stderr(&o)
    );
    let o = run(&["--box", "C10=0.0005,0.002", "--prony", "g1=0.3,tau1=1"]);
    assert!(
        stderr(&o).contains("--benchmark N1 does not use it"),
        "{}",
        stderr(&o)
    );
}

/// Q1: a timed ramp-and-hold record (neo-Hookean, Prony series held fixed),
/// sampled through the surrogate; a record without times is refused.
#[test]
fn q1_ramp_and_hold_through_the_surrogate() {
    let dir = tempfile::tempdir().unwrap();
    let spec = ModelSpec::Q1(Q1Spec {
        law: "neo-hookean".into(),
        mesh: Some(Mesh::Level(1)),
        prony: Some("g1=0.3,tau1=1".parse().unwrap()),
        ..Default::default()
    });
    let time = vec![0.0, 0.125, 0.25, 0.375, 0.5, 1.0, 1.5, 2.5, 3.5, 5.0];
    let drive: Vec<f64> = time
        .iter()
        .map(|t: &f64| 0.1 * (t / 0.5).min(1.0))
        .collect();
    let loading = Loading::timed(Drive::DisplacementMm, time, drive);
    let rec = dir.path().join("q1.csv");
    record(build(&spec).unwrap().as_ref(), &[1e-3], &loading, &rec);
    let post = dir.path().join("post.json");
    let o = palpate(&[
        "sample",
        "--benchmark",
        "Q1",
        "--law",
        "neo-hookean",
        "--prony",
        "g1=0.3,tau1=1",
        "--data",
        rec.to_str().unwrap(),
        "--box",
        "C10=0.0005,0.002",
        "--design",
        "5",
        "--holdout",
        "2",
        "--cache",
        dir.path().join("cache").to_str().unwrap(),
        "--json",
        post.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&post);
    let p = &v["params"]["C10"];
    assert!(p["hdi_3"].as_f64().unwrap() < 1e-3 && 1e-3 < p["hdi_97"].as_f64().unwrap());
    assert!(v["surrogate"]["max_rel_error"].as_f64().unwrap() < 1e-3);
    // The same record without its time column.
    let text = std::fs::read_to_string(&rec).unwrap();
    let untimed: String = text
        .lines()
        .map(|l| l.split_once(',').unwrap().1.to_string() + "\n")
        .collect();
    let bare = dir.path().join("bare.csv");
    std::fs::write(&bare, untimed).unwrap();
    let o = palpate(&[
        "sample",
        "--benchmark",
        "Q1",
        "--law",
        "neo-hookean",
        "--data",
        bare.to_str().unwrap(),
        "--box",
        "C10=0.0005,0.002",
    ]);
    assert!(
        !o.status.success() && stderr(&o).contains("time_s"),
        "{}",
        stderr(&o)
    );
}

/// The ensemble sampler's defaults on the C1 reduced-polynomial record
/// stopped at R-hat 1.03: so the draws are doubled, with a line
/// per extension, until R-hat < 1.01 and bulk ESS >= 400; with a cap below
/// that, a warning says so and the JSON records it.
#[test]
fn sample_extends_until_converged() {
    let data =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/mcmc_c1_rp2_data.csv");
    let dir = tempfile::tempdir().unwrap();
    let post = dir.path().join("post.json");
    let base = [
        "sample",
        "--benchmark",
        "C1",
        "--law",
        "reduced-polynomial:2",
        "--data",
        data.to_str().unwrap(),
        "--sampler",
        "ensemble",
        "--json",
        post.to_str().unwrap(),
    ];
    let o = palpate(&base);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("after 2000 draws per chain max R-hat"), "{e}");
    assert!(e.contains("extending to 4000 draws per chain"), "{e}");
    let v = json(&post);
    let c = &v["convergence"];
    assert!(c["converged"].as_bool().unwrap(), "{c}");
    assert!(c["rhat_max"].as_f64().unwrap() < 1.01 && c["ess_bulk_min"].as_f64().unwrap() >= 400.0);
    for name in ["C10", "C20", "sigma"] {
        assert!(v["params"][name]["rhat"].as_f64().unwrap() < 1.01);
    }
    let mut capped = base.to_vec();
    capped.extend(["--max-draws", "2000"]);
    let o = palpate(&capped);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not converged at the cap of 2000 draws per chain"),
        "{}",
        stderr(&o)
    );
    assert!(!json(&post)["convergence"]["converged"].as_bool().unwrap());
    let mut bad = base.to_vec();
    bad.extend(["--draws", "100", "--max-draws", "50"]);
    let o = palpate(&bad);
    assert!(
        !o.status.success() && stderr(&o).contains("--max-draws 50"),
        "{}",
        stderr(&o)
    );
}
