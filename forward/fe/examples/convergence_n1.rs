//! Mesh convergence of N1 (BENCHMARKS.md): neo-Hookean `ecoflex-nh`,
//! friction 0.8, bonded base, exact incompressibility, force at 2, 5 and
//! 10 mm on mesh levels 1, 2, 3 (element size 0.4 / level mm under the
//! needle). Prints the forces, the differences between successive meshes,
//! the observed order p from the three meshes (solving
//! `(F1 - F2) / (F2 - F3) = (h1^p - h2^p) / (h2^p - h3^p)`) and the
//! Richardson-extrapolated force `F3 - (F2 - F3) h3^p / (h2^p - h3^p)`.
//!
//! `cargo run --release -p palpate-fe --example convergence_n1 -- [levels...]`

use palpate_core::{Drive, ForwardModel, Loading};
use palpate_fe::{MeshDensity, N1Needle};

const C10: f64 = 1101.295e-6;
const AT: [f64; 3] = [2.0, 5.0, 10.0];

fn forces(level: usize) -> (Vec<f64>, usize, f64) {
    let mut m = N1Needle::new("neo-hookean".parse().expect("law"));
    m.mesh = MeshDensity { level };
    let drive: Vec<f64> = (1..=40).map(|k| 0.25 * k as f64).collect();
    let t = std::time::Instant::now();
    let f = m
        .predict(&[C10], &Loading::quasi_static(Drive::DisplacementMm, drive))
        .unwrap_or_else(|e| panic!("level {level}: {e}"));
    let elements = m.build_mesh().map(|m| m.elements.len()).unwrap_or(0);
    let picked = AT
        .iter()
        .map(|d| f[(d / 0.25).round() as usize - 1])
        .collect();
    (picked, elements, t.elapsed().as_secs_f64())
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

fn main() {
    let mut levels: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    if levels.is_empty() {
        levels = vec![1, 2, 3];
    }
    println!("| level | h (mm) | elements | F(2) N | F(5) N | F(10) N | wall (s) |");
    println!("|---|---|---|---|---|---|---|");
    let mut rows = Vec::new();
    for &l in &levels {
        let (f, ne, wall) = forces(l);
        let h = MeshDensity { level: l }.h_fine();
        println!(
            "| {l} | {h:.4} | {ne} | {:.6} | {:.6} | {:.6} | {wall:.1} |",
            f[0], f[1], f[2]
        );
        rows.push((h, f));
    }
    for w in rows.windows(2) {
        let rel: Vec<String> = (0..3)
            .map(|k| format!("{:+.3} %", 100.0 * (w[1].1[k] - w[0].1[k]) / w[1].1[k]))
            .collect();
        println!(
            "h {:.4} -> {:.4}: change at 2/5/10 mm {}",
            w[0].0,
            w[1].0,
            rel.join(" / ")
        );
    }
    for w in rows.windows(3) {
        let h = [w[0].0, w[1].0, w[2].0];
        for (k, d) in AT.iter().enumerate() {
            let f = [w[0].1[k], w[1].1[k], w[2].1[k]];
            match order(h, f) {
                Some(p) => {
                    let ext = f[2] - (f[1] - f[2]) * h[2].powf(p) / (h[1].powf(p) - h[2].powf(p));
                    println!(
                        "at {d} mm: observed order {p:.2}, extrapolated {ext:.6} N (finest {:+.3} % from it)",
                        100.0 * (f[2] - ext) / ext
                    );
                }
                None => println!("at {d} mm: not monotone, no order"),
            }
        }
    }
}
