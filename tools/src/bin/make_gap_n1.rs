//! Writes the synthetic N1 withheld-effect records of `tests/data/gap-n1/`
//! (used by `tests/integration/gap_n1.rs`): N1 needle indentation (docs/benchmarks.md) to
//! 6 mm, every 0.25 mm, simulated on the MEDIUM mesh (so the coarse-mesh base
//! model of the diagnosis does not share its discretisation), plus Gaussian
//! noise of a stated fraction of the largest force, from a fixed seed.
//!
//! `cargo run --release -p palpate-tools --bin make_gap_n1` (about a
//! minute). The records are committed; rerun only to change them.

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{MeshDensity, N1Needle, Support};
use palpate_material::Law;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

struct Case {
    name: &'static str,
    c10: f64,
    friction: f64,
    base: Support,
    noise_fraction: f64,
    seed: u64,
    effects: &'static [&'static str],
    expected: &'static str,
}

fn main() {
    let cases = [
        Case {
            name: "n1-friction",
            c10: 1.2e-3,
            friction: 0.5,
            base: Support::Bonded,
            noise_fraction: 0.01,
            seed: 11,
            effects: &["friction"],
            expected: "friction",
        },
        Case {
            name: "n1-none",
            c10: 0.9e-3,
            friction: 0.0,
            base: Support::Bonded,
            noise_fraction: 0.01,
            seed: 12,
            effects: &[],
            expected: "none",
        },
        Case {
            name: "n1-sliding",
            c10: 1.0e-3,
            friction: 0.0,
            base: Support::Sliding,
            noise_fraction: 0.005,
            seed: 13,
            effects: &["boundary_condition"],
            // the sliding base lowers the force by 0.6-1.1 % almost
            // uniformly: a change of C10, not of shape, so too weak to see
            expected: "none",
        },
    ];
    let dir = palpate_tools::repo("tests/data/gap-n1");
    std::fs::create_dir_all(&dir).expect("create data/gap-n1");
    let depths: Vec<f64> = (0..=24).map(|i| 0.25 * i as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths.clone());
    let mut truth = String::from("{\n");
    for (k, c) in cases.iter().enumerate() {
        let mut m = N1Needle::new(Law::NeoHookean);
        m.friction = c.friction;
        m.base = c.base;
        m.mesh = MeshDensity::MEDIUM;
        let f = m.predict(&[c.c10], &loading).expect("N1 simulation");
        let fmax = f.iter().cloned().fold(0.0, f64::max);
        let sd = c.noise_fraction * fmax;
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(c.seed);
        let noise = Normal::new(0.0, sd).expect("noise sd");
        let mut csv = format!(
            "# synthetic N1 record (tools/src/bin/make_gap_n1.rs): neo-Hookean C10 = {} MPa, \
             friction {}, {:?} base, MEDIUM mesh, noise sd {:.3e} N (seed {})\n\
             displacement_mm,force_N\n",
            c.c10, c.friction, c.base, sd, c.seed
        );
        for (d, v) in depths.iter().zip(&f) {
            let _ = writeln!(csv, "{d:.4},{:.6e}", v + noise.sample(&mut rng));
        }
        std::fs::write(dir.join(format!("{}.csv", c.name)), csv).expect("write record");
        let effects: Vec<String> = c.effects.iter().map(|e| format!("\"{e}\"")).collect();
        let _ = writeln!(
            truth,
            "  \"{}\": {{\"benchmark\": \"N1\", \"base_model\": \"neo-Hookean, frictionless needle, bonded base\", \
             \"effects\": [{}], \"params\": {{\"C10_MPa\": {}, \"friction\": {}, \"base\": \"{:?}\"}}, \
             \"noise_sd_N\": {sd:.6e}, \"expected\": \"{}\"}}{}",
            c.name,
            effects.join(", "),
            c.c10,
            c.friction,
            c.base,
            c.expected,
            if k + 1 < cases.len() { "," } else { "" }
        );
        eprintln!("{}: F(6 mm) = {:.4} N, noise sd {:.2e} N", c.name, fmax, sd);
    }
    truth.push_str("}\n");
    std::fs::write(dir.join("truth.json"), truth).expect("write truth.json");
}
