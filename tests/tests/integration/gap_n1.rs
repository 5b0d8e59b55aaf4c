//! Sim-to-real gap diagnosis on benchmark N1: the finite-element
//! needle model as the base (neo-Hookean, frictionless needle, bonded base,
//! coarse mesh), on the synthetic withheld-effect records of
//! `tests/data/gap-n1/` (written by `tools/src/bin/make_gap_n1.rs` on the MEDIUM
//! mesh, so the data do not share the base model's discretisation):
//!
//! * planted friction 0.5 -> verdict `friction`, friction within 3 standard
//!   errors and inside its 95 % profile-likelihood interval, which excludes
//!   a frictionless needle; held-out misfit within 20 % of the noise SD;
//! * no effect -> `none`;
//! * a sliding base (0.6-1.1 % less force, almost uniformly: absorbed by C10)
//!   -> `none`, the effect too weak to see at 0.5 % noise.
//!
//! * the friction record with `material_form` as the rival candidate: the
//!   two are reported as confounded (a stiffening law bends one force-depth
//!   curve as friction does), not one picked.
//!
//! The candidates are GAP.md's N1 effects (friction, boundary_condition),
//! the CLI's default for N1. The diagnosis runs the FE model some 60 times
//! per record (a minute of CPU in the dev profile): the four diagnoses run in
//! parallel.

use palpate_core::{Drive, Effect, Loading, Table};
use palpate_fe::{MeshDensity, N1Needle};
use palpate_material::Law;
use palpate_uq::gap::{diagnose, GapOptions, GapReport};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/gap-n1")
}

fn diagnose_case(name: &str, effects: &[Effect]) -> GapReport {
    let table = Table::read(dir().join(format!("{name}.csv"))).unwrap();
    let d = table.column("displacement_mm").unwrap().to_vec();
    let f = table.column("force_N").unwrap().to_vec();
    let loading = Loading::quasi_static(Drive::DisplacementMm, d);
    let mut base = N1Needle::new(Law::NeoHookean);
    base.friction = 0.0;
    base.mesh = MeshDensity::COARSE;
    let options = GapOptions {
        effects: Some(effects.to_vec()),
        ..GapOptions::default()
    };
    diagnose(&base, &loading, &f, &options).unwrap()
}

/// GAP.md's N1 candidates (the CLI's default for N1).
const N1_EFFECTS: [Effect; 2] = [Effect::Friction, Effect::BoundaryCondition];

#[test]
fn n1_records_get_the_expected_verdicts() {
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir().join("truth.json")).unwrap()).unwrap();
    let names: Vec<String> = truth.as_object().unwrap().keys().cloned().collect();
    assert_eq!(names.len(), 3);
    // The three records with the N1 candidates, and the friction record
    // once more with a stiffening law as a rival candidate.
    let mut jobs: Vec<(String, Vec<Effect>)> = names
        .iter()
        .map(|n| (n.clone(), N1_EFFECTS.to_vec()))
        .collect();
    jobs.push((
        "n1-friction".into(),
        vec![Effect::Friction, Effect::MaterialForm],
    ));
    let mut reports: Vec<(String, GapReport)> = jobs
        .par_iter()
        .map(|(n, e)| (n.clone(), diagnose_case(n, e)))
        .collect();
    let rival = reports.pop().unwrap().1;
    // On one force-depth curve friction and a stiffening C20 bend the curve
    // alike (both fit to the noise): reported as confounded, not picked.
    assert!(
        ["friction", "material_form"].contains(&rival.verdict.as_str()),
        "{}",
        rival.explanation
    );
    let other = if rival.verdict == "friction" {
        "material_form"
    } else {
        "friction"
    };
    assert_eq!(rival.confounded, [other], "{}", rival.explanation);
    assert!(!rival.ranking[0].identifiable);
    for (name, r) in &reports {
        let t = &truth[name.as_str()];
        let expected = t["expected"].as_str().unwrap();
        assert_eq!(r.verdict, expected, "{name}: {}", r.explanation);
        let sd = t["noise_sd_N"].as_f64().unwrap();
        assert!(
            (r.noise_sd / sd - 1.0).abs() < 0.35,
            "{name}: noise {} for {sd}",
            r.noise_sd
        );
        if expected == "none" {
            continue;
        }
        let best = &r.ranking[0];
        assert_eq!(best.effect, expected);
        assert!(
            best.heldout_after <= 1.2 * sd,
            "{name}: held-out {} for noise {sd}",
            best.heldout_after
        );
        assert!(best.misfit_before > 1.5 * best.misfit_after, "{name}");
        if expected == "friction" {
            let planted = t["params"]["friction"].as_f64().unwrap();
            let value = best.params["friction"];
            let se = best.standard_errors["friction"].expect("a standard error");
            assert!(
                (value - planted).abs() <= 3.0 * se,
                "{name}: friction {value} +- {se}, planted {planted}"
            );
            // the friction effect saturates as the contact sticks (a large
            // standard error), but the profile likelihood bounds it below
            // and contains the planted value
            let profile = best.profile.iter().find(|p| p.param == "friction").unwrap();
            let lower = profile.lower.expect("friction bounded below");
            assert!(
                lower > 0.1 && lower < planted && profile.upper.is_none_or(|u| u > planted),
                "{name}: {}, planted {planted}",
                profile.describe()
            );
        }
    }
}
