//! Mesh convergence of N1 (docs/benchmarks.md): neo-Hookean `ecoflex-nh`,
//! friction 0.8, bonded base, exact incompressibility, force at 2, 5 and
//! 10 mm on mesh levels 1, 2, 3 (element size 0.4 / level mm under the
//! needle). Prints the forces, the differences between successive meshes,
//! the observed order p from each three successive levels (solving
//! `(F1 - F2) / (F2 - F3) = (h1^p - h2^p) / (h2^p - h3^p)`) and the
//! Richardson-extrapolated force `F3 - (F2 - F3) h3^p / (h2^p - h3^p)`.
//!
//! Besides levels, an argument `h/zone/growth` (e.g. `0.2/3/1.1`) runs a
//! custom grading ([`palpate_fe::mesh::Grading`]: fine element size, fine
//! zone, outward growth), and every row prints its distance from the force
//! of level 5 ([`LEVEL5`], 20615 elements, the finest run; its own distance
//! from the converged force is in docs/validation/fe.md, "N1 speed"). Each
//! run is on one thread; the CPU column is the process user + system time
//! of the run (`/proc/self/stat`).
//!
//! `--max-step=S` (mm, default 0.25), `--penalty=P` (default 100) and
//! `--augment=TOL` (inner augmentation loop to a penetration of TOL mm) change
//! the increment size and the contact penalty factor, to separate their
//! errors from the mesh's.
//!
//! `cargo run --release -p palpate-tools --bin convergence_n1 -- [level | h/zone/growth ...] [--max-step=S] [--penalty=P] [--augment=TOL]`

