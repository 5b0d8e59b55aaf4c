//! Every analytic model kind, and the FE C1 model with bonded and with
//! frictionless platens (the cheapest FE model: the FE models share one
//! `ForwardModel` and `Enrichable` implementation, so one stands for the
//! scaffolding of all), runs through `Box<dyn ForwardModel>` (as studies hold
//! them), every declared enrichment (every analytic model declares some; FE
//! C1 declares none) can be built and reproduces its base at the "effect
//! off" point, and evaluation in parallel threads gives
//! bit-identical predictions to serial evaluation.

use palpate_analytic::{C1Compression, Homogeneous, Mode};
use palpate_core::enrichable::{effects_of, embed, enrich};
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{C1Fe, Platens};
use palpate_material::Law;
use rayon::prelude::*;

fn c1_loading() -> Loading {
    let t: Vec<f64> = (0..=50).map(|i| i as f64 * 0.1).collect();
    let d: Vec<f64> = t
        .iter()
        .map(|&t| if t <= 5.0 { 0.4 * t } else { 2.0 })
        .collect();
    Loading::timed(Drive::DisplacementMm, t, d)
}

fn stretch_loading() -> Loading {
    // Timed, so that the viscoelastic enrichment applies too.
    Loading::timed(
        Drive::Stretch,
        (0..=30).map(|i| 0.1 * i as f64).collect(),
        (0..=30).map(|i| 0.7 + 0.05 * i as f64).collect(),
    )
}

fn analytic_models() -> Vec<(Box<dyn ForwardModel>, Loading)> {
    let mut v: Vec<(Box<dyn ForwardModel>, Loading)> = Vec::new();
    for law in [
        "neo-hookean",
        "mooney-rivlin",
        "yeoh",
        "arruda-boyce",
        "ogden:2",
    ] {
        let law: Law = law.parse().unwrap();
        v.push((Box::new(C1Compression::new(law)), c1_loading()));
        for mode in [Mode::Uniaxial, Mode::Equibiaxial, Mode::Planar] {
            v.push((Box::new(Homogeneous::new(law, mode)), stretch_loading()));
        }
    }
    v
}

/// The analytic models, then C1 by finite elements on its default 19 x 9
/// mesh, compressed 0.4 mm in two timed samples (timed, so that the
/// viscoelastic enrichment applies too).
fn models() -> Vec<(Box<dyn ForwardModel>, Loading)> {
    let mut v = analytic_models();
    let law: Law = "neo-hookean".parse().unwrap();
    for platens in [Platens::Bonded, Platens::Frictionless] {
        let loading = Loading::timed(Drive::DisplacementMm, vec![0.5, 1.0], vec![0.2, 0.4]);
        v.push((Box::new(C1Fe::new(law, platens)), loading));
    }
    v
}

#[test]
fn every_model_predicts_through_the_trait_object() {
    for (m, loading) in models() {
        let theta = m.space().initial();
        let f = m
            .predict(&theta, &loading)
            .unwrap_or_else(|e| panic!("{}: {e}", m.name()));
        assert_eq!(f.len(), loading.len());
        assert!(f.iter().all(|v| v.is_finite()), "{}", m.name());
        // A loaded sample gives a non-zero response.
        assert!(f.iter().any(|v| v.abs() > 0.0), "{}", m.name());
    }
}

#[test]
fn every_declared_enrichment_is_off_at_its_embedding() {
    // every analytic model has the capability, reached through the trait object
    for (m, _) in analytic_models() {
        assert!(m.as_enrichable().is_some(), "{}", m.name());
    }
    for (m, loading) in models() {
        if m.as_enrichable().is_none() {
            continue; // FE C1: nothing declared
        }
        let theta = m.space().initial();
        let base = m.predict(&theta, &loading).unwrap();
        for effect in effects_of(m.as_ref()) {
            let enriched = enrich(m.as_ref(), effect)
                .unwrap_or_else(|e| panic!("{} + {effect}: {e}", m.name()));
            let off = embed(enriched.as_ref(), &theta);
            assert_eq!(off.len(), enriched.space().len(), "{} + {effect}", m.name());
            let f = enriched
                .predict(&off, &loading)
                .unwrap_or_else(|e| panic!("{} + {effect}: {e}", m.name()));
            for (a, b) in f.iter().zip(&base) {
                assert!(
                    (a - b).abs() <= 1e-9 * b.abs().max(1e-12),
                    "{} + {effect}: {a} vs {b}",
                    m.name()
                );
            }
        }
    }
}

#[test]
fn parallel_and_serial_evaluation_are_bit_identical() {
    let models = models();
    let thetas: Vec<Vec<f64>> = (0..8)
        .map(|k| {
            let m = &models[0].0;
            m.space()
                .initial()
                .iter()
                .map(|v| v * (1.0 + 0.05 * k as f64))
                .collect()
        })
        .collect();
    for (m, loading) in &models {
        let thetas: Vec<Vec<f64>> = thetas
            .iter()
            .map(|t| {
                m.space()
                    .initial()
                    .iter()
                    .zip(t.iter().cycle())
                    .map(|(a, b)| a * b / t[0])
                    .collect()
            })
            .collect();
        let serial: Vec<Vec<f64>> = thetas
            .iter()
            .map(|t| m.predict(t, loading).unwrap())
            .collect();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let parallel: Vec<Vec<f64>> = pool.install(|| {
            thetas
                .par_iter()
                .map_init(
                    || m.evaluator(),
                    |ev, t| {
                        let mut out = vec![0.0; loading.len()];
                        ev.predict_into(t, loading, &mut out).unwrap();
                        out
                    },
                )
                .collect()
        });
        for (a, b) in serial.iter().zip(&parallel) {
            assert!(
                a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{}",
                m.name()
            );
        }
    }
}
