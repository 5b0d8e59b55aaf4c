//! Benchmark: N1 (BENCHMARKS.md) neo-Hookean `ecoflex-nh`, friction 0.8,
//! bonded base, exact incompressibility, needle to 10 mm with the force every
//! 0.25 mm, on 1 and 2 threads; prints elements, unknowns, increments, Newton
//! iterations, wall time and the force at 2, 5 and 10 mm. With `--ccx` it
//! also runs CalculiX (`ccx` on the PATH) on the reference deck
//! `../shared/reference/calculix/n1/n1_nh_f0.8_k1000_n6.inp` in a temporary
//! directory and times it.
//!
//! `cargo run --release -p palpate-fe --example bench_n1 -- [level ...] [--ccx]`
//! (default levels 1 2).

use std::path::Path;
use std::time::Instant;

use palpate_core::{Drive, Loading};
use palpate_fe::{MeshDensity, N1Needle};

const C10: f64 = 1101.295e-6;

fn run(level: usize, threads: usize) -> (Vec<f64>, palpate_fe::RunStats, usize, usize, f64) {
    let mut m = N1Needle::new("neo-hookean".parse().expect("law"));
    m.mesh = MeshDensity { level };
    let drive: Vec<f64> = (1..=40).map(|k| 0.25 * k as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let t = Instant::now();
    let (sim, solver) = pool
        .install(|| m.simulate(&[C10], &loading, None))
        .unwrap_or_else(|e| panic!("level {level}: {e}"));
    let wall = t.elapsed().as_secs_f64();
    (
        sim.forces,
        sim.stats,
        solver.mesh.elements.len(),
        solver.equations(),
        wall,
    )
}

fn calculix() -> Option<f64> {
    let deck = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference/calculix/n1/n1_nh_f0.8_k1000_n6.inp");
    let dir = std::env::temp_dir().join(format!("palpate_bench_ccx_{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    std::fs::copy(&deck, dir.join("n1.inp")).ok()?;
    let t = Instant::now();
    let status = std::process::Command::new("ccx")
        .arg("-i")
        .arg("n1")
        .current_dir(&dir)
        .env("OMP_NUM_THREADS", "1")
        .stdout(std::process::Stdio::null())
        .status()
        .ok()?;
    let wall = t.elapsed().as_secs_f64();
    std::fs::remove_dir_all(&dir).ok();
    status.success().then_some(wall)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let with_ccx = args.iter().any(|a| a == "--ccx");
    let mut levels: Vec<usize> = args.iter().filter_map(|a| a.parse().ok()).collect();
    if levels.is_empty() {
        levels = vec![1, 2];
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("N1 ecoflex-nh, friction 0.8, exact incompressibility, 0..10 mm every 0.25 mm; machine cores: {cores}");
    println!("| level | elements | unknowns | threads | increments | Newton iterations | factorisations | wall (s) | F(2) N | F(5) N | F(10) N | assembly (s) | solve (s) | loose |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for &level in &levels {
        let mut first: Option<Vec<f64>> = None;
        for threads in [1, 2] {
            let (f, s, ne, neq, wall) = run(level, threads);
            println!(
                "| {level} | {ne} | {neq} | {threads} | {} | {} | {} | {wall:.2} | {:.6} | {:.6} | {:.6} | {:.2} | {:.2} | {} |",
                s.increments, s.iterations, s.factorisations, f[7], f[19], f[39], s.assembly_seconds, s.solve_seconds, s.loose
            );
            match &first {
                None => first = Some(f),
                Some(g) => assert!(
                    g.iter().zip(&f).all(|(a, b)| a.to_bits() == b.to_bits()),
                    "forces differ between 1 and 2 threads"
                ),
            }
        }
    }
    if with_ccx {
        match calculix() {
            Some(wall) => println!(
                "| CalculiX n6 (480 CAX8R, K = 1000 mu, penalty contact) | 480 | 3078 | 1 | - | - | - | {wall:.1} | 0.045461 | 0.155403 | 0.394390 | - | - | - |"
            ),
            None => println!("CalculiX: `ccx` not found or failed"),
        }
    }
}
