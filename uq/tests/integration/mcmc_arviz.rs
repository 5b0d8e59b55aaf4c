//! The diagnostics agree with ArviZ on fixed chains.
//!
//! `docs/validation/mcmc_arviz.py` generated the chains and ArviZ's
//! summary of them (`mcmc_arviz.json`); every number is recomputed here.

use palpate_uq::mcmc::{diagnostics, hdi, summarize, Chains};
use std::path::Path;

#[test]
fn diagnostics_match_arviz_to_1e_6() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/validation/mcmc_arviz.json");
    let text = std::fs::read_to_string(&path).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let vars = json["variables"].as_object().unwrap();
    assert_eq!(vars.len(), 5);
    for (name, v) in vars {
        let chains: Vec<Vec<f64>> = serde_json::from_value(v["chains"].clone()).unwrap();
        let flat: Vec<f64> = chains.iter().flatten().copied().collect();
        let nested: Vec<Vec<Vec<f64>>> = chains
            .iter()
            .map(|c| c.iter().map(|&x| vec![x]).collect())
            .collect();
        let s = &summarize(&Chains::from_nested(&nested), std::slice::from_ref(name))[0];
        let (lo, hi) = hdi(&flat, 0.94);
        let ours = [
            ("mean", s.mean),
            ("sd", s.sd),
            ("hdi_3", lo),
            ("hdi_97", hi),
            ("mcse_mean", s.mcse_mean),
            ("ess_bulk", s.ess_bulk),
            ("ess_tail", s.ess_tail),
            ("rhat", s.rhat),
            ("ess_mean", diagnostics::ess_mean(&chains)),
        ];
        for (key, value) in ours {
            let reference = v[key].as_f64().unwrap();
            let rel = (value - reference).abs() / reference.abs().max(1e-12);
            let tol = if key == "mean" {
                1e-6 * s.sd / reference.abs().max(1e-12)
            } else {
                1e-6
            };
            assert!(
                rel < tol.max(1e-6),
                "{name} {key}: ours {value} arviz {reference} (rel {rel:e})"
            );
        }
    }
}
