//! Q1 mesh study (docs/validation/fe.md, "Q1"): the elastic flat-punch force
//! at a small depth against Sneddon's 8 G a d on one grading.
//! `cargo run --release -p palpate-tools --bin convergence_q1 -- H_FINE GROWTH EDGE [DEPTH]
//! [--aug 20] [--pen P] [--gauss] [--refine N]` (`--help` says what each is).
use clap::Parser;
use palpate_core::{Drive, Loading};
use palpate_fe::mesh::Grading;
use palpate_fe::Q1Punch;

/// The elastic flat-punch force of Q1 at a small depth on one grading,
/// against Sneddon's 8 G a d.
#[derive(Parser)]
struct Args {
    /// Element size at the punch edge (mm).
    h_fine: f64,
    /// Growth factor of the grading away from the edge.
    growth: f64,
    /// Edge radius of the punch (mm).
    edge: f64,
    /// Depth (mm).
    #[arg(default_value_t = 0.1)]
    depth: f64,
    /// Augmentations of the contact's inner loop (the model's default if absent).
    #[arg(long)]
    aug: Option<usize>,
    /// Contact penalty factor (the model's default if absent).
    #[arg(long)]
    pen: Option<f64>,
    /// Contact at fixed Gauss points of the edges instead of the split quadrature.
    #[arg(long)]
    gauss: bool,
    /// Edge refinement count (the model's default if absent).
    #[arg(long)]
    refine: Option<usize>,
}

fn main() {
    let a = Args::parse();
    let (h, growth, edge, depth) = (a.h_fine, a.growth, a.edge, a.depth);
    let mut m = Q1Punch::new("neo-hookean".parse().unwrap());
    m.grading = Some(Grading {
        h_fine: h,
        fine_length: 3.0,
        growth,
    });
    m.edge_radius = edge;
    if let Some(n) = a.aug {
        m.options.max_augmentations = n;
    }
    if a.gauss {
        m.contact_points = palpate_fe::ContactPoints::EdgeGauss;
    }
    if let Some(n) = a.refine {
        m.edge_refinement = n;
    }
    if let Some(p) = a.pen {
        m.penalty = p;
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
