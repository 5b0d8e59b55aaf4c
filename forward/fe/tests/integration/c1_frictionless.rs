//! C1 with frictionless platens: the FE force equals the analytic
//! (homogeneous, incompressible) C1 force, docs/benchmarks.md materials.

use palpate_analytic::C1Compression;
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{C1Fe, Platens};
use palpate_material::Law;

fn check(law: &str, theta: &[f64]) {
    let law: Law = law.parse().unwrap();
    let loading = Loading::quasi_static(
        Drive::DisplacementMm,
        (1..=8).map(|k| 0.25 * k as f64).collect(),
    );
    let mut fe = C1Fe::new(law, Platens::Frictionless);
    fe.elements = (4, 2);
    let f_fe = fe.predict(theta, &loading).unwrap();
    let f_an = C1Compression::new(law).predict(theta, &loading).unwrap();
    for (a, b) in f_fe.iter().zip(&f_an) {
        assert!(((a - b) / b).abs() < 1e-6, "FE {a} vs analytic {b}");
    }
}

#[test]
fn frictionless_c1_equals_analytic_neo_hookean() {
    check("neo-hookean", &[1101.295e-6]);
}

#[test]
fn frictionless_c1_equals_analytic_reduced_polynomial() {
    check("reduced-polynomial:2", &[686.428e-6, 1929.606e-6]);
}
