//! Writes the development records of gap diagnosis v2 to
//! `tests/data/gap-v2/`, one group per weakness of the first version, each
//! record seeded and with its truth in `truth.json` (used by
//! `tests/integration/gap_v2.rs`):
//!
//! * `w1-*` (weakness 1, a true effect rejected by its own cross-validation):
//!   C1 compression, a fast ramp and a long hold with two-term relaxation.
//!   The ramp is shorter than one of eight contiguous blocks, so leaving out
//!   the block that holds it (or the early hold) leaves the time constants
//!   unidentified in the refit. Expected `viscoelasticity`.
//! * `w2-*` (weakness 2, tiny but significant misfits): about 800 samples,
//!   AR(1) noise (a filtered load cell, lag-1 correlation about 0.15) and a
//!   zero offset of 0.01-0.02 mm, which moves the misfit by a few per cent of
//!   the noise. Expected `none`; a detectable effect must be listed as
//!   `immaterial`.
//! * `w3-c1-*` (weakness 3, undetectable does not mean harmless): a zero
//!   offset of 0.1 mm (the end of its plausible range) under heavy noise on a
//!   ramp: not detected, but it biases C10. Expected `none`, with the true
//!   C10 inside the range the `undetectable` refits report.
//! * `w3-n1-friction` (weakness 3 on N1): needle indentation to 5 mm with
//!   friction 0.8 on the MEDIUM mesh (the coarse-mesh base of the diagnosis
//!   does not share its discretisation), noise 4 % of the peak force: the
//!   frictionless base fits within the noise with C10 well above the truth.
//!
//! `cargo run --release -p palpate-tools --bin make_gap_v2` (about a
//! minute, most of it the N1 record). The records are committed; rerun only
//! to change them.

use palpate_analytic::C1Compression;
use palpate_core::{Drive, ForwardModel, Loading};
use palpate_enrich::{Viscoelastic, ZeroOffset};
use palpate_fe::{MeshDensity, N1Needle};
use palpate_material::Law;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

/// A C1 history sampled every `dt` s: a ramp at `rate` mm/s to `depth`,
/// a hold of `hold` s, and an unloading at the same rate when `unload`.
fn c1_history(rate: f64, depth: f64, hold: f64, unload: bool, dt: f64) -> Loading {
    let ramp = depth / rate;
    let total = ramp + hold + if unload { ramp } else { 0.0 };
    let n = (total / dt).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
    let d = t
        .iter()
        .map(|&t| {
            if t <= ramp {
                rate * t
            } else if t <= ramp + hold {
                depth
            } else {
                (depth - rate * (t - ramp - hold)).max(0.0)
            }
        })
        .collect();
    Loading::timed(Drive::DisplacementMm, t, d)
}

/// Gaussian AR(1) noise of marginal SD `sd` and lag-1 correlation `phi`
/// (white for phi = 0), from `seed`.
fn noise(n: usize, sd: f64, phi: f64, seed: u64) -> Vec<f64> {
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    let innovation = Normal::new(0.0, sd * (1.0 - phi * phi).sqrt()).expect("sd");
    let mut e = Normal::new(0.0, sd).expect("sd").sample(&mut rng);
    (0..n)
        .map(|_| {
            let v = e;
            e = phi * e + innovation.sample(&mut rng);
            v
        })
        .collect()
}

struct Record {
    name: String,
    loading: Loading,
    clean: Vec<f64>,
    sd: f64,
    phi: f64,
    seed: u64,
    /// JSON of the truth (without noise, which is added here).
    truth: String,
}

