//! Writes the synthetic Q1 ramp-and-hold record of the two-stage study
//! (`studies/two-stage-q1.toml`, `palpate calibrate --benchmark Q1 --stages
//! elastic,relaxation`) into `tests/data/two-stage-q1/`:
//!
//! * `record.csv` (`time_s,displacement_mm,force_N`): docs/benchmarks.md Q1's
//!   flat punch (radius 2 mm, edge 0.2 mm, cylinder 50 x 60 mm,
//!   frictionless), neo-Hookean C10 = 0.0016 MPa with the Prony series
//!   g = 0.3 / 0.2, tau = 0.5 / 10 s on the isochoric stress, ramped to
//!   **1.0 mm** in 0.5 s and held 60 s. The depth is 1.0 mm, not the 5 mm of
//!   docs/benchmarks.md: with the 0.2 mm punch edge the FE model stalls near
//!   2 mm (the surface creases round the edge; docs/validation/fe.md Q1).
//!   Samples: 21 in the ramp (every 0.025 s), 40 in the hold, spaced
//!   geometrically from 0.02 s to 60 s after the ramp (the relaxation is
//!   fastest at its start).
//! * made on a **finer mesh** than the fits (level 2: 0.1 mm elements under
//!   the punch; the fits use level 1, 0.2 mm) with a finer time step
//!   (0.25 s; the fits step by at most 1 s between samples), plus Gaussian
//!   noise of 0.5 % of the largest force (seed 13).
//! * `truth.json`: the parameters, the noise and the noise-free forces.
//!
//! The record is committed; rerun only to change it:
//! `cargo run --release -p palpate-tools --bin make_two_stage_q1`.
//! With env `Q1_RECORD_DEPTH=D` (mm) the ramp goes to D instead, into
//! `tests/data/two-stage-q1-Dmm/` (the 5 mm record of docs/benchmarks.md; its fit is a
//! study, not a test).
//! With env `Q1_RECORD_LEVEL=L` the record is made on mesh level L instead
//! of 2 (the 5 mm record is level 3, finer than the level-2 mesh that
//! corrects its fits: `--correct-mesh`).
//! With env `Q1_RECORD_EDGE=R` (mm) the punch's edge is rounded to R instead
//! of 0.2 mm, into `tests/data/two-stage-q1-Dmm-edgeR/` (an edge the meshes
//! resolve: the 5 mm record whose fit is not limited by the 0.2 mm edge's
//! discretisation error; docs/guide.md, two-stage).
//! (`-- --time LEVEL DT` instead times one run of the record's history).

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{Prony, Q1Punch};
use palpate_material::Law;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;

/// The truth: C10 (MPa), g1, tau1 (s), g2, tau2 (s).
const TRUTH: [f64; 5] = [0.0016, 0.3, 0.5, 0.2, 10.0];
const DEPTH: f64 = 1.0;

/// The record's depth: `DEPTH` unless env `Q1_RECORD_DEPTH` says.
fn depth() -> f64 {
    std::env::var("Q1_RECORD_DEPTH").ok().map_or(DEPTH, |v| {
        v.parse().expect("Q1_RECORD_DEPTH: a depth in mm")
    })
}
/// The record's mesh level: 2 unless env `Q1_RECORD_LEVEL` says.
fn level() -> usize {
    std::env::var("Q1_RECORD_LEVEL")
        .ok()
        .map_or(2, |v| v.parse().expect("Q1_RECORD_LEVEL: a mesh level"))
}
/// The punch's edge radius (mm): 0.2 (the model's default) unless env
/// `Q1_RECORD_EDGE` says.
fn edge() -> Option<f64> {
    std::env::var("Q1_RECORD_EDGE")
        .ok()
        .map(|v| v.parse().expect("Q1_RECORD_EDGE: an edge radius in mm"))
}
const RAMP: f64 = 0.5;
const HOLD: f64 = 60.0;

/// The record's times and depths.
fn history() -> (Vec<f64>, Vec<f64>) {
    let depth = depth();
    let mut t: Vec<f64> = (0..=20).map(|i| RAMP * i as f64 / 20.0).collect();
    let mut d: Vec<f64> = (0..=20).map(|i| depth * i as f64 / 20.0).collect();
    let (first, n) = (0.02f64, 40);
    let ratio = (HOLD / first).powf(1.0 / (n - 1) as f64);
    for k in 0..n {
        t.push(RAMP + first * ratio.powi(k));
        d.push(depth);
    }
    (t, d)
}

