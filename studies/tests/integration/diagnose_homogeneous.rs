//! `palpate diagnose --data TEST=FILE`: the gap diagnosis of a homogeneous
//! record, read through `palpate calibrate`'s reader, with the candidates its
//! kind offers. Seeded synthetic uniaxial records with known truth, and one
//! real file end to end.

use crate::common;
use common::Scratch;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

/// Neo-Hookean uniaxial nominal stress (MPa), P = 2 C10 (lambda - lambda^-2).
fn neo_hookean(c10: f64, stretch: f64) -> f64 {
    2.0 * c10 * (stretch - stretch.powi(-2))
}

/// A uniaxial tension record `stretch,stress_MPa` from 1 to 2 (150 rows) of
/// a neo-Hookean solid (C10 = 0.1 MPa) whose recorded stretch is off by
/// `d0` (lambda = recorded - d0), with Gaussian noise of SD 1 kPa.
fn record(d0: f64, seed: u64) -> String {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    let noise = Normal::new(0.0, 1e-3).unwrap();
    let mut s = String::from("stretch,stress_MPa\n");
    for i in 0..150 {
        let recorded = 1.0 + i as f64 / 149.0;
        let p = neo_hookean(0.1, recorded - d0) + noise.sample(&mut rng);
        let _ = writeln!(s, "{recorded:.6},{p:.6e}");
    }
    s
}

fn diagnose(s: &Scratch, args: &[&str]) -> serde_json::Value {
    let json = s.path("gap.json").display().to_string();
    let mut a = vec!["diagnose"];
    a.extend(args);
    a.extend(["--json", &json]);
    let o = s.run(&a);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

fn effects_tried(r: &serde_json::Value) -> Vec<String> {
    r["ranking"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["effect"].as_str().unwrap().to_string())
        .collect()
}

/// A planted stretch offset of 0.02 is found as `zero_offset`; on a
/// tension-only, untimed record the candidates are material_form and
/// zero_offset only (no asymmetry: one side of 1; no viscoelasticity: no time).
#[test]
fn a_planted_zero_offset_is_found() {
    let s = Scratch::new();
    let f = s.file("offset.csv", &record(0.02, 7));
    let data = format!("uniaxial={f}");
    let r = diagnose(&s, &["--data", &data, "--law", "neo-hookean"]);
    assert_eq!(r["verdict"], "zero_offset", "{r:#}");
    let mut tried = effects_tried(&r);
    tried.sort();
    assert_eq!(tried, ["material_form", "zero_offset"], "{r:#}");
}

/// A plain record from the base law itself gets `none`.
#[test]
fn a_record_of_the_base_law_gets_none() {
    let s = Scratch::new();
    let f = s.file("plain.csv", &record(0.0, 11));
    let data = format!("uniaxial={f}");
    let r = diagnose(&s, &["--data", &data, "--law", "neo-hookean"]);
    assert_eq!(r["verdict"], "none", "{r:#}");
}

/// A real record (Budday et al. 2017, cortex, compression and tension)
/// is diagnosed end to end; spanning both sides of stretch 1 it is offered
/// tension_compression_asymmetry.
#[test]
fn a_real_brain_record_is_diagnosed_end_to_end() {
    let s = Scratch::new();
    let f = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/real/brain_budday2017/cortex_compression_tension.csv");
    let data = format!("uniaxial={}", f.display());
    let r = diagnose(&s, &["--data", &data, "--law", "neo-hookean"]);
    assert!(r["verdict"].is_string(), "{r:#}");
    assert!(
        effects_tried(&r).contains(&"tension_compression_asymmetry".to_string()),
        "{r:#}"
    );
}

/// A simple-shear record goes through the same reader, its options included;
/// a kind that offers no candidate for the law says so.
#[test]
fn simple_shear_records_and_empty_candidate_lists() {
    let s = Scratch::new();
    let mut text = String::from("amount_of_shear,shear_stress_MPa\n");
    for i in 0..40 {
        let g = 0.2 * i as f64 / 39.0;
        let _ = writeln!(text, "{g},{}", 2.0 * 0.1 * g * (1.0 + 0.3 * g * g));
    }
    let f = s.file("shear.csv", &text);
    let data = format!("simple_shear[axial_stretch=0.9]={f}");
    let r = diagnose(&s, &["--data", &data, "--law", "neo-hookean"]);
    assert_eq!(effects_tried(&r), ["material_form"], "{r:#}");
    let o = s.run(&["diagnose", "--data", &data, "--law", "mooney-rivlin"]);
    common::refused(&o, &["shear.csv", "no candidate effect"]);
}
