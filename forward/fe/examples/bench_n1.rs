//! Benchmark: N1 (docs/benchmarks.md) neo-Hookean `ecoflex-nh`,
//! friction 0.8, bonded base, exact incompressibility, needle to 10 mm with
//! the force every 0.25 mm, on 1 and 2 threads, against CalculiX on the
//! reference deck `tests/data/calculix/n1/n1_nh_f0.8_k1000_n6.inp`.
//!
//! Meshes: the Q2/P1 benchmark mesh ([`Q9_GRADING`], 9-node cells with a
//! discontinuous linear pressure), the Q1/P0 benchmark mesh ([`MeshDensity::BENCH_GRADING`], the cheapest
//! found as accurate as level 2) with the default 0.25 mm increments and
//! with 0.125 mm increments (the increment error is ~0.1 % at 10 mm), and,
//! for context, levels 1 and 2 (or the levels given as arguments). Each row
//! prints elements, unknowns, increments, Newton iterations,
//! factorisations, wall and CPU seconds (user + system of the whole process
//! during the run, `/proc/self/stat`), assembly and factorise-and-solve wall
//! seconds, the forces at 2, 5 and 10 mm and their distance from the best
//! estimate of the converged force ([`CONVERGED`]). The CalculiX line quotes the run recorded in
//! docs/validation/fe.md; `--ccx` reruns it (`ccx` on the PATH, one thread,
//! ~10 min) and measures its wall and CPU time (the child's user + system).
//! `--margin` adds a finer grading ([`MARGIN_GRADING`]) with 0.125 mm
//! increments, inside CalculiX's error budget with a margin.
//!
//! `cargo run --release -p palpate-fe --example bench_n1 -- [level ...] [--margin] [--ccx]`

use std::path::Path;
use std::time::Instant;

