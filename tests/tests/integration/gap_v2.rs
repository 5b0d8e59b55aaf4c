//! Gap diagnosis v2 on the development records of
//! `tests/data/gap-v2/` (seeded, with truth; written by
//! `tools/src/bin/make_gap_v2.rs`), one group per weakness of the first version:
//!
//! 1. a true effect must not be rejected by its own cross-validation: fast
//!    ramp, long hold, two-term relaxation -> `viscoelasticity` on every
//!    record; with v1's contiguous blocks the same records lose it to a weak
//!    rival, which the report must call a partial explanation;
//! 2. tiny but significant misfits (800 samples, AR(1) noise, an offset of
//!    0.01-0.02 mm) -> `none`, the detectable effects listed as `immaterial`;
//!    with the materiality threshold at 0 (v1) the offset is named;
//! 3. undetectable is not harmless: an offset of 0.1 mm under heavy noise
//!    (C1) and friction 0.8 at a needle (N1, MEDIUM-mesh data, coarse base)
//!    -> `none`, and `undetectable` shows the base C10 moving over the
//!    effect's plausible range, the truth inside that range.

use palpate_analytic::C1Compression;
use palpate_core::{Drive, Effect, Loading, Table};
use palpate_fe::{MeshDensity, N1Needle};
use palpate_material::Law;
use palpate_uq::gap::{diagnose, FoldLayout, GapOptions, GapReport};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/gap-v2")
}

fn truth() -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir().join("truth.json")).unwrap()).unwrap()
}

fn record(name: &str) -> (Loading, Vec<f64>) {
    let table = Table::read(dir().join(format!("{name}.csv"))).unwrap();
    let d = table.column("displacement_mm").unwrap().to_vec();
    let f = table.column("force_N").unwrap().to_vec();
    let loading = match table.column("time_s") {
        Ok(t) => Loading::timed(Drive::DisplacementMm, t.to_vec(), d),
        Err(_) => Loading::quasi_static(Drive::DisplacementMm, d),
    };
    (loading, f)
}

fn c1(name: &str, options: &GapOptions) -> GapReport {
    let (loading, f) = record(name);
    diagnose(&C1Compression::new(Law::NeoHookean), &loading, &f, options).unwrap()
}

fn names(prefix: &str) -> Vec<String> {
    let t = truth();
    let mut v: Vec<String> = t
        .as_object()
        .unwrap()
        .keys()
        .filter(|k| k.starts_with(prefix))
        .cloned()
        .collect();
    v.sort();
    v
}

#[test]
fn weakness_1_relaxation_is_not_rejected_by_its_own_cross_validation() {
    let cases = names("w1-");
    assert!(cases.len() >= 5);
    let contiguous = GapOptions {
        fold_layout: FoldLayout::Contiguous,
        ..GapOptions::default()
    };
    let reports: Vec<(String, GapReport, GapReport)> = cases
        .par_iter()
        .map(|n| (n.clone(), c1(n, &GapOptions::default()), c1(n, &contiguous)))
        .collect();
    let t = truth();
    let mut v1_wrong = 0;
    for (name, r, old) in &reports {
        let sd = t[name.as_str()]["noise_sd_N"].as_f64().unwrap();
        assert_eq!(r.verdict, "viscoelasticity", "{name}: {}", r.explanation);
        let best = &r.ranking[0];
        assert!(best.earns && best.practical.material, "{name}");
        assert!(
            best.heldout_after < 1.15 * sd && best.misfit_after < 1.1 * sd,
            "{name}: held-out {} misfit {} for noise {sd}",
            best.heldout_after,
            best.misfit_after
        );
        assert!(r.partly_explained.is_none(), "{name}: {}", r.explanation);
        // v1's contiguous blocks: where the verdict goes elsewhere, the rival
        // leaves the misfit far above the noise and the report says that the
        // gap is only partly explained, and by how much.
        if old.verdict != "viscoelasticity" {
            v1_wrong += 1;
            let partly = old.partly_explained.as_ref().unwrap_or_else(|| {
                panic!("{name}: v1 verdict {} not flagged partial", old.verdict)
            });
            assert!(partly.misfit_over_noise_after > 1.5 && partly.excess_explained < 0.5);
            assert!(
                old.explanation.contains("only partly explained"),
                "{}",
                old.explanation
            );
        }
    }
    // The records reproduce the weakness: v1's folds lose the effect on some.
    assert!(v1_wrong >= 1, "no record reproduces weakness 1");
}

