//! Q1's top-surface nodes near the punch edge against depth, sampled finely
//! before the stop near 2 mm (docs/validation/fe.md "Q1"): does
//! the equilibrium path turn (a fold, where the nodes would run away as the
//! stop nears) or stay straight up to it?
//!
//! `cargo run --release -p palpate-tools --bin q1_fold -- LEVEL FINE_FROM TO FINE_STEP
//! [--refine N] [--edge MM]` (0.05 mm samples to FINE_FROM, then FINE_STEP
//! to TO; the edge refinement and edge radius default to the model's). Prints, per sample from 0.2 mm
//! before FINE_FROM, the depth, the punch force and each watched node's
//! current `r / z - height`, then where the run stopped.
use clap::Parser;
use palpate_core::{Drive, Loading};
use palpate_fe::stepper::{run, LoadPath};
use palpate_fe::Q1Punch;

/// Q1's top-surface nodes near the punch edge against depth, sampled finely
/// before the stop near 2 mm.
#[derive(Parser)]
struct Args {
    /// Mesh level.
    level: usize,
    /// Depth (mm) from which the samples are FINE_STEP apart (0.05 mm before).
    fine_from: f64,
    /// Final depth (mm).
    to: f64,
    /// Sample spacing (mm) from FINE_FROM.
    fine_step: f64,
    /// Edge refinement count (the model's default if absent).
    #[arg(long)]
    refine: Option<usize>,
    /// Edge radius of the punch (mm; the model's default if absent).
    #[arg(long)]
    edge: Option<f64>,
}

fn main() {
    let a = Args::parse();
    let (fine_from, to, fine) = (a.fine_from, a.to, a.fine_step);
    let mut m = Q1Punch::new("neo-hookean".parse().unwrap());
    m.level = a.level;
    if let Some(v) = a.refine {
        m.edge_refinement = v;
    }
    if let Some(v) = a.edge {
        m.edge_radius = v;
    }
    // a system with the material installed, from a first tiny run
    let tiny = Loading::quasi_static(Drive::DisplacementMm, vec![0.01]);
    let (_, mut sys) = m.simulate(&[1e-3], &tiny, None).unwrap();
    let mut drive = vec![];
    let mut d = 0.0;
    while d < fine_from - 1e-9 {
        d += 0.05;
        drive.push(d);
    }
    while d < to - 1e-9 {
        d += fine;
        drive.push(d);
    }
    let mut watched: Vec<usize> = sys
        .mesh
        .node_set("top")
        .unwrap()
        .iter()
        .copied()
        .filter(|&n| (sys.mesh.nodes[n][0] - m.punch_radius).abs() < 0.55)
        .collect();
    watched.sort_by(|a, b| sys.mesh.nodes[*a][0].total_cmp(&sys.mesh.nodes[*b][0]));
    print!("depth_mm force_N");
    for &n in &watched {
        print!(" r0={:.3}", sys.mesh.nodes[n][0]);
    }
    println!();
    let height = m.height;
    let mut observe = |s: &palpate_fe::System| {
        let u = s.displacements();
        let mut o = vec![s.contributions[1]
            .tool_force([0.0, -1.0, 0.0])
            .unwrap_or(0.0)];
        for &n in &watched {
            o.push(s.mesh.nodes[n][0] + u[n][0]);
            o.push(s.mesh.nodes[n][1] + u[n][1] - height);
        }
        o
    };
    let result = run(
        &mut sys,
        &LoadPath::from_drive(&drive),
        &m.options,
        &mut observe,
        None,
    );
    let (outputs, end) = match result {
        Ok(o) => (o, format!("reached {to} mm")),
        Err(f) => (
            f.completed,
            format!("stopped at {} mm: {}", f.drive, f.error),
        ),
    };
    for (k, o) in outputs.iter().enumerate() {
        if drive[k] < fine_from - 0.2 {
            continue;
        }
        print!("{:.5} {:.6e}", drive[k], o[0]);
        for p in o[1..].chunks(2) {
            print!(" {:.4}/{:.4}", p[0], p[1]);
        }
        println!();
    }
    println!("{end}");
}
