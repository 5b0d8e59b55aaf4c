//! N1 mesh convergence on a cheap pair (palpate-fe, docs/benchmarks.md N1,
//! neo-Hookean `ecoflex-nh`, friction 0.8): the coarse (level 1, 864
//! elements) and medium (level 2, 3286 elements) meshes agree within 0.5 %
//! at 2 mm (0.36 %), and both agree with the CalculiX reference within its error budget
//! (tests/data/calculix/README.md: mesh 0.3 %, penalty contact
//! 0.4-0.8 % low). The full study on three meshes to 10 mm (observed order,
//! extrapolated force) is `tools/src/bin/convergence_n1.rs`, numbers in
//! docs/validation/fe.md.

use std::path::Path;

use palpate_core::{Drive, ForwardModel, Loading, Table};
use palpate_fe::{MeshDensity, N1Needle};

const C10: f64 = 1101.295e-6;

fn forces(level: usize, at: &[f64]) -> Vec<f64> {
    let mut m = N1Needle::new("neo-hookean".parse().unwrap());
    m.mesh = MeshDensity { level };
    m.predict(
        &[C10],
        &Loading::quasi_static(Drive::DisplacementMm, at.to_vec()),
    )
    .unwrap()
}

fn calculix(at: f64) -> f64 {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/calculix/n1/n1_nh_f0.8_k1000_n6.csv");
    let t = Table::read(&p).unwrap();
    let (x, y) = (
        t.column("displacement_mm").unwrap(),
        t.column("force_N").unwrap(),
    );
    let k = x.iter().position(|&v| v >= at).unwrap();
    let w = (at - x[k - 1]) / (x[k] - x[k - 1]);
    y[k - 1] + w * (y[k] - y[k - 1])
}

#[test]
fn coarse_and_medium_n1_meshes_agree_to_half_a_percent() {
    let at = [2.0];
    let coarse = forces(1, &at);
    let medium = forces(2, &at);
    for ((d, c), m) in at.iter().zip(&coarse).zip(&medium) {
        let change = (c - m) / m;
        assert!(change.abs() < 0.005, "at {d} mm: coarse {c} medium {m}");
        let ccx = calculix(*d);
        for f in [c, m] {
            assert!(
                ((f - ccx) / ccx).abs() < 0.015,
                "at {d} mm: FE {f} vs CalculiX {ccx}"
            );
        }
    }
}
