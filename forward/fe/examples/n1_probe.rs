//! Quick N1 run printing the curve (development probe).
use palpate_core::{Drive, Loading};
use palpate_fe::{MeshDensity, N1Needle};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let level: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let friction: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.8);
    let depth: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(10.0);
    let mut m = N1Needle::new("neo-hookean".parse().unwrap());
    m.mesh = MeshDensity { level };
    m.friction = friction;
    if let Some(p) = args.get(5).and_then(|s| s.parse::<f64>().ok()) {
        m.penalty = p;
    }
    if let Some(r) = args.get(4).and_then(|s| s.parse::<f64>().ok()) {
        m.bulk = palpate_fe::Bulk::Ratio(r);
    }
    let n = (depth / 0.5).round() as usize;
    let loading = Loading::quasi_static(
        Drive::DisplacementMm,
        (1..=n).map(|k| 0.5 * k as f64).collect(),
    );
    let t = std::time::Instant::now();
    let cb = |p: &palpate_fe::Progress| {
        eprintln!(
            "d {:6.3} F {:.6} inc {} it {} t {:.1}s",
            p.drive,
            p.force,
            p.increments,
            p.iterations,
            t.elapsed().as_secs_f64()
        )
    };
    match m.simulate(&[1101.295e-6], &loading, Some(&cb)) {
        Ok((sim, solver)) => println!(
            "{:?} eqs {} elements {}",
            sim.stats,
            solver.equations(),
            solver.mesh.elements.len()
        ),
        Err(e) => println!("error {e}"),
    }
}
