//! Cost of one `Law::stress_tangent` call (what an FE quadrature point pays), per law.
//! Run: `cargo bench -p palpate-material --bench stress_tangent`. Prints a table, asserts nothing.

use std::hint::black_box;
use std::time::Instant;

use nalgebra::Matrix3;
use palpate_material::{homogeneous, stability, Law, Volumetric};

fn main() {
    let laws: Vec<(Law, Vec<f64>)> = vec![
        (Law::NeoHookean, vec![1.1e-3]),
        (Law::MooneyRivlin, vec![1e-3, 1e-4]),
        (Law::ReducedPolynomial(3), vec![1e-3, -1e-5, 1e-6]),
        (Law::ArrudaBoyce, vec![4.98e-3, 1.05]),
        (Law::Ogden(3), vec![0.40, 1.3, 0.003, 5.0, 0.0098, -2.0]),
    ];
    let f = Matrix3::new(1.1, 0.2, 0.0, -0.1, 0.9, 0.05, 0.0, 0.03, 1.05);
    let n = 200_000;
    let t = Instant::now();
    let mut acc0 = 0.0;
    for k in 0..n {
        let mut g = f;
        g[(0, 0)] += 1e-9 * k as f64;
        acc0 += black_box(nalgebra::SymmetricEigen::new(g.transpose() * g)).eigenvalues[0];
    }
    black_box(acc0);
    println!(
        "3x3 symmetric eigen-decomposition alone: {:.0} ns",
        t.elapsed().as_secs_f64() / n as f64 * 1e9
    );
    println!(
        "{:<22} {:>16} {:>16} {:>14}",
        "law", "stress_tangent", "uniaxial", "drucker"
    );
    for (law, p) in &laws {
        let vol = Volumetric::from_bulk_modulus(1000.0 * law.shear_modulus(p));
        let t0 = Instant::now();
        let mut acc = 0.0;
        for k in 0..n {
            let mut g = f;
            g[(0, 0)] += 1e-9 * k as f64;
            acc += black_box(law.stress_tangent(black_box(p), vol, &g)).a[(0, 0)];
        }
        let per_call = t0.elapsed().as_secs_f64() / n as f64;
        let t1 = Instant::now();
        for k in 0..n {
            acc += black_box(homogeneous::uniaxial(
                law,
                black_box(p),
                1.2 + 1e-9 * k as f64,
            ));
        }
        let per_uni = t1.elapsed().as_secs_f64() / n as f64;
        let t2 = Instant::now();
        let report = black_box(stability::drucker(law, p));
        let per_drucker = t2.elapsed().as_secs_f64();
        black_box(acc);
        println!(
            "{:<22} {:>13.0} ns {:>13.0} ns {:>11.2} ms   uniaxial stable in [{:.3}, {:.3}]",
            law.to_string(),
            per_call * 1e9,
            per_uni * 1e9,
            per_drucker * 1e3,
            report.uniaxial.lower,
            report.uniaxial.upper
        );
    }
}