use palpate_core::{Drive, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::{MeshDensity, N1Needle, PlaneCell, RunStats};

const C10: f64 = 1101.295e-6;
const AT: [f64; 3] = [2.0, 5.0, 10.0];
/// Best estimate of the converged force (mesh and increments) at 2, 5 and
/// 10 mm (N): Richardson extrapolation of levels 2, 3 and 5 run with
/// 0.125 mm increments (`convergence_n1 2 3 5 --max-step=0.125`; order 1.2
/// at 10 mm, orders 1 to 1.5 at 2 and 5 mm, the middle value taken), about
/// +-0.1 % uncertain at 5 and 10 mm. docs/validation/fe.md, "N1 speed".
const CONVERGED: [f64; 3] = [0.045312, 0.155020, 0.393390];
/// CalculiX 2.20 n6 (480 CAX8R, K = 1000 mu, penalty contact, one thread),
/// run once on this machine (docs/validation/fe.md): forces at 2, 5, 10 mm,
/// unknowns, wall and user CPU seconds, and the README's wall time.
const CCX_FORCES: [f64; 3] = [0.045461, 0.155403, 0.394390];
const CCX_UNKNOWNS: usize = 3078;
/// A finer grading (`--margin`) whose error, with 0.125 mm increments, is
/// inside CalculiX's 0.5 % budget with a margin (+0.07 / +0.33 / +0.34 % at
/// 2 / 5 / 10 mm), at three times the bench mesh's CPU time; the bench mesh
/// is at the edge of that budget (its neighbouring gradings are not inside).
const MARGIN_GRADING: Grading = Grading {
    h_fine: 0.4 / 3.0,
    fine_length: 3.0,
    growth: 1.08,
};
/// The Q2/P1 bench mesh: 9-node cells of 0.5 mm (nodes every 0.25 mm) in a
/// 2 mm zone under the needle, growing by 1.25 beyond it (320 cells, 3560
/// unknowns). Chosen from the gradings tried with `examples/q9_try`-style
/// runs (docs/validation/fe.md, "N1 speed"): inside CalculiX's 0.5 %
/// budget at 2, 5 and 10 mm with the default 0.25 mm increments.
const Q9_GRADING: Grading = Grading {
    h_fine: 0.5,
    fine_length: 2.0,
    growth: 1.25,
};
#[path = "common/cpu.rs"]
mod cpu;
use cpu::cpu_seconds;

const CCX_WALL: f64 = 627.7;
const CCX_CPU: f64 = 287.8;
const CCX_README_WALL: f64 = 586.0;

/// One mesh of the table.
#[derive(Clone, Copy)]
enum MeshChoice {
    Level(usize),
    Graded(&'static str, Grading),
    /// 9-node Q2/P1 cells on this grading (each graded cell one quadratic cell).
    Quadratic(&'static str, Grading),
}

/// One row of the table: a mesh and the largest increment (mm; `None`: the
/// model's default, 0.25).
#[derive(Clone, Copy)]
struct Case {
    mesh: MeshChoice,
    max_step: Option<f64>,
}

impl Case {
    fn label(&self) -> String {
        let mesh = match self.mesh {
            MeshChoice::Level(l) => format!("level {l}"),
            MeshChoice::Graded(name, g) | MeshChoice::Quadratic(name, g) => {
                let h = (g.h_fine * 1e4).round() / 1e4;
                format!("{name} ({h}/{}/{})", g.fine_length, g.growth)
            }
        };
        match self.max_step {
            Some(s) => format!("{mesh}, {s} mm steps"),
            None => mesh,
        }
    }
}

struct Run {
    forces: [f64; 3],
    stats: RunStats,
    elements: usize,
    unknowns: usize,
    wall: f64,
    cpu: f64,
    all_forces: Vec<f64>,
}

fn run(case: Case, threads: usize) -> Run {
    let mut m = N1Needle::new("neo-hookean".parse().expect("law"));
    match case.mesh {
        MeshChoice::Level(level) => m.mesh = MeshDensity { level },
        MeshChoice::Graded(_, g) => m.grading = Some(g),
        MeshChoice::Quadratic(_, g) => {
            m.grading = Some(g);
            m.element = PlaneCell::Quad9;
        }
    }
    if let Some(s) = case.max_step {
        m.options.max_step = s;
    }
    let drive: Vec<f64> = (1..=40).map(|k| 0.25 * k as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let (t, c) = (Instant::now(), cpu_seconds(false));
    let (sim, solver) = pool
        .install(|| m.simulate(&[C10], &loading, None))
        .unwrap_or_else(|e| panic!("{}: {e}", case.label()));
    let (wall, cpu) = (t.elapsed().as_secs_f64(), cpu_seconds(false) - c);
    let at = |d: f64| sim.forces[(d / 0.25).round() as usize - 1];
    Run {
        forces: [at(AT[0]), at(AT[1]), at(AT[2])],
        stats: sim.stats,
        elements: solver.mesh.cell_count(),
        unknowns: solver.equations(),
        wall,
        cpu,
        all_forces: sim.forces,
    }
}

/// Reruns CalculiX on the reference deck: (wall, CPU) seconds.
fn calculix() -> Option<(f64, f64)> {
    let deck = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/calculix/n1/n1_nh_f0.8_k1000_n6.inp");
    let dir = std::env::temp_dir().join(format!("palpate_bench_ccx_{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    std::fs::copy(&deck, dir.join("n1.inp")).ok()?;
    let (t, c) = (Instant::now(), cpu_seconds(true));
    let status = std::process::Command::new("ccx")
        .arg("-i")
        .arg("n1")
        .current_dir(&dir)
        .env("OMP_NUM_THREADS", "1")
        .stdout(std::process::Stdio::null())
        .status()
        .ok()?;
    let (wall, cpu) = (t.elapsed().as_secs_f64(), cpu_seconds(true) - c);
    std::fs::remove_dir_all(&dir).ok();
    status.success().then_some((wall, cpu))
}

fn pct(a: f64, b: f64) -> f64 {
    100.0 * (a - b) / b
}

fn distances(f: [f64; 3]) -> String {
    format!(
        "{:+.2} / {:+.2} / {:+.2}",
        pct(f[0], CONVERGED[0]),
        pct(f[1], CONVERGED[1]),
        pct(f[2], CONVERGED[2])
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let with_ccx = args.iter().any(|a| a == "--ccx");
    let with_margin = args.iter().any(|a| a == "--margin");
    let mut levels: Vec<usize> = args.iter().filter_map(|a| a.parse().ok()).collect();
    if levels.is_empty() {
        levels = vec![1, 2];
    }
    let bench = MeshChoice::Graded("bench", MeshDensity::BENCH_GRADING);
    let mut cases = vec![
        Case {
            mesh: MeshChoice::Quadratic("Q2/P1 bench", Q9_GRADING),
            max_step: None,
        },
        Case {
            mesh: bench,
            max_step: None,
        },
        Case {
            mesh: bench,
            max_step: Some(0.125),
        },
    ];
    if with_margin {
        cases.push(Case {
            mesh: MeshChoice::Graded("margin", MARGIN_GRADING),
            max_step: Some(0.125),
        });
    }
    cases.extend(levels.iter().map(|&l| Case {
        mesh: MeshChoice::Level(l),
        max_step: None,
    }));
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!(
        "N1 ecoflex-nh, friction 0.8, exact incompressibility, 0..10 mm every 0.25 mm; machine cores: {cores}; \
         CPU = user + system of the run; vs converged = distance from {CONVERGED:?} N"
    );
    println!("| mesh (h/zone/growth) | elements | unknowns | threads | increments | Newton iterations | factorisations | wall (s) | CPU (s) | assembly (s) | solve (s) | F(2) N | F(5) N | F(10) N | vs converged at 2/5/10 mm (%) | loose |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut bench_runs: Vec<(String, usize, Run)> = Vec::new();
    for &case in &cases {
        let mut first: Option<Vec<f64>> = None;
        for threads in [1, 2] {
            let r = run(case, threads);
            let s = &r.stats;
            println!(
                "| {} | {} | {} | {threads} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.6} | {:.6} | {:.6} | {} | {} |",
                case.label(),
                r.elements,
                r.unknowns,
                s.increments,
                s.iterations,
                s.factorisations,
                r.wall,
                r.cpu,
                s.assembly_seconds,
                s.solve_seconds,
                r.forces[0],
                r.forces[1],
                r.forces[2],
                distances(r.forces),
                s.loose
            );
            match &first {
                None => first = Some(r.all_forces.clone()),
                Some(g) => assert!(
                    g.iter()
                        .zip(&r.all_forces)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "forces differ between 1 and 2 threads"
                ),
            }
            if let MeshChoice::Graded(..) | MeshChoice::Quadratic(..) = case.mesh {
                bench_runs.push((case.label(), threads, r));
            }
        }
    }
    println!(
        "| CalculiX 2.20 n6 (480 CAX8R, K = 1000 mu, penalty contact; recorded) | 480 | {CCX_UNKNOWNS} | 1 | - | ~900 (README) | - | {CCX_WALL:.1} (README {CCX_README_WALL:.0}) | {CCX_CPU:.1} | - | - | {:.6} | {:.6} | {:.6} | {} | - |",
        CCX_FORCES[0],
        CCX_FORCES[1],
        CCX_FORCES[2],
        distances(CCX_FORCES)
    );
    let mut ccx = (CCX_WALL, CCX_CPU);
    if with_ccx {
        match calculix() {
            Some((wall, cpu)) => {
                println!(
                    "| CalculiX 2.20 n6 (rerun now) | 480 | {CCX_UNKNOWNS} | 1 | - | - | - | {wall:.1} | {cpu:.1} | - | - | - | - | - | - | - |"
                );
                ccx = (wall, cpu);
            }
            None => println!("CalculiX: `ccx` not found or failed"),
        }
    }
    for (label, threads, r) in &bench_runs {
        println!(
            "speed-up of {label} on {threads} thread(s) against CalculiX: {:.0}x wall ({:.0}x against the README's {CCX_README_WALL:.0} s), {:.0}x CPU",
            ccx.0 / r.wall,
            CCX_README_WALL / r.wall,
            ccx.1 / r.cpu
        );
    }
}
