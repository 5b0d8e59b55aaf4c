//! Writes the synthetic records of the Mesa-Munera et al. (2011) source
//! study (`studies/mesa2011.toml`) into `tests/data/mesa2011/`:
//!
//! * `c1-compression.csv`: benchmark C1 (38 x 9 mm cylinder, lubricated,
//!   2 mm at 0.4 mm/s, sampled at 100 Hz: every 0.004 mm, 501 rows) made
//!   with `ecoflex-rp2` of docs/benchmarks.md (reduced polynomial N=2,
//!   C10 = 686.428 Pa, C20 = 1929.606 Pa; analytic, exact for lubricated
//!   platens) plus Gaussian noise of 0.5 % of the largest force. The
//!   neo-Hookean `ecoflex-nh` (C10 = 1101.295 Pa) is the least-squares
//!   neo-Hookean fit of that same curve over 0..2 mm (the continuous limit
//!   is 1101.34 Pa; on 501 samples 1102.25 Pa), so one record reproduces
//!   both materials.
//! * `needle-1.csv` .. `needle-3.csv`: needle-indentation records of "the
//!   phantom", three replicates, every 0.25 mm to 10 mm. They come from a
//!   model **richer than either prediction of the study**:
//!   - 3D (N3 quarter block, friction 0.8) on a finer mesh than the study's
//!     N3 (0.6 mm hexahedra under the needle, growth 1.3: 5,780 cells,
//!     24,500 unknowns, against level 1's 0.8 mm / 2,340 cells);
//!   - a richer law: Yeoh (reduced polynomial N=3) with ecoflex-rp2's C10
//!     and C20 and C30 = 100 Pa. In the compression test (I1 - 3 <= 0.18)
//!     the C30 term adds at most 0.7 % to the stress (at 2 mm), about the
//!     record's noise, so compression cannot tell it from RP2; under the
//!     needle tip the strains are far larger and it stiffens the material;
//!   - replicate-to-replicate variation: replicate r is
//!     `(1 + s_r) F(d - delta_r) + e`, with a stiffness factor
//!     `s_r ~ N(0, 0.03)` (three castings of a phantom), a zero offset of
//!     the depth `delta_r ~ N(0, 0.1 mm)` (surface detection; F = 0 above
//!     the surface, linear interpolation of the 0.25 mm curve) and noise
//!     `e ~ N(0, 0.5 % of the largest force)` on each sample.
//!
//! `truth.json` holds every value drawn. Seeds are fixed; the records are
//! committed, rerun only to change them:
//! `cargo run --release -p palpate-tools --bin make_mesa2011` (the fine
//! N3 run: about 5 min of CPU and 1.6 GiB).

use palpate_analytic::C1Compression;
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::N3Needle;
use palpate_material::Law;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

/// ecoflex-rp2 (docs/benchmarks.md), MPa.
const RP2: [f64; 2] = [686.428e-6, 1929.606e-6];
/// The phantom's Yeoh C30 (MPa).
const C30: f64 = 100e-6;