use palpate_core::{Drive, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::{MeshDensity, N1Needle};

const C10: f64 = 1101.295e-6;
const AT: [f64; 3] = [2.0, 5.0, 10.0];
/// Force of level 5 at 2, 5 and 10 mm (N): `convergence_n1 5` (222 s CPU).
const LEVEL5: [f64; 3] = [0.045322, 0.155379, 0.394378];

/// A mesh to run: a standard level or a custom grading.
#[derive(Clone, Copy)]
enum Case {
    Level(usize),
    Graded(Grading),
}

impl Case {
    fn parse(arg: &str) -> Option<Case> {
        if let Ok(level) = arg.parse() {
            return Some(Case::Level(level));
        }
        let v: Vec<f64> = arg.split('/').filter_map(|s| s.parse().ok()).collect();
        (v.len() == 3).then(|| {
            Case::Graded(Grading {
                h_fine: v[0],
                fine_length: v[1],
                growth: v[2],
            })
        })
    }
    fn label(&self) -> String {
        match self {
            Case::Level(l) => format!("level {l}"),
            Case::Graded(g) => format!("{}/{}/{}", g.h_fine, g.fine_length, g.growth),
        }
    }
    fn h_fine(&self) -> f64 {
        match self {
            Case::Level(l) => MeshDensity { level: *l }.h_fine(),
            Case::Graded(g) => g.h_fine,
        }
    }
}

use palpate_tools::cpu;

fn cpu_seconds() -> f64 {
    cpu::cpu_seconds(false)
}

struct Row {
    forces: [f64; 3],
    elements: usize,
    unknowns: usize,
    wall: f64,
    cpu: f64,
}

/// Solver knobs that are not the mesh.
#[derive(Clone, Copy)]
struct Knobs {
    max_step: Option<f64>,
    penalty: Option<f64>,
    /// Inner augmentation loop: accepted penetration (mm), up to 20 updates.
    augment: Option<f64>,
}

fn forces(case: Case, knobs: Knobs) -> Row {
    let mut m = N1Needle::new("neo-hookean".parse().expect("law"));
    if let Some(s) = knobs.max_step {
        m.options.max_step = s;
    }
    if let Some(p) = knobs.penalty {
        m.penalty = p;
    }
    if let Some(tol) = knobs.augment {
        m.penetration_tol = tol;
        m.options.max_augmentations = 20;
    }
    match case {
        Case::Level(level) => m.mesh = MeshDensity { level },
        Case::Graded(g) => m.grading = Some(g),
    }
    let drive: Vec<f64> = (1..=40).map(|k| 0.25 * k as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("thread pool");
    let (t, c) = (std::time::Instant::now(), cpu_seconds());
    let (sim, solver) = pool
        .install(|| m.simulate(&[C10], &loading, None))
        .unwrap_or_else(|e| panic!("{}: {e}", case.label()));
    let (wall, cpu) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
    let f = &sim.forces;
    let at = |d: f64| f[(d / 0.25).round() as usize - 1];
    Row {
        forces: [at(AT[0]), at(AT[1]), at(AT[2])],
        elements: solver.mesh.cell_count(),
        unknowns: solver.equations(),
        wall,
        cpu,
    }
}

/// Observed order from three meshes (bisection on p in [0.2, 6]).
fn order(h: [f64; 3], f: [f64; 3]) -> Option<f64> {
    let ratio = (f[0] - f[1]) / (f[1] - f[2]);
    let g = |p: f64| (h[0].powf(p) - h[1].powf(p)) / (h[1].powf(p) - h[2].powf(p)) - ratio;
    let (mut lo, mut hi) = (0.2, 6.0);
    if g(lo) * g(hi) >= 0.0 || g(lo).is_nan() || g(hi).is_nan() {
        return None;
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if g(lo) * g(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

fn pct(a: f64, b: f64) -> f64 {
    100.0 * (a - b) / b
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |name: &str| -> Option<f64> {
        args.iter()
            .find_map(|a| a.strip_prefix(name))
            .and_then(|v| v.parse().ok())
    };
    let knobs = Knobs {
        max_step: flag("--max-step="),
        penalty: flag("--penalty="),
        augment: flag("--augment="),
    };
    let mut cases: Vec<Case> = args.iter().filter_map(|a| Case::parse(a)).collect();
    if cases.is_empty() {
        cases = vec![Case::Level(1), Case::Level(2), Case::Level(3)];
    }
    println!("Distances from the force of level 5 {LEVEL5:?} N; one thread per run.");
    println!("| mesh (h/zone/growth) | h (mm) | elements | unknowns | F(2) N | F(5) N | F(10) N | vs level 5 at 2/5/10 mm (%) | wall (s) | CPU (s) |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut levels = Vec::new();
    for case in cases {
        let r = forces(case, knobs);
        let f = r.forces;
        println!(
            "| {} | {:.4} | {} | {} | {:.6} | {:.6} | {:.6} | {:+.3} / {:+.3} / {:+.3} | {:.1} | {:.1} |",
            case.label(),
            case.h_fine(),
            r.elements,
            r.unknowns,
            f[0],
            f[1],
            f[2],
            pct(f[0], LEVEL5[0]),
            pct(f[1], LEVEL5[1]),
            pct(f[2], LEVEL5[2]),
            r.wall,
            r.cpu
        );
        if let Case::Level(_) = case {
            levels.push((case.h_fine(), f));
        }
    }
    for w in levels.windows(2) {
        let rel: Vec<String> = (0..3)
            .map(|k| format!("{:+.3} %", pct(w[1].1[k], w[0].1[k])))
            .collect();
        println!(
            "h {:.4} -> {:.4}: change at 2/5/10 mm {}",
            w[0].0,
            w[1].0,
            rel.join(" / ")
        );
    }
    for w in levels.windows(3) {
        let h = [w[0].0, w[1].0, w[2].0];
        for (k, d) in AT.iter().enumerate() {
            let f = [w[0].1[k], w[1].1[k], w[2].1[k]];
            match order(h, f) {
                Some(p) => {
                    let ext = f[2] - (f[1] - f[2]) * h[2].powf(p) / (h[1].powf(p) - h[2].powf(p));
                    println!(
                        "h {:.4}/{:.4}/{:.4} at {d} mm: observed order {p:.2}, extrapolated {ext:.6} N (finest {:+.3} % from it)",
                        h[0], h[1], h[2],
                        pct(f[2], ext)
                    );
                }
                None => println!("at {d} mm: not monotone, no order"),
            }
        }
    }
}
