//! N3 (BENCHMARKS.md): the 3D quarter block with the needle. Fast checks on
//! coarse meshes at small depth (docs/validation/fe.md, "N3").

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::{n3_grading, N1Needle, N3Needle, ToolShape};

const C10: f64 = 1101.295e-6;
const MU: f64 = 2.0 * C10;

fn nh() -> palpate_material::Law {
    "neo-hookean".parse().unwrap()
}

fn quasi_static(depths: &[f64]) -> Loading {
    Loading::quasi_static(Drive::DisplacementMm, depths.to_vec())
}

/// Sneddon's exact-sphere force on an incompressible half-space
/// (E* = 4 mu; tests/hertz.rs has the derivation).
fn sneddon(r: f64, d: f64) -> f64 {
    let depth_of = |a: f64| 0.5 * a * ((r + a) / (r - a)).ln();
    let (mut lo, mut hi) = (0.0, r * (1.0 - 1e-12));
    for _ in 0..200 {
        let a = 0.5 * (lo + hi);
        if depth_of(a) > d {
            hi = a;
        } else {
            lo = a;
        }
    }
    let a = 0.5 * (lo + hi);
    let l = ((r + a) / (r - a)).ln();
    0.5 * 4.0 * MU * ((a * a + r * r) * l - 2.0 * a * r)
}

/// A frictionless sphere of radius 10 mm at 0.25 and 0.5 mm (a / R = 0.16
/// and 0.22) on the N3 block, 0.4 mm hexahedra over 3 mm growing by 1.5.
#[test]
fn frictionless_sphere_against_sneddon() {
    let r = 10.0;
    let depths = [0.25, 0.5];
    let mut m = N3Needle::new(nh());
    m.tool = ToolShape::Sphere { radius: r };
    m.friction = 0.0;
    m.grading = Some(Grading {
        h_fine: 0.4,
        fine_length: 3.0,
        growth: 1.5,
    });
    m.options.first_step = 0.125;
    let f = m.predict(&[C10], &quasi_static(&depths)).unwrap();
    let dev: Vec<f64> = depths
        .iter()
        .zip(&f)
        .map(|(d, f)| f / sneddon(r, *d) - 1.0)
        .collect();
    eprintln!("N3 sphere: {f:?}, / Sneddon - 1 = {dev:?}");
    assert!(dev.iter().all(|e| e.abs() < 0.05), "{dev:?}");
}

/// N3 against N1 with the needle at 1 and 2 mm, friction 0.8, both on
/// the level-1 N3 grading (0.8 mm elements over 4 mm).
#[test]
fn n3_against_n1() {
    let depths = [1.0, 2.0];
    let g = n3_grading(1);
    let n3 = N3Needle::new(nh());
    let f3 = n3.predict(&[C10], &quasi_static(&depths)).unwrap();
    let mut n1 = N1Needle::new(nh());
    n1.grading = Some(g);
    let f1 = n1.predict(&[C10], &quasi_static(&depths)).unwrap();
    let mut n1_fine = N1Needle::new(nh());
    n1_fine.mesh = palpate_fe::MeshDensity::MEDIUM;
    let f1f = n1_fine.predict(&[C10], &quasi_static(&depths)).unwrap();
    let rel: Vec<f64> = f3.iter().zip(&f1).map(|(a, b)| a / b - 1.0).collect();
    let relf: Vec<f64> = f3.iter().zip(&f1f).map(|(a, b)| a / b - 1.0).collect();
    eprintln!("N3 {f3:?} N1 same grading {f1:?} N1 level 2 {f1f:?}: N3/N1 - 1 = {rel:?}, N3/N1(level 2) - 1 = {relf:?}");
}

/// A needle that starts inside the block and a negative friction are
/// refused with the reason, before any solve; so is a depth the block
/// cannot take.
#[test]
fn bad_input_is_named() {
    let loading = quasi_static(&[0.5]);
    let mut m = N3Needle::new(nh());
    m.start_gap = -0.5;
    let e = m.predict(&[C10], &loading).unwrap_err().to_string();
    assert!(e.contains("starts inside the body"), "{e}");
    let mut m = N3Needle::new(nh());
    m.friction = -0.1;
    let e = m.predict(&[C10], &loading).unwrap_err().to_string();
    assert!(e.contains("friction") && e.contains(">= 0"), "{e}");
    let m = N3Needle::new(nh());
    let e = match m.simulate(&[C10], &quasi_static(&[10.0, 45.0]), None) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("a 45 mm depth was accepted"),
    };
    assert!(e.contains("beyond what the 80 mm block allows"), "{e}");
}