#[test]
fn weakness_2_tiny_significant_misfits_are_detectable_but_immaterial() {
    let cases = names("w2-");
    assert!(cases.len() >= 3);
    let v1 = GapOptions {
        materiality: 0.0,
        ..GapOptions::default()
    };
    let reports: Vec<(String, GapReport, GapReport)> = cases
        .par_iter()
        .map(|n| (n.clone(), c1(n, &GapOptions::default()), c1(n, &v1)))
        .collect();
    for (name, r, old) in &reports {
        assert!(r.base.gap_significant, "{name}: {}", r.base.reason);
        assert_eq!(r.verdict, "none", "{name}: {}", r.explanation);
        assert!(
            r.immaterial.contains(&Effect::ZeroOffset),
            "{name}: immaterial {:?}",
            r.immaterial
        );
        assert!(r.explanation.contains("detectable but immaterial"));
        // every immaterial effect earns its parameters and removes a small
        // systematic component; misfit/noise barely moves
        for e in &r.immaterial {
            let entry = r.ranking.iter().find(|x| x.effect == *e).unwrap();
            let size = &entry.practical;
            assert!(entry.earns && !size.material && size.removed_over_noise < 0.4);
            assert!(size.misfit_over_noise_before - size.misfit_over_noise_after < 0.1);
        }
        let json = serde_json::to_value(r).unwrap();
        assert_eq!(json["verdict"], "none");
        assert!(json["immaterial"]
            .as_array()
            .unwrap()
            .iter()
            .any(|e| e == "zero_offset"));
        // v1 (no materiality threshold) names the offset.
        assert_eq!(old.verdict, "zero_offset", "{name}: {}", old.explanation);
    }
}

/// `undetectable` entry of `effect`: the C10 values at both ends.
fn c10_range(r: &GapReport, effect: Effect, name: &str) -> [f64; 2] {
    let u = r
        .undetectable
        .iter()
        .find(|u| u.effect == effect)
        .unwrap_or_else(|| panic!("{name}: no undetectable {effect}: {:?}", r.undetectable));
    u.base_params["C10"]
}

#[test]
fn weakness_3_an_undetected_offset_shows_how_far_it_moves_c10() {
    let t = truth();
    for name in names("w3-c1-") {
        let r = c1(&name, &GapOptions::default());
        assert_eq!(r.verdict, "none", "{name}: {}", r.explanation);
        let u = r
            .undetectable
            .iter()
            .find(|u| u.effect == Effect::ZeroOffset)
            .unwrap();
        assert_eq!(u.param, "d0_mm");
        assert_eq!(u.range, [-0.1, 0.1]);
        let truth_c10 = t[name.as_str()]["params"]["C10_MPa"].as_f64().unwrap();
        let d0 = t[name.as_str()]["params"]["offset_mm"].as_f64().unwrap();
        assert_eq!(d0, 0.1, "the planted offset is the upper end");
        let [lo, hi] = c10_range(&r, Effect::ZeroOffset, &name);
        // the end at the planted offset recovers C10; the base fit does not
        assert!(
            (hi / truth_c10 - 1.0).abs() < 0.05,
            "{name}: C10 at d0 = 0.1 is {hi}, planted {truth_c10}"
        );
        assert!((hi - lo).abs() / truth_c10 > 0.1, "{name}: {lo} .. {hi}");
        let base = r.base.params["C10"];
        assert!((base / truth_c10 - 1.0).abs() > 0.05, "{name}: base {base}");
        assert!(r.to_markdown().contains("Effects the record cannot see"));
    }
}

#[test]
fn weakness_3_undetected_needle_friction_shows_how_far_it_moves_c10() {
    let name = "w3-n1-friction";
    let (loading, f) = record(name);
    let mut base = N1Needle::new(Law::NeoHookean);
    base.friction = 0.0;
    base.mesh = MeshDensity::COARSE;
    let options = GapOptions {
        effects: Some(vec![Effect::Friction]),
        ..GapOptions::default()
    };
    let r = diagnose(&base, &loading, &f, &options).unwrap();
    assert_eq!(r.verdict, "none", "{}", r.explanation);
    let t = truth();
    let truth_c10 = t[name]["params"]["C10_MPa"].as_f64().unwrap();
    // the frictionless fit is within the noise but C10 is biased high
    let fitted = r.base.params["C10"];
    assert!(fitted / truth_c10 > 1.05, "base C10 {fitted}");
    let u = &r.undetectable[0];
    assert_eq!((u.effect, u.param.as_str()), (Effect::Friction, "friction"));
    assert_eq!(u.range, [0.0, 0.8]);
    let [lo, hi] = u.base_params["C10"];
    assert!(
        (lo / fitted - 1.0).abs() < 0.01,
        "friction 0 is the base fit"
    );
    assert!(
        (hi / truth_c10 - 1.0).abs() < 0.05,
        "C10 at friction 0.8: {hi}, planted {truth_c10}"
    );
    assert!(u.relative_shift["C10"] < -0.05, "{u:?}");
}
