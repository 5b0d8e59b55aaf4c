//! Diagnostic: N3 with 27-node hexahedra, frictionless, run to
//! `DEPTH` (mm) every 0.25 mm; writes the deformed state's VTU to `OUT` and
//! prints, for the cells whose smallest Gauss-point det F or corner
//! Jacobian of the deformed geometry is lowest, where they are.
//!
//! `cargo run --release -p palpate-tools --bin n3_deep -- DEPTH OUT.vtu [h,zone,growth]`

use palpate_core::{Drive, Loading};
use palpate_fe::mesh::jacobian::corner_jacobians;
use palpate_fe::mesh::Grading;
use palpate_fe::{N3Element, N3Mesh, N3Needle};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let depth: f64 = args.first().map_or(5.0, |a| a.parse().expect("mm"));
    let out = args.get(1).cloned().unwrap_or_else(|| "n3_deep.vtu".into());
    let g: Vec<f64> = args
        .get(2)
        .map_or("1.6,4,1.8".into(), |s| s.clone())
        .split(',')
        .map(|v| v.parse().expect("h,zone,growth"))
        .collect();
    let mut m = N3Needle::new("neo-hookean".parse().expect("law"));
    m.mesh = N3Mesh::OGrid;
    m.element = N3Element::Hex27;
    m.friction = 0.0;
    m.grading = Some(Grading {
        h_fine: g[0],
        fine_length: g[1],
        growth: g[2],
    });
    let n = (depth / 0.25).round() as usize;
    let drive: Vec<f64> = (1..=n).map(|k| 0.25 * k as f64).collect();
    let loading = Loading::quasi_static(Drive::DisplacementMm, drive);
    let (sim, sys) = match m.simulate(&[1101.295e-6], &loading, None) {
        Ok(r) => r,
        Err(e) => {
            println!("stopped: {e}");
            return;
        }
    };
    println!("F = {:?}", sim.forces.last());
    std::fs::write(&out, palpate_fe::vtu::to_vtu(&sys).expect("vtu")).expect("write");
    let mesh = &sys.mesh;
    let mut worst: Vec<(f64, usize, [f64; 3], [f64; 3])> = Vec::new();
    for (e, c) in mesh.cells().enumerate() {
        let x: Vec<[f64; 3]> = c
            .iter()
            .map(|&a| {
                let p = mesh.nodes[a];
                [
                    p[0] + sys.u[3 * a],
                    p[1] + sys.u[3 * a + 1],
                    p[2] + sys.u[3 * a + 2],
                ]
            })
            .collect();
        let x0: Vec<[f64; 3]> = c.iter().map(|&a| mesh.nodes[a]).collect();
        let j = corner_jacobians(mesh.cell_type, &x);
        let j0 = corner_jacobians(mesh.cell_type, &x0);
        let r = j
            .iter()
            .zip(&j0)
            .map(|(a, b)| a / b)
            .fold(f64::INFINITY, f64::min);
        worst.push((r, e, x0[26], x[26]));
    }
    worst.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (r, e, p0, p) in worst.iter().take(8) {
        println!(
            "cell {e}: min corner J/J0 {r:.3}, centre from ({:.2}, {:.2}, {:.2}) to ({:.2}, {:.2}, {:.2})",
            p0[0], p0[1], p0[2], p[0], p[1], p[2]
        );
    }
}
