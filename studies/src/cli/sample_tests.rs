//! Unit tests of `sample.rs`.

use super::*;
use serde_json::Value;
use std::path::Path;

/// `palpate sample` on C1 with a neo-Hookean law, a record that does not
/// exist and every other option at its default: the tests change what
/// they try.
fn c1_args() -> Args {
    Args {
        law: Some("neo-hookean".into()),
        data: vec!["x.csv".into()],
        reading: Default::default(),
        benchmark: Some("C1".into()),
        experiment: None,
        boxes: vec![],
        mesh: None,
        bulk: None,
        friction: None,
        prony: None,
        edge_radius: None,
        design: None,
        holdout: None,
        cache: None,
        max_draws: None,
        sampler: "nuts".into(),
        draws: None,
        tune: None,
        chains: None,
        seed: 0,
        sigma: None,
        ar1: false,
        prior: vec![],
        json: None,
        chains_out: None,
        evidence: false,
        plot: None,
        hierarchical: false,
    }
}

#[test]
fn samples_c1_and_writes_json_csv_and_plots() {
    let data =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/mcmc_c1_rp2_data.csv");
    let dir = tempfile::tempdir().unwrap();
    let json_path = dir.path().join("post.json");
    let args = Args {
        law: Some("reduced-polynomial:2".into()),
        data: vec![data.display().to_string()],
        max_draws: Some(300),
        sampler: "demc".into(),
        draws: Some(300),
        tune: Some(300),
        chains: Some(2),
        seed: 3,
        prior: vec!["C10=lognormal:-7.3,1".into()],
        json: Some(json_path.clone()),
        chains_out: Some(dir.path().join("chains.csv")),
        plot: Some(dir.path().join("figs")),
        ..c1_args()
    };
    run(args).unwrap();
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    for name in ["C10", "C20", "sigma"] {
        for key in [
            "mean",
            "sd",
            "hdi_3",
            "hdi_97",
            "rhat",
            "ess_bulk",
            "ess_tail",
            "mcse_mean",
        ] {
            assert!(v["params"][name][key].is_number(), "{name}.{key}");
        }
    }
    assert_eq!(v["params"]["C10"]["prior"], "lognormal:-7.3,1");
    assert!(v["evaluations"].as_u64().unwrap() > 0 && v["wall_time_s"].as_f64().unwrap() > 0.0);
    let c10 = v["params"]["C10"]["mean"].as_f64().unwrap();
    assert!((c10 / 6.8e-4 - 1.0).abs() < 0.05, "{c10}");
    let csv = std::fs::read_to_string(dir.path().join("chains.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 6 * 300);
    assert!(dir.path().join("figs/corner.svg").exists());
    assert!(dir.path().join("figs/predictive_C1.svg").exists());
}

#[test]
fn bad_options_are_named() {
    let args = |sampler: &str, prior: &str| Args {
        sampler: sampler.into(),
        prior: vec![prior.into()],
        ..c1_args()
    };
    let e = options(&args("gibbs", "")).unwrap_err().to_string();
    assert!(e.contains("gibbs"), "{e}");
    let e = run(args("nuts", "C10=flat")).unwrap_err().to_string();
    assert!(e.contains("x.csv"), "{e}");
    let data =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/mcmc_c1_rp2_data.csv");
    let mut a = args("nuts", "C10=flat");
    a.data = vec![data.display().to_string()];
    a.evidence = true;
    let e = run(a).unwrap_err().to_string();
    assert!(e.contains("--evidence needs a proper prior"), "{e}");
}
