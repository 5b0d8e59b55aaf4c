//! Prints N1 and C1 forces for the regression record.
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{Bulk, C1Fe, MeshDensity, N1Needle, Platens, Support};

fn main() {
    let nh: palpate_material::Law = "neo-hookean".parse().unwrap();
    let rp: palpate_material::Law = "reduced-polynomial:2".parse().unwrap();
    let d: Vec<f64> = (1..=12).map(|k| 0.5 * k as f64).collect();
    let load = Loading::quasi_static(Drive::DisplacementMm, d);
    let mut cases: Vec<(String, Box<dyn ForwardModel>, Vec<f64>)> = Vec::new();
    for (fr, bulk, base, law, p) in [
        (0.8, Bulk::Exact, Support::Bonded, nh, vec![0.001101295]),
        (0.0, Bulk::Exact, Support::Bonded, nh, vec![0.001101295]),
        (
            0.8,
            Bulk::Ratio(1000.0),
            Support::Bonded,
            rp,
            vec![0.0011, 0.0002],
        ),
        (0.3, Bulk::Exact, Support::Sliding, nh, vec![0.001101295]),
    ] {
        let mut m = N1Needle::new(law);
        m.friction = fr;
        m.bulk = bulk;
        m.base = base;
        m.mesh = MeshDensity::COARSE;
        cases.push((format!("n1 {fr} {bulk:?} {base:?} {law}"), Box::new(m), p));
    }
    for (pl, bulk) in [
        (Platens::Frictionless, Bulk::Exact),
        (Platens::Bonded, Bulk::Exact),
        (Platens::Bonded, Bulk::Ratio(1000.0)),
    ] {
        let mut m = C1Fe::new(rp, pl);
        m.bulk = bulk;
        cases.push((
            format!("c1 {pl:?} {bulk:?}"),
            Box::new(m),
            vec![0.0011, 0.0002],
        ));
    }
    let c1load = Loading::quasi_static(Drive::DisplacementMm, vec![0.5, 1.0, 2.0, 1.5, 0.5]);
    for (name, m, p) in &cases {
        let l = if name.starts_with("c1") {
            &c1load
        } else {
            &load
        };
        let f = m.predict(p, l).unwrap();
        println!(
            "{name}: {}",
            f.iter()
                .map(|v| format!("{v:.15e}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}
