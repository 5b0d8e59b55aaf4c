//! Prints, as CSV, the FE curve of the Hertz table of docs/validation/fe.md
//! ("Hertz"): a rigid sphere of radius 2.5 mm pressed frictionlessly into
//! the N1 cylinder of neo-Hookean `ecoflex-nh`, mesh graded from 0.04 mm
//! over 1.2 mm, depths 0.025 .. 0.25 mm, with the force's relative
//! difference from Hertz's and Sneddon's incompressible half-space forces
//! (the formulas and the assertions are in
//! `forward/fe/tests/integration/hertz.rs`).
//!
//! `cargo run --release -p palpate-tools --bin hertz_fe_curve`

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::{N1Needle, ToolShape};

const C10: f64 = 1101.295e-6;
const MU: f64 = 2.0 * C10;
const R: f64 = 2.5;

/// Hertz (paraboloid) force of an incompressible half-space, E* = 4 mu.
fn hertz(d: f64) -> f64 {
    16.0 / 3.0 * MU * R.sqrt() * d.powf(1.5)
}

/// Sneddon's exact-sphere force of an incompressible half-space, E* = 4 mu
/// (the contact radius by bisection of `d = (a/2) ln((R+a)/(R-a))`).
fn sneddon(d: f64) -> f64 {
    let depth_of = |a: f64| 0.5 * a * ((R + a) / (R - a)).ln();
    let (mut lo, mut hi) = (0.0, R * (1.0 - 1e-12));
    for _ in 0..200 {
        let a = 0.5 * (lo + hi);
        if depth_of(a) > d {
            hi = a;
        } else {
            lo = a;
        }
    }
    let a = 0.5 * (lo + hi);
    let l = ((R + a) / (R - a)).ln();
    0.5 * 4.0 * MU * ((a * a + R * R) * l - 2.0 * a * R)
}

fn main() {
    let depths: Vec<f64> = (1..=10).map(|k| 0.025 * k as f64).collect();
    let mut m = N1Needle::new("neo-hookean".parse().expect("law"));
    m.tool = ToolShape::Sphere { radius: R };
    m.friction = 0.0;
    m.grading = Some(Grading {
        h_fine: 0.04,
        fine_length: 1.2,
        growth: 1.3,
    });
    m.options.first_step = depths[0] / 2.0;
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths.clone());
    let f = match m.predict(&[C10], &loading) {
        Ok(f) => f,
        Err(e) => {
            eprintln!("hertz_fe_curve: {e}");
            std::process::exit(1);
        }
    };
    println!("depth_mm,force_N,fe_over_hertz_minus_1,fe_over_sneddon_minus_1");
    for (d, f) in depths.iter().zip(&f) {
        println!(
            "{d:.4},{f:.9e},{:.5},{:.5}",
            f / hertz(*d) - 1.0,
            f / sneddon(*d) - 1.0
        );
    }
}