fn model(level: usize, dt: f64) -> Q1Punch {
    let mut m = Q1Punch::new(Law::NeoHookean);
    m.level = level;
    m.prony = Some(Prony::new(vec![(TRUTH[1], TRUTH[2]), (TRUTH[3], TRUTH[4])]).expect("prony"));
    m.options.max_time_step = Some(dt);
    if let Some(rho) = edge() {
        m.set_edge_radius(rho).expect("Q1_RECORD_EDGE");
    }
    m
}

fn main() {
    let (t, d) = history();
    let loading = Loading::timed(Drive::DisplacementMm, t.clone(), d.clone());
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("--time") {
        let level: usize = args[2].parse().expect("LEVEL");
        let dt: f64 = args[3].parse().expect("DT");
        let t0 = std::time::Instant::now();
        let mut m = model(level, dt);
        if let Some(h) = args.get(4) {
            let h: f64 = h.parse().expect("H_FINE");
            m.set_fine_size(h);
        }
        let (sim, _) = m.simulate(&TRUTH[..1], &loading, None).expect("run");
        let f = sim.forces;
        eprintln!(
            "level {level}, dt {dt}: {:.2} s {:?}; F(ramp end) {:.6e}, F(end) {:.6e}",
            t0.elapsed().as_secs_f64(),
            sim.stats,
            f[20],
            f[f.len() - 1]
        );
        for (k, v) in f.iter().enumerate() {
            println!("{},{},{v:.8e}", t[k], d[k]);
        }
        return;
    }
    let depth = depth();
    let mut sub = if depth == DEPTH {
        "tests/data/two-stage-q1".to_string()
    } else {
        format!("tests/data/two-stage-q1-{depth}mm")
    };
    if let Some(rho) = edge() {
        sub = format!("{sub}-edge{rho}");
    }
    let edge_mm = edge().unwrap_or(palpate_fe::q1::DEFAULT_EDGE_RADIUS);
    let dir = palpate_tools::repo(&sub);
    std::fs::create_dir_all(&dir).expect("create the record's folder");
    let level = level();
    let f = model(level, 0.25)
        .predict(&TRUTH[..1], &loading)
        .expect("the fine run");
    let fmax = f.iter().cloned().fold(0.0, f64::max);
    let sd = 0.005 * fmax;
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(13);
    let noise = Normal::new(0.0, sd).expect("sd");
    let mut csv = format!(
        "# synthetic Q1 ramp-and-hold record (tools/src/bin/make_two_stage_q1.rs): flat punch r 2 mm \
         (edge {edge_mm} mm), neo-Hookean C10 = {} MPa, Prony g1 = {}, tau1 = {} s, g2 = {}, tau2 = {} s, \
         {depth} mm in {RAMP} s, hold {HOLD} s, mesh level {level}, time step 0.25 s, noise sd {sd:.4e} N (seed 13)\n\
         time_s,displacement_mm,force_N\n",
        TRUTH[0], TRUTH[1], TRUTH[2], TRUTH[3], TRUTH[4]
    );
    let mut noisy = Vec::new();
    for k in 0..t.len() {
        let v = f[k] + noise.sample(&mut rng);
        noisy.push(v);
        let _ = writeln!(csv, "{:.6},{:.6},{v:.6e}", t[k], d[k]);
    }
    std::fs::write(dir.join("record.csv"), csv).expect("write the record");
    let truth = format!(
        "{{\"parameters\": {{\"C10\": {}, \"g1\": {}, \"tau1_s\": {}, \"g2\": {}, \"tau2_s\": {}}},\n \
         \"depth_mm\": {depth}, \"edge_radius_mm\": {edge_mm}, \"ramp_s\": {RAMP}, \"hold_s\": {HOLD}, \"mesh_level\": {level}, \
         \"max_time_step_s\": 0.25, \"noise_sd_N\": {sd:.6e}, \"seed\": 13,\n \
         \"noise_free_force_N\": [{}]}}\n",
        TRUTH[0],
        TRUTH[1],
        TRUTH[2],
        TRUTH[3],
        TRUTH[4],
        f.iter()
            .map(|v| format!("{v:.8e}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    std::fs::write(dir.join("truth.json"), truth).expect("write truth.json");
    eprintln!(
        "Q1 record: peak {fmax:.4e} N, noise sd {sd:.3e} N, {} samples",
        t.len()
    );
}
