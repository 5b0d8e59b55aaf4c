//! Q1 deep indentation diagnostics (docs/validation/fe.md, "Q1"): the
//! elastic ramp to DEPTH in STEP increments on a given mesh level, printing
//! where it stops, the deformed top surface near the punch edge and the
//! smallest corner Jacobian there, and writing the last converged state as
//! VTU (`OUT.vtu`) for ParaView (Warp By Vector on `displacement`).
//!
//! `cargo run --release -p palpate-tools --bin q1_deep -- LEVEL DEPTH [EDGE] [C10] [OUT.vtu]
//! [OPTIONS]` (`--help` lists the options: sample spacing, contact
//! smoothing, contact points, line search, stagnation, a viscoelastic hold,
//! self-contact, a bulk penalty, the proximal stabilisation, the whole curve).
use clap::Parser;
use palpate_core::{Drive, ForwardError, Loading};
use palpate_fe::mesh::jacobian::corner_jacobians;
use palpate_fe::Q1Punch;

/// Q1's elastic ramp to DEPTH: where it stops, the top surface near the
/// punch edge, the smallest corner Jacobian there, and the last converged
/// state as VTU.
#[derive(Parser)]
struct Args {
    /// Mesh level.
    level: usize,
    /// Depth of the ramp (mm).
    depth: f64,
    /// Edge radius of the punch (mm).
    #[arg(default_value_t = 0.2)]
    edge: f64,
    /// Neo-Hookean C10 (MPa).
    #[arg(default_value_t = 1e-3)]
    c10: f64,
    /// Where to write the last converged state (VTU).
    out: Option<String>,
    /// Sample spacing of the ramp (mm).
    #[arg(long, default_value_t = 0.05)]
    step: f64,
    /// Edge refinement count (the model's default if absent).
    #[arg(long)]
    refine: Option<usize>,
    /// Contact smoothing as a fraction of the element size.
    #[arg(long)]
    smooth: Option<f64>,
    /// Contact at the nodes.
    #[arg(long)]
    nodes: bool,
    /// Contact at fixed Gauss points of the edges instead of the split quadrature.
    #[arg(long)]
    gauss: bool,
    /// The proximal stabilisation (0: off).
    #[arg(long)]
    prox: Option<f64>,
    /// The relative residual at which a stagnating increment is accepted.
    #[arg(long)]
    stag: Option<f64>,
    /// The slope line search instead of the default.
    #[arg(long)]
    slope_line_search: bool,
    /// Without the surface's self-contact.
    #[arg(long)]
    no_self_contact: bool,
    /// A mean-dilatation penalty K = BULK mu instead of the exact constraint.
    #[arg(long)]
    bulk: Option<f64>,
    /// Seconds of hold after a 0.5 s viscoelastic ramp (g 0.3 / 0.2, tau 0.5 / 10 s).
    #[arg(long)]
    hold: Option<f64>,
    /// Print the force at every sample.
    #[arg(long)]
    curve: bool,
}

