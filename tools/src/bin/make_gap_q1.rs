//! Writes the synthetic Q1 withheld-effect records of `tests/data/gap-q1/`
//! (used by `gap_fe_effects`): the Q1 flat punch (docs/benchmarks.md Q1,
//! radius 2 mm, edge 0.2 mm, frictionless) ramped to 0.5 mm in 0.25 s and
//! held 4 s — a short protocol so that one viscoelastic run of the base
//! costs seconds and a diagnosis minutes (the first records, 1 mm and a 10 s
//! hold in 51 samples, did not finish a diagnosis under load) — simulated
//! by a model richer than the
//! diagnosis's enrichment: a **two-term** Prony series (the enrichment has
//! one term) integrated with time steps of a tenth of the shortest
//! relaxation time (the enrichment steps at the samples), on mesh level 2
//! (the base's too: level 1 does not converge at the first viscoelastic
//! hold increment); plus Gaussian noise of a stated fraction of the largest
//! force, from a fixed seed.
//!
//! `cargo run --release -p palpate-tools --bin make_gap_q1`. The records
//! are committed; rerun only to change them.

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::viscoelastic::Prony;
use palpate_fe::Q1Punch;
use palpate_material::Law;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

struct Case {
    name: &'static str,
    c10: f64,
    /// (g_i, tau_i) of the generator's Prony series; empty: elastic.
    prony: &'static [(f64, f64)],
    noise_fraction: f64,
    seed: u64,
    expected: &'static str,
}

/// The record's times and depths: a ramp to 0.5 mm in 0.25 s sampled every
/// 0.025 s, then a hold to 4.25 s sampled every 0.2 s (31 samples).
pub fn q1_history() -> (Vec<f64>, Vec<f64>) {
    let mut t: Vec<f64> = (0..=10).map(|i| 0.025 * i as f64).collect();
    t.extend((1..=20).map(|i| 0.25 + 0.2 * i as f64));
    let d = t.iter().map(|&s| 0.5 * (s / 0.25).min(1.0)).collect();
    (t, d)
}

fn main() {
    let cases = [
        Case {
            name: "q1-relaxation",
            c10: 1.0e-3,
            prony: &[(0.3, 0.3), (0.2, 2.0)],
            noise_fraction: 0.01,
            seed: 21,
            expected: "viscoelasticity",
        },
        Case {
            name: "q1-weak-relaxation",
            c10: 1.5e-3,
            prony: &[(0.08, 1.0)],
            noise_fraction: 0.01,
            seed: 22,
            expected: "viscoelasticity",
        },
        Case {
            name: "q1-none",
            c10: 0.8e-3,
            prony: &[],
            noise_fraction: 0.01,
            seed: 23,
            expected: "none",
        },
    ];
    let dir = palpate_tools::repo("tests/data/gap-q1");
    std::fs::create_dir_all(&dir).expect("create data/gap-q1");
    let (time, depth) = q1_history();
    let loading = Loading::timed(Drive::DisplacementMm, time.clone(), depth.clone());
    let mut elastic = Q1Punch::new(Law::NeoHookean);
    elastic.level = 2;
    let base_f = elastic.predict(&[1e-3], &loading).expect("elastic base");
    let mut truth = String::from("{\n");
    for (k, c) in cases.iter().enumerate() {
        let mut m = Q1Punch::new(Law::NeoHookean);
        m.level = 2;
        if !c.prony.is_empty() {
            m.prony = Some(Prony::new(c.prony.to_vec()).expect("Prony series"));
        }
        let f = m.predict(&[c.c10], &loading).expect("Q1 simulation");
        let fmax = f.iter().cloned().fold(0.0, f64::max);
        let sd = c.noise_fraction * fmax;
        // visible size: RMS of the noiseless record minus the elastic base's
        // least-squares fit (exact: homogeneous in C10), in noise SDs; the
        // planted effect is the right answer at 1 SD or more, `none` below
        // 0.4 SD (the diagnosis's materiality threshold)
        let a = f.iter().zip(&base_f).map(|(y, b)| y * b).sum::<f64>()
            / base_f.iter().map(|b| b * b).sum::<f64>();
        let size = (f
            .iter()
            .zip(&base_f)
            .map(|(y, b)| (y - a * b).powi(2))
            .sum::<f64>()
            / f.len() as f64)
            .sqrt()
            / sd;
        let expected = if c.expected != "none" && size >= 1.0 {
            c.expected
        } else if size < 0.4 {
            "none"
        } else {
            "borderline"
        };
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(c.seed);
        let noise = Normal::new(0.0, sd).expect("noise sd");
        let mut csv = format!(
            "# synthetic Q1 record (tools/src/bin/make_gap_q1.rs): neo-Hookean C10 = {} MPa, \
             Prony {:?}, mesh level 2, noise sd {:.3e} N (seed {})\n\
             time_s,displacement_mm,force_N\n",
            c.c10, c.prony, sd, c.seed
        );
        for ((t, d), v) in time.iter().zip(&depth).zip(&f) {
            let _ = writeln!(csv, "{t:.4},{d:.4},{:.6e}", v + noise.sample(&mut rng));
        }
        std::fs::write(dir.join(format!("{}.csv", c.name)), csv).expect("write record");
        let terms: Vec<String> = c
            .prony
            .iter()
            .map(|(g, tau)| format!("[{g}, {tau}]"))
            .collect();
        let _ = writeln!(
            truth,
            "  \"{}\": {{\"benchmark\": \"Q1\", \"base_model\": \"neo-Hookean, elastic, mesh level 2\", \
             \"generator\": \"Q1 level 2, two-term-capable Prony, dt = tau_min / 10\", \
             \"params\": {{\"C10_MPa\": {}, \"prony_g_tau_s\": [{}]}}, \
             \"noise_sd_N\": {sd:.6e}, \"visible_rms_in_sd\": {size:.3}, \"expected\": \"{}\"}}{}",
            c.name,
            c.c10,
            terms.join(", "),
            expected,
            if k + 1 < cases.len() { "," } else { "" }
        );
        eprintln!(
            "{}: peak {:.4} N, noise sd {:.2e} N, visible {size:.2} SD -> {expected}",
            c.name, fmax, sd
        );
    }
    truth.push_str("}\n");
    std::fs::write(dir.join("truth.json"), truth).expect("write truth.json");
}
