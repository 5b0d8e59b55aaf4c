//! The forward models built on the composable FE layer reproduce the forces
//! of the original axisymmetric solver (commit 55dd440, recorded with
//! `forward/fe/examples/regress_forces.rs` there, now
//! `tools/src/bin/regress_forces.rs`) to 1e-9 relative: N1 on the
//! coarse mesh (friction 0.8 exactly incompressible neo-Hookean; K = 1000 mu
//! reduced polynomial) at 0.5..6 mm, C1 frictionless and bonded, exact and
//! K = 1000 mu, on a ramp-and-unload.

// recorded digits, as printed
#![allow(clippy::excessive_precision)]

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{Bulk, C1Fe, MeshDensity, N1Needle, Platens, Support};

fn check(name: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{name}");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        let rel = (g - w).abs() / w.abs();
        assert!(
            rel < 1e-9,
            "{name} sample {k}: {g} vs recorded {w} ({rel:.2e})"
        );
    }
}

#[test]
fn n1_forces_equal_the_original_solver() {
    let d: Vec<f64> = (1..=12).map(|k| 0.5 * k as f64).collect();
    let load = Loading::quasi_static(Drive::DisplacementMm, d);
    let mut m = N1Needle::new("neo-hookean".parse().unwrap());
    m.mesh = MeshDensity::COARSE;
    check(
        "n1 nh f0.8 exact",
        &m.predict(&[0.001101295], &load).unwrap(),
        &NH_08,
    );
    let mut m = N1Needle::new("reduced-polynomial:2".parse().unwrap());
    m.mesh = MeshDensity::COARSE;
    m.bulk = Bulk::Ratio(1000.0);
    m.base = Support::Bonded;
    check(
        "n1 rp2 f0.8 K1000",
        &m.predict(&[0.0011, 0.0002], &load).unwrap(),
        &RP_K1000,
    );
}

#[test]
fn c1_forces_equal_the_original_solver() {
    let load = Loading::quasi_static(Drive::DisplacementMm, vec![0.5, 1.0, 2.0, 1.5, 0.5]);
    let law = "reduced-polynomial:2".parse().unwrap();
    for (platens, bulk, want) in [
        (Platens::Frictionless, Bulk::Exact, C1_FRICTIONLESS),
        (Platens::Bonded, Bulk::Exact, C1_BONDED),
        (Platens::Bonded, Bulk::Ratio(1000.0), C1_BONDED_K1000),
    ] {
        let mut m = C1Fe::new(law, platens);
        m.bulk = bulk;
        let f = m.predict(&[0.0011, 0.0002], &load).unwrap();
        check(&format!("c1 {platens:?} {bulk:?}"), &f, &want);
    }
}

const NH_08: [f64; 12] = [
    6.235069375999396e-3,
    1.711794755707938e-2,
    3.029837426932246e-2,
    4.552277835707701e-2,
    6.216627293390574e-2,
    7.973581602605545e-2,
    9.763350322543859e-2,
    1.174047937824550e-1,
    1.369567508057985e-1,
    1.563454650831366e-1,
    1.774677920760318e-1,
    1.989885485425335e-1,
];
const RP_K1000: [f64; 12] = [
    6.287812473380327e-3,
    1.732484768274605e-2,
    3.090036360004905e-2,
    4.706482169054164e-2,
    6.468727466778668e-2,
    8.409957281426453e-2,
    1.040871281555728e-1,
    1.264216879470078e-1,
    1.495290644922184e-1,
    1.733386401134888e-1,
    1.984456350277413e-1,
    2.253390749878755e-1,
];
const C1_FRICTIONLESS: [f64; 5] = [
    4.423254024897879e-1,
    9.536911055789256e-1,
    2.323938036521765e0,
    1.565649886080379e0,
    4.423254026092688e-1,
];
const C1_BONDED: [f64; 5] = [
    1.506758278910594e0,
    3.502130256221830e0,
    1.095356691097979e1,
    6.409511955900922e0,
    1.506758279016787e0,
];
const C1_BONDED_K1000: [f64; 5] = [
    1.493950772068315e0,
    3.465765977608521e0,
    1.074625487886219e1,
    6.321331618182239e0,
    1.493950772069128e0,
];
