//! C1 parameter recovery (docs/benchmarks.md C1, materials `ecoflex-nh` and
//! `ecoflex-rp2`): synthetic force-displacement curves from the analytic C1
//! model, 0..2 mm at 0.4 mm/s, 200 samples, fitted back by
//! Levenberg-Marquardt through `dyn ForwardModel`.

use palpate_analytic::C1Compression;
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_inverse::{fit, DataSet, FitOptions, Objective, ResidualKind};
use palpate_material::Law;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::sync::Arc;

const PA: f64 = 1e-6; // MPa

fn loading() -> Loading {
    let d: Vec<f64> = (0..200).map(|i| 2.0 * i as f64 / 199.0).collect();
    let t = d.iter().map(|d| d / 0.4).collect();
    Loading::timed(Drive::DisplacementMm, t, d)
}

fn cases() -> Vec<(Law, Vec<(&'static str, f64)>)> {
    vec![
        (Law::NeoHookean, vec![("C10", 1101.295 * PA)]),
        (
            Law::ReducedPolynomial(2),
            vec![("C10", 686.428 * PA), ("C20", 1929.606 * PA)],
        ),
    ]
}

fn synthetic(law: Law, truth: &[f64], noise: Option<u64>) -> DataSet {
    let model: Arc<dyn ForwardModel> = Arc::new(C1Compression::new(law));
    let loading = loading();
    let mut force = model.predict(truth, &loading).unwrap();
    if let Some(seed) = noise {
        // 2 % multiplicative Gaussian noise, one seeded stream per curve.
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let normal = Normal::new(0.0, 0.02).unwrap();
        for f in force.iter_mut() {
            *f *= 1.0 + normal.sample(&mut rng);
        }
    }
    DataSet::new("C1", model, loading, force)
}

#[test]
fn noise_free_curves_are_recovered_to_1e_6() {
    for (law, truth) in cases() {
        let theta: Vec<f64> = truth.iter().map(|t| t.1).collect();
        for residual in [ResidualKind::Absolute, ResidualKind::Relative] {
            let objective =
                Objective::new(vec![synthetic(law, &theta, None)], residual, &[]).unwrap();
            let r = fit(&objective, &FitOptions::default()).unwrap();
            assert!(r.converged, "{law} {residual}: {:?}", r.termination);
            for (name, t) in &truth {
                let v = r.value(name).unwrap();
                assert!(
                    (v / t - 1.0).abs() < 1e-6,
                    "{law} {residual}: {name} = {v} vs {t}"
                );
            }
            assert!(
                r.identifiability.identifiable,
                "{law}: {:?}",
                r.identifiability
            );
        }
    }
}

#[test]
fn noisy_curves_are_recovered_within_three_standard_errors() {
    // Relative residuals match multiplicative noise (equal variance), so
    // sigma^2 (J^T J)^-1 is the right covariance.
    for (law, truth) in cases() {
        let theta: Vec<f64> = truth.iter().map(|t| t.1).collect();
        for seed in [1, 2, 3] {
            let set = synthetic(law, &theta, Some(seed));
            let objective = Objective::new(vec![set], ResidualKind::Relative, &[]).unwrap();
            let r = fit(&objective, &FitOptions::default()).unwrap();
            assert!(r.converged, "{law}: {:?}", r.termination);
            // sigma estimates the 2 % noise.
            let sigma = r.sigma2.unwrap().sqrt();
            assert!(
                (sigma / 0.02 - 1.0).abs() < 0.15,
                "{law} seed {seed}: sigma {sigma}"
            );
            for (name, t) in &truth {
                let (v, se) = (r.value(name).unwrap(), r.standard_error(name).unwrap());
                assert!(se > 0.0 && se < 0.2 * t, "{law}: {name} se {se}");
                assert!(
                    (v - t).abs() < 3.0 * se,
                    "{law} seed {seed}: {name} = {v} +- {se} vs {t}"
                );
            }
        }
    }
}