fn main() {
    let a = Args::parse();
    let (level, depth, edge, c10, step) = (a.level, a.depth, a.edge, a.c10, a.step);
    let out = a.out.clone();
    let mut m = Q1Punch::new("neo-hookean".parse().unwrap());
    m.level = level;
    m.edge_radius = edge;
    if let Some(v) = a.refine {
        m.edge_refinement = v;
    }
    if let Some(v) = a.smooth {
        m.contact_smoothing = v;
    }
    if a.nodes {
        m.contact_points = palpate_fe::ContactPoints::Nodes;
    }
    if let Some(v) = a.prox {
        m.options.stabilisation = v;
    }
    if a.gauss {
        m.contact_points = palpate_fe::ContactPoints::EdgeGauss;
    }
    if let Some(v) = a.stag {
        m.options.stagnation_tolerance = v;
    }
    if a.slope_line_search {
        m.options.line_search = palpate_fe::LineSearch::Slope;
    }
    m.self_contact = !a.no_self_contact;
    if let Some(v) = a.bulk {
        // a mean-dilatation penalty K = BULK mu instead of the exact constraint
        m.bulk = palpate_fe::Bulk::Ratio(v);
    }
    let n = (depth / step).round().max(1.0) as usize;
    let drive: Vec<f64> = (1..=n).map(|k| depth * k as f64 / n as f64).collect();
    let t0 = std::time::Instant::now();
    let hold = a.hold;
    let loading = match hold {
        None => Loading::quasi_static(Drive::DisplacementMm, drive.clone()),
        Some(h) => {
            // viscoelastic (g 0.3 / 0.2, tau 0.5 / 10 s): ramp in 0.5 s, hold h s
            m.prony = Some(palpate_fe::Prony::new(vec![(0.3, 0.5), (0.2, 10.0)]).unwrap());
            let mut t: Vec<f64> = (1..=n).map(|k| 0.5 * k as f64 / n as f64).collect();
            let mut d = drive.clone();
            for k in 1..=20 {
                t.push(0.5 + h * k as f64 / 20.0);
                d.push(depth);
            }
            let l = Loading::timed(Drive::DisplacementMm, t, d);
            let r = m.simulate(&[c10], &l, None);
            match r {
                Ok((sim, _)) => println!(
                    "hold: reached, F ramp end {:.6e} end {:.6e}, {} increments, {:.1} s",
                    sim.forces[n - 1],
                    sim.forces.last().unwrap(),
                    sim.stats.increments,
                    t0.elapsed().as_secs_f64()
                ),
                Err(e) => println!("hold: {e}"),
            }
            return;
        }
    };
    let reached = match m.simulate(&[c10], &loading, None) {
        Ok((sim, _)) => {
            if a.curve {
                for (d, f) in drive.iter().zip(&sim.forces) {
                    println!("curve {d:.3} {f:.6e}");
                }
            }
            println!(
                "level {level} edge {edge}: reached {depth} mm, F {:.6e} N, {} increments, {:.1} s",
                sim.forces.last().unwrap(),
                sim.stats.increments,
                t0.elapsed().as_secs_f64()
            );
            depth
        }
        Err(ForwardError::NotConverged {
            drive: at,
            completed,
            reason,
            ..
        }) => {
            println!(
                "level {level} edge {edge}: stopped at {at} mm after {} samples ({:.1} s): {reason}",
                completed.len(),
                t0.elapsed().as_secs_f64()
            );
            if completed.is_empty() {
                return;
            }
            drive[completed.len() - 1]
        }
        Err(e) => panic!("{e}"),
    };
    // the last converged sample again, to look at it
    let k = drive
        .iter()
        .position(|&d| d >= reached - 1e-9)
        .unwrap_or(n - 1);
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive[..=k].to_vec());
    let (sim, sys) = m.simulate(&[c10], &loading, None).unwrap();
    println!("at {} mm: F {:.6e} N", drive[k], sim.forces.last().unwrap());
    let u = sys.displacements();
    let top = sys.mesh.node_set("top").unwrap();
    println!(
        "top surface near the punch (reference r -> current r, z - height, tool bottom at -{}):",
        drive[k]
    );
    for &nd in top {
        let x = sys.mesh.nodes[nd];
        if x[0] > 1.2 && x[0] < 3.0 {
            println!(
                "  r0 {:.3} -> r {:.4} z {:.4}",
                x[0],
                x[0] + u[nd][0],
                u[nd][1]
            );
        }
    }
    // smallest corner Jacobian (relative to the reference) of cells near the edge
    let mut worst = (f64::INFINITY, 0usize);
    for (e, cell) in sys.mesh.cells().enumerate() {
        let x0: Vec<[f64; 3]> = cell.iter().map(|&i| sys.mesh.nodes[i]).collect();
        if x0
            .iter()
            .any(|p| (p[0] - 2.0).abs() > 1.0 || p[1] < m.height - 1.0)
        {
            continue;
        }
        let x: Vec<[f64; 3]> = cell
            .iter()
            .map(|&i| {
                let p = sys.mesh.nodes[i];
                [p[0] + u[i][0], p[1] + u[i][1], 0.0]
            })
            .collect();
        let j0 = corner_jacobians(sys.mesh.cell_type, &x0);
        let j = corner_jacobians(sys.mesh.cell_type, &x);
        for (a, b) in j.iter().zip(&j0) {
            if a / b < worst.0 {
                worst = (a / b, e);
            }
        }
    }
    let c = sys.mesh.cell(worst.1);
    println!(
        "smallest corner J/J0 near the edge: {:.4} in cell {} (reference corner {:?})",
        worst.0, worst.1, sys.mesh.nodes[c[0]]
    );
    if let Some(path) = out {
        std::fs::write(&path, palpate_fe::vtu::to_vtu(&sys).unwrap()).unwrap();
        println!("wrote {path}");
    }
}