fn c1_records() -> Vec<Record> {
    let nh = || Box::new(C1Compression::new(Law::NeoHookean)) as Box<dyn ForwardModel>;
    let mut out = Vec::new();
    // Weakness 1: fast ramp, long hold, two-term relaxation.
    let w1 = [
        // (rate mm/s, depth mm, hold s, C10, g1, tau1, g2, tau2, noise N, seed)
        (1.0, 2.0, 30.0, 1.2e-3, 0.25, 0.6, 0.15, 6.0, 0.0158, 101),
        (4.0, 2.0, 30.0, 1.2e-3, 0.1, 0.3, 0.05, 20.0, 0.0158, 107),
        (4.0, 2.0, 30.0, 1.0e-3, 0.15, 0.5, 0.08, 15.0, 0.0158, 109),
        (2.0, 1.8, 25.0, 1.2e-3, 0.1, 0.4, 0.06, 25.0, 0.0158, 110),
        (4.0, 2.0, 20.0, 1.3e-3, 0.12, 0.3, 0.05, 12.0, 0.0158, 111),
        (4.0, 2.0, 30.0, 1.1e-3, 0.08, 0.3, 0.06, 20.0, 0.0158, 112),
    ];
    for (k, &(rate, depth, hold, c10, g1, tau1, g2, tau2, sd, seed)) in w1.iter().enumerate() {
        let loading = c1_history(rate, depth, hold, false, 0.05);
        let m = Viscoelastic::new(nh(), 2);
        let clean = m
            .predict(&[c10, g1, tau1, g2, tau2], &loading)
            .expect("C1 QLV");
        out.push(Record {
            name: format!("w1-relaxation-{}", k + 1),
            loading,
            clean,
            sd,
            phi: 0.0,
            seed,
            truth: format!(
                "\"protocol\": \"ramp_hold\", \"rate_mm_s\": {rate}, \"depth_mm\": {depth}, \"hold_s\": {hold}, \
                 \"effects\": [\"viscoelasticity\"], \"params\": {{\"C10_MPa\": {c10}, \"prony_g\": [{g1}, {g2}], \
                 \"prony_tau_s\": [{tau1}, {tau2}]}}, \"expected\": \"viscoelasticity\""
            ),
        });
    }
    // Weakness 2: ~800 samples, AR(1) noise, a tiny offset.
    let w2 = [
        // (rate, depth, hold, unload, dt, C10, d0 mm, noise N, phi, seed)
        (0.2, 2.0, 20.0, true, 0.05, 1.2e-3, 0.015, 0.02, 0.15, 201),
        (0.2, 2.0, 0.0, true, 0.025, 1.0e-3, 0.01, 0.02, 0.15, 202),
        (0.1, 2.0, 20.0, false, 0.05, 1.3e-3, 0.02, 0.025, 0.15, 203),
    ];
    for (k, &(rate, depth, hold, unload, dt, c10, d0, sd, phi, seed)) in w2.iter().enumerate() {
        let loading = c1_history(rate, depth, hold, unload, dt);
        let m = ZeroOffset::new(nh());
        let clean = m.predict(&[c10, d0], &loading).expect("C1 offset");
        out.push(Record {
            name: format!("w2-tiny-offset-{}", k + 1),
            loading,
            clean,
            sd,
            phi,
            seed,
            truth: format!(
                "\"protocol\": \"{}\", \"effects\": [\"zero_offset\"], \"params\": {{\"C10_MPa\": {c10}, \
                 \"offset_mm\": {d0}}}, \"noise_ar1_phi\": {phi}, \"expected\": \"none\"",
                if unload { "ramp_hold_unload" } else { "ramp_hold" }
            ),
        });
    }
    // Weakness 3 on C1: an offset at the end of its plausible range, heavy noise.
    let w3 = [
        // (rate, depth, C10, d0, noise, seed)
        (0.2, 2.0, 1.2e-3, 0.1, 0.15, 301),
        (0.4, 1.6, 1.0e-3, 0.1, 0.06, 302),
    ];
    for (k, &(rate, depth, c10, d0, sd, seed)) in w3.iter().enumerate() {
        let loading = c1_history(rate, depth, 0.0, false, 0.1);
        let m = ZeroOffset::new(nh());
        let clean = m.predict(&[c10, d0], &loading).expect("C1 offset");
        out.push(Record {
            name: format!("w3-c1-offset-{}", k + 1),
            loading,
            clean,
            sd,
            phi: 0.0,
            seed,
            truth: format!(
                "\"protocol\": \"ramp\", \"effects\": [\"zero_offset\"], \"params\": {{\"C10_MPa\": {c10}, \
                 \"offset_mm\": {d0}}}, \"expected\": \"none\""
            ),
        });
    }
    out
}

fn n1_record() -> Record {
    let depths: Vec<f64> = (0..=20).map(|i| 0.25 * i as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, depths);
    let mut m = N1Needle::new(Law::NeoHookean);
    m.friction = 0.8;
    m.mesh = MeshDensity::MEDIUM;
    let c10 = 1.0e-3;
    let clean = m.predict(&[c10], &loading).expect("N1 simulation");
    let peak = clean.iter().cloned().fold(0.0, f64::max);
    Record {
        name: "w3-n1-friction".into(),
        loading,
        clean,
        sd: 0.04 * peak,
        phi: 0.0,
        seed: 401,
        truth: format!(
            "\"benchmark\": \"N1\", \"effects\": [\"friction\"], \"params\": {{\"C10_MPa\": {c10}, \
             \"friction\": 0.8}}, \"mesh\": \"medium\", \"expected\": \"none\""
        ),
    }
}

fn main() {
    let dir = palpate_tools::repo("tests/data/gap-v2");
    std::fs::create_dir_all(&dir).expect("create data/gap-v2");
    let mut records = c1_records();
    if !std::env::args().any(|a| a == "--c1-only") {
        records.push(n1_record());
    }
    let mut truth = String::from("{\n");
    for (k, r) in records.iter().enumerate() {
        let e = noise(r.clean.len(), r.sd, r.phi, r.seed);
        let timed = r.loading.time.is_some();
        let mut csv = format!(
            "# gap diagnosis v2 development record (tools/src/bin/make_gap_v2.rs), seed {}, noise sd {:.4e} N, AR(1) phi {}\n{}displacement_mm,force_N\n",
            r.seed,
            r.sd,
            r.phi,
            if timed { "time_s," } else { "" }
        );
        for i in 0..r.clean.len() {
            if let Some(t) = &r.loading.time {
                let _ = write!(csv, "{:.4},", t[i]);
            }
            let _ = writeln!(csv, "{:.5},{:.6e}", r.loading.drive[i], r.clean[i] + e[i]);
        }
        std::fs::write(dir.join(format!("{}.csv", r.name)), csv).expect("write record");
        let _ = writeln!(
            truth,
            "  \"{}\": {{{}, \"noise_sd_N\": {:.6e}, \"samples\": {}}}{}",
            r.name,
            r.truth,
            r.sd,
            r.clean.len(),
            if k + 1 < records.len() { "," } else { "" }
        );
        eprintln!(
            "{}: {} samples, noise sd {:.3e}",
            r.name,
            r.clean.len(),
            r.sd
        );
    }
    truth.push_str("}\n");
    std::fs::write(dir.join("truth.json"), truth).expect("write truth.json");
}
