//! Q1 deep indentation diagnostics (docs/validation/fe.md, "Q1"): the
//! elastic ramp to DEPTH in STEP increments on a given mesh level, printing
//! where it stops, the deformed top surface near the punch edge and the
//! smallest corner Jacobian there, and writing the last converged state as
//! VTU (`OUT.vtu`) for ParaView (Warp By Vector on `displacement`).
//!
//! `cargo run --release -p palpate-tools --bin q1_deep -- LEVEL DEPTH [EDGE] [C10] [OUT.vtu]`
//! (env `STEP=` sample spacing in mm, default 0.05; `SMOOTH=` the contact
//! smoothing as a fraction of the element size; `NODES=1` contact at the
//! nodes; `LINE=slope` the slope line search; `STAG=` the relative
//! residual at which a stagnating increment is accepted; `HOLD=` seconds: viscoelastic ramp in 0.5 s and hold; `SELF=0` without the
//! surface's self-contact; `BULK=` a bulk modulus of BULK x mu instead of
//! the exact constraint; `GAUSS=1` contact at fixed Gauss points of the
//! edges instead of the split quadrature; `PROX=` the proximal
//! stabilisation, 0 off; `CURVE=1` prints the force at every sample).
use palpate_core::{Drive, ForwardError, Loading};
use palpate_fe::mesh::jacobian::corner_jacobians;
use palpate_fe::Q1Punch;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let level: usize = args[1].parse().unwrap();
    let depth: f64 = args[2].parse().unwrap();
    let edge: f64 = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(0.2);
    let c10: f64 = args.get(4).map(|s| s.parse().unwrap()).unwrap_or(1e-3);
    let out = args.get(5).cloned();
    let step: f64 = std::env::var("STEP")
        .ok()
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.05);
    let mut m = Q1Punch::new("neo-hookean".parse().unwrap());
    m.level = level;
    m.edge_radius = edge;
    if let Ok(v) = std::env::var("REFINE") {
        m.edge_refinement = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("SMOOTH") {
        m.contact_smoothing = v.parse().unwrap();
    }
    if let Ok(v) = std::env::var("NODES") {
        if v == "1" {
            m.contact_points = palpate_fe::ContactPoints::Nodes;
        }
    }
    if let Ok(v) = std::env::var("PROX") {
        m.options.stabilisation = v.parse().unwrap();
    }
    if std::env::var("GAUSS").as_deref() == Ok("1") {
        m.contact_points = palpate_fe::ContactPoints::EdgeGauss;
    }
    if let Ok(v) = std::env::var("STAG") {
        m.options.stagnation_tolerance = v.parse().unwrap();
    }
    if std::env::var("LINE").as_deref() == Ok("slope") {
        m.options.line_search = palpate_fe::LineSearch::Slope;
    }
    m.self_contact = std::env::var("SELF").map(|v| v != "0").unwrap_or(true);
    if let Ok(v) = std::env::var("BULK") {
        // a mean-dilatation penalty K = BULK mu instead of the exact constraint
        m.bulk = palpate_fe::Bulk::Ratio(v.parse().unwrap());
    }
    let n = (depth / step).round().max(1.0) as usize;
    let drive: Vec<f64> = (1..=n).map(|k| depth * k as f64 / n as f64).collect();
    let t0 = std::time::Instant::now();
    let hold: Option<f64> = std::env::var("HOLD").ok().map(|s| s.parse().unwrap());
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
            if std::env::var("CURVE").is_ok() {
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
