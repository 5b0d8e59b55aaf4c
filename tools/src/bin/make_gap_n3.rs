//! Writes the `modelling_space` development records of `tests/data/gap-n3/`
//! (used by `gap_fe_effects -- n3` and
//! `tests/integration/gap_fe_effects.rs`): needle indentation (docs/benchmarks.md N1/N3
//! needle, neo-Hookean C10 1e-3 MPa, frictionless, bonded base) to 6 mm
//! every 0.25 mm (25 samples), plus Gaussian noise of a fraction of the
//! largest force from a fixed seed:
//!
//! * `n3-3d` (noise 1 %) and `n3-3d-precise` (0.3 %, the same noiseless
//!   run): made by the 3D model (N3, the quarter of a 70 x 80 x 80 mm
//!   block, mesh level 1) — records the axisymmetric N1 base (a cylinder of
//!   radius 35 mm) should call `modelling_space` where the difference is
//!   visible;
//! * `n3-axisymmetric` (1 %): made by the axisymmetric model on the
//!   MEDIUM mesh (the base runs on the COARSE one) — a null record for the
//!   same candidates.
//!
//! `expected` is decided from the noiseless record before any diagnosis:
//! the base model (N1, COARSE mesh) fitted by its least-squares C10 (exact:
//! the model is homogeneous in C10), and the RMS of what is left in noise
//! SDs — at 1 SD or more the planted effect, below 0.4 SD (the diagnosis's
//! materiality threshold) `none`, between `borderline`.
//!
//! `cargo run --release -p palpate-tools --bin make_gap_n3` (one 3D run,
//! about a minute of CPU). The records are committed; rerun only to change
//! them.

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{MeshDensity, N1Needle, N3Needle};
use palpate_material::Law;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

/// A record: name, generator, its noiseless forces, noise fraction of the
/// peak, seed, planted effect.
type Case<'a> = (
    &'a str,
    &'a dyn ForwardModel,
    &'a [f64],
    f64,
    u64,
    Option<&'a str>,
);

fn main() {
    let dir = palpate_tools::repo("tests/data/gap-n3");
    std::fs::create_dir_all(&dir).expect("create data/gap-n3");
    let depths: Vec<f64> = (0..=24).map(|i| 0.25 * i as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths.clone());
    let c10 = 1.0e-3;
    let mut base = N1Needle::new(Law::NeoHookean);
    base.friction = 0.0;
    base.mesh = MeshDensity::COARSE;
    let base_f = base.predict(&[c10], &loading).expect("base run");
    let mut n3 = N3Needle::new(Law::NeoHookean);
    n3.friction = 0.0;
    let mut medium = N1Needle::new(Law::NeoHookean);
    medium.friction = 0.0;
    medium.mesh = MeshDensity::MEDIUM;
    let f_3d = n3.predict(&[c10], &loading).expect("3D record");
    let f_medium = medium.predict(&[c10], &loading).expect("MEDIUM record");
    // (name, generator, its noiseless forces, noise fraction, seed, effect)
    let cases: [Case; 3] = [
        ("n3-3d", &n3, &f_3d, 0.01, 31, Some("modelling_space")),
        (
            "n3-3d-precise",
            &n3,
            &f_3d,
            0.003,
            33,
            Some("modelling_space"),
        ),
        ("n3-axisymmetric", &medium, &f_medium, 0.01, 32, None),
    ];
    let mut entries = Vec::new();
    for (name, model, f, fraction, seed, effect) in cases {
        let peak = f.iter().cloned().fold(0.0, f64::max);
        let sd = fraction * peak;
        let a = f.iter().zip(&base_f).map(|(y, b)| y * b).sum::<f64>()
            / base_f.iter().map(|b| b * b).sum::<f64>();
        let rms = (f
            .iter()
            .zip(&base_f)
            .map(|(y, b)| (y - a * b).powi(2))
            .sum::<f64>()
            / f.len() as f64)
            .sqrt();
        let size = rms / sd;
        let expected = match effect {
            Some(e) if size >= 1.0 => e,
            _ if size < 0.4 => "none",
            _ => "borderline",
        };
        let noise = Normal::new(0.0, sd).expect("sd");
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut csv = format!(
            "# synthetic needle record (tools/src/bin/make_gap_n3.rs): {}, C10 {c10} MPa, \
             noise sd {sd:.3e} N ({} % of peak, seed {seed})\ndisplacement_mm,force_N\n",
            model.name(),
            100.0 * fraction
        );
        for (d, v) in depths.iter().zip(f) {
            let _ = writeln!(csv, "{d},{:.6e}", v + noise.sample(&mut rng));
        }
        std::fs::write(dir.join(format!("{name}.csv")), csv).expect("write record");
        entries.push(format!(
            "  \"{name}\": {{\"generator\": \"{}\", \"base_model\": \"N1 neo-Hookean, frictionless, \
             bonded, COARSE mesh\", \"effects\": [{}], \"params\": {{\"C10_MPa\": {c10}}}, \
             \"noise_sd_N\": {sd:.6e}, \"c10_ratio_of_base_fit\": {a:.4}, \
             \"visible_rms_in_sd\": {size:.3}, \"expected\": \"{expected}\"}}",
            model.name(),
            effect.map_or(String::new(), |e| format!("\"{e}\""))
        ));
        eprintln!("{name}: peak {peak:.4} N, sd {sd:.2e} N, base C10 factor {a:.4}, visible {size:.2} SD -> {expected}");
    }
    std::fs::write(
        dir.join("truth.json"),
        format!("{{\n{}\n}}\n", entries.join(",\n")),
    )
    .expect("write truth.json");
}
