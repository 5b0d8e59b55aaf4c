//! Q1 mesh study (docs/validation/fe.md, "Q1"): the elastic flat-punch force
//! at a small depth against Sneddon's 8 G a d on one grading.
//! `cargo run --release -p palpate-tools --bin convergence_q1 -- H_FINE GROWTH EDGE [DEPTH]`
//! (env `AUG=20` for an inner augmentation loop, `PEN=` the penalty factor,
//! `GAUSS=1` contact at fixed Gauss points of the edges, `REFINE=` edge
//! refinement).
use palpate_core::{Drive, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::Q1Punch;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let h: f64 = args[1].parse().unwrap();
    let growth: f64 = args[2].parse().unwrap();
    let edge: f64 = args[3].parse().unwrap();
    let depth: f64 = args.get(4).map(|s| s.parse().unwrap()).unwrap_or(0.1);
    let mut m = Q1Punch::new("neo-hookean".parse().unwrap());
    m.grading = Some(Grading {
        h_fine: h,
        fine_length: 3.0,
        growth,
    });
    m.edge_radius = edge;
    if let Ok(a) = std::env::var("AUG") {
        m.options.max_augmentations = a.parse().unwrap();
    }
    if std::env::var("GAUSS").as_deref() == Ok("1") {
        m.contact_points = palpate_fe::ContactPoints::EdgeGauss;
    }
    if let Ok(a) = std::env::var("REFINE") {
        m.edge_refinement = a.parse().unwrap();
    }
    if let Ok(a) = std::env::var("PEN") {
        m.penalty = a.parse().unwrap();
    }
    let c10 = 1e-3;
    let g = 2.0 * c10;
    let n = 5;
    let drive: Vec<f64> = (1..=n).map(|k| depth * k as f64 / n as f64).collect();
    let t0 = std::time::Instant::now();
    let (sim, sys) = m
        .simulate(
            &[c10],
            &Loading::quasi_static(Drive::DisplacementMm, drive.clone()),
            None,
        )
        .unwrap();
    let f = *sim.forces.last().unwrap();
    let sneddon = 8.0 * g * m.punch_radius * depth;
    println!("h {h} growth {growth} edge {edge} d {depth}: cells {} F {f:.6e} Sneddon {sneddon:.6e} ratio {:.5} incr {} it {} {:.1}s",
        sys.mesh.cell_count(), f / sneddon, sim.stats.increments, sim.stats.iterations, t0.elapsed().as_secs_f64());
}
