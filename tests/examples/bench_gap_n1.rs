//! Speed of the N1 gap diagnosis (goal: a 10 mm record in 60 s
//! or less on 2 cores). Writes (once, to `target/bench_gap_n1.csv`) a 10 mm
//! needle record every 0.25 mm (41 samples) with friction 0.5 on the MEDIUM
//! mesh, C10 1.2e-3 MPa, noise 1 % of the peak force, then diagnoses it
//! with the CLI's N1 base (neo-Hookean, frictionless, bonded, coarse mesh)
//! and candidates (friction, boundary_condition), and prints the verdict,
//! the number of FE simulations, wall and CPU seconds (user + system of the
//! process, `/proc/self/stat`).
//!
//! `cargo run --release -p palpate-tests --example bench_gap_n1 [-- --effects friction,material_form]`

use palpate_core::{Drive, Effect, ForwardModel, Loading, Table};
use palpate_fe::{MeshDensity, N1Needle};
use palpate_material::Law;
use palpate_tests::counted::{Counted, RUNS};
use palpate_uq::gap::{diagnose, GapOptions};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::fmt::Write;
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Instant;

/// User + system CPU seconds of this process.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

fn record() -> (Loading, Vec<f64>) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/bench_gap_n1.csv");
    if !path.exists() {
        let depths: Vec<f64> = (0..=40).map(|i| 0.25 * i as f64).collect();
        let loading = Loading::quasi_static(Drive::DisplacementMm, depths.clone());
        let mut m = N1Needle::new(Law::NeoHookean);
        m.friction = 0.5;
        m.mesh = MeshDensity::MEDIUM;
        let f = m.predict(&[1.2e-3], &loading).expect("N1 record");
        let peak = f.iter().cloned().fold(0.0, f64::max);
        let noise = Normal::new(0.0, 0.01 * peak).expect("sd");
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let mut csv = String::from("displacement_mm,force_N\n");
        for (d, v) in depths.iter().zip(&f) {
            let _ = writeln!(csv, "{d},{:.6e}", v + noise.sample(&mut rng));
        }
        std::fs::write(&path, csv).expect("write record");
    }
    let t = Table::read(&path).expect("record");
    let d = t.column("displacement_mm").unwrap().to_vec();
    let f = t.column("force_N").unwrap().to_vec();
    (Loading::quasi_static(Drive::DisplacementMm, d), f)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let effects: Vec<Effect> = match args.iter().position(|a| a == "--effects") {
        Some(k) => args[k + 1]
            .split(',')
            .map(|e| e.parse().expect("effect"))
            .collect(),
        None => vec![Effect::Friction, Effect::BoundaryCondition],
    };
    let (loading, f) = record();
    let mut base = N1Needle::new(Law::NeoHookean);
    base.friction = 0.0;
    base.mesh = MeshDensity::COARSE;
    let base = Counted(Arc::new(base));
    let names: Vec<&str> = effects.iter().map(|e| e.name()).collect();
    // `--no-cache-too`: also the diagnosis without the prediction cache
    // (what the cache and the homogeneity shortcut save).
    let caches: &[bool] = if args.iter().any(|a| a == "--no-cache-too") {
        &[false, true]
    } else {
        &[true]
    };
    let mut rows = Vec::new();
    let mut last = None;
    for &cache in caches {
        let options = GapOptions {
            effects: Some(effects.clone()),
            cache,
            ..GapOptions::default()
        };
        RUNS.store(0, Ordering::Relaxed);
        let (wall, cpu) = (Instant::now(), cpu_seconds());
        let r = diagnose(&base, &loading, &f, &options).expect("diagnosis");
        let (wall, cpu) = (wall.elapsed().as_secs_f64(), cpu_seconds() - cpu);
        rows.push(format!(
            "| N1 10 mm, 41 samples, friction 0.5 | {} | {} | {} | {} | {wall:.1} | {cpu:.1} | {} |",
            names.join(", "),
            if cache { "yes" } else { "no" },
            r.verdict,
            RUNS.load(Ordering::Relaxed),
            rayon::current_num_threads()
        ));
        last = Some(r);
    }
    let r = last.expect("one run");
    println!(
        "| record | candidates | cache | verdict | FE runs | wall s | CPU s (user+sys) | threads |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for row in rows {
        println!("{row}");
    }
    for e in &r.ranking {
        println!(
            "  {}: misfit {:.3e} -> {:.3e}, held-out {:.3e} -> {:.3e}, params {:?}",
            e.effect, e.misfit_before, e.misfit_after, e.heldout_before, e.heldout_after, e.params
        );
    }
    for u in &r.undetectable {
        println!(
            "  not seen: {} {:?} -> {:?}",
            u.effect, u.range, u.base_params
        );
    }
}