fn main() {
    let dir = palpate_tools::repo("tests/data/mesa2011");
    std::fs::create_dir_all(&dir).expect("create data/mesa2011");
    let mut truth = String::from("{\n");

    // --- C1 compression record ---
    let d: Vec<f64> = (0..=500).map(|i| 0.004 * i as f64).collect();
    let c1 = C1Compression::new(Law::ReducedPolynomial(2));
    let f = c1
        .predict(
            &RP2,
            &Loading::quasi_static(Drive::DisplacementMm, d.clone()),
        )
        .expect("C1");
    let fmax = f.iter().cloned().fold(0.0, f64::max);
    let sd = 0.005 * fmax;
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(2011);
    let noise = Normal::new(0.0, sd).expect("sd");
    let mut csv = format!(
        "# synthetic C1 compression record (tools/src/bin/make_mesa2011.rs): ecoflex-rp2, \
         reduced polynomial N=2, C10 = {} MPa, C20 = {} MPa, analytic (lubricated), \
         2 mm at 0.4 mm/s sampled at 100 Hz, noise sd {sd:.4e} N (seed 2011)\n\
         displacement_mm,force_N\n",
        RP2[0], RP2[1]
    );
    for (x, v) in d.iter().zip(&f) {
        let _ = writeln!(csv, "{x:.4},{:.6e}", v + noise.sample(&mut rng));
    }
    std::fs::write(dir.join("c1-compression.csv"), csv).expect("write C1");
    eprintln!("C1: F(2 mm) = {fmax:.4} N, noise sd {sd:.3e} N");
    let _ = writeln!(
        truth,
        "  \"c1-compression\": {{\"law\": \"reduced-polynomial:2\", \"params_MPa\": [{}, {}], \
         \"noise_sd_N\": {sd:.6e}, \"seed\": 2011}},",
        RP2[0], RP2[1]
    );

    // --- the phantom's needle curve ---
    let depths: Vec<f64> = (0..=40).map(|i| 0.25 * i as f64).collect();
    let mut n3 = N3Needle::new(Law::ReducedPolynomial(3));
    n3.friction = 0.8;
    n3.grading = Some(Grading {
        h_fine: 0.6,
        fine_length: 4.0,
        growth: 1.3,
    });
    let t = std::time::Instant::now();
    let theta = [RP2[0], RP2[1], C30];
    let curve = n3
        .predict(
            &theta,
            &Loading::quasi_static(Drive::DisplacementMm, depths.clone()),
        )
        .expect("N3 phantom run");
    eprintln!(
        "phantom N3 (0.6 mm, Yeoh): F(10 mm) = {:.6} N in {:.0} s",
        curve[curve.len() - 1],
        t.elapsed().as_secs_f64()
    );
    let fmax = curve.iter().cloned().fold(0.0, f64::max);
    let sd = 0.005 * fmax;
    let at = |x: f64| -> f64 {
        if x <= 0.0 {
            return 0.0;
        }
        let k = ((x / 0.25).floor() as usize).min(depths.len() - 2);
        let w = (x - depths[k]) / 0.25;
        (1.0 - w) * curve[k] + w * curve[k + 1]
    };
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(2012);
    let scale = Normal::new(0.0, 0.03).expect("sd");
    let offset = Normal::new(0.0, 0.1).expect("sd");
    let noise = Normal::new(0.0, sd).expect("sd");
    let mut reps = Vec::new();
    for r in 1..=3 {
        let s: f64 = scale.sample(&mut rng);
        let delta: f64 = offset.sample(&mut rng);
        let mut csv = format!(
            "# synthetic needle record of the mesa2011 phantom, replicate {r} \
             (tools/src/bin/make_mesa2011.rs): N3 block, 0.6 mm hexahedra, friction 0.8, \
             Yeoh C10 = {} C20 = {} C30 = {C30} MPa; stiffness factor 1{s:+.5}, depth offset \
             {delta:+.4} mm, noise sd {sd:.4e} N (seed 2012)\n\
             displacement_mm,force_N\n",
            RP2[0], RP2[1]
        );
        for &x in &depths {
            let v = (1.0 + s) * at(x - delta) + noise.sample(&mut rng);
            let _ = writeln!(csv, "{x:.4},{v:.6e}");
        }
        std::fs::write(dir.join(format!("needle-{r}.csv")), csv).expect("write needle");
        reps.push(format!(
            "{{\"replicate\": {r}, \"stiffness_factor\": {:.6}, \"depth_offset_mm\": {delta:.6}}}",
            1.0 + s
        ));
    }
    let curve_text: Vec<String> = curve.iter().map(|v| format!("{v:.6e}")).collect();
    let _ = writeln!(
        truth,
        "  \"needle\": {{\"model\": \"N3 quarter block, grading 0.6/4/1.3, friction 0.8\", \
         \"law\": \"reduced-polynomial:3\", \"params_MPa\": [{}, {}, {C30}], \
         \"noise_sd_N\": {sd:.6e}, \"seed\": 2012, \"replicates\": [{}],\n   \
         \"depth_mm\": \"0:0.25:10\", \"force_N\": [{}]}}",
        RP2[0],
        RP2[1],
        reps.join(", "),
        curve_text.join(", ")
    );
    truth.push_str("}\n");
    std::fs::write(dir.join("truth.json"), truth).expect("write truth.json");
}
