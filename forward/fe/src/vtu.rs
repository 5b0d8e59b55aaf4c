//! VTK XML UnstructuredGrid (.vtu, ASCII) output of the deformed state for
//! ParaView: reference mesh (r, z, 0) with point data `displacement` and cell
//! data `pressure` (hydrostatic, compression positive, MPa) and the mean
//! Cauchy stress components `stress_rr`, `stress_zz`, `stress_tt`, `stress_rz`.
//! Use ParaView's "Warp By Vector" on `displacement` for the deformed shape.

use std::fmt::Write;

use crate::element::mean_cauchy_stress;
use crate::material::PointMaterial;
use crate::solver::Solver;

/// The current state of `solver` as a .vtu document.
pub fn to_vtu(solver: &Solver, mat: &dyn PointMaterial) -> String {
    let mesh = &solver.mesh;
    let pressures = solver.pressures();
    let mut s = String::new();
    let (np, nc) = (mesh.nodes.len(), mesh.elements.len());
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">"
    );
    let _ = writeln!(
        s,
        "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">"
    );
    let _ = writeln!(
        s,
        "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
    );
    for p in &mesh.nodes {
        let _ = writeln!(s, "{} {} 0", p[0], p[1]);
    }
    let _ = writeln!(s, "</DataArray>\n</Points>\n<Cells>");
    let _ = writeln!(
        s,
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    );
    for e in &mesh.elements {
        let _ = writeln!(s, "{} {} {} {}", e[0], e[1], e[2], e[3]);
    }
    let _ = writeln!(
        s,
        "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    );
    for k in 0..nc {
        let _ = writeln!(s, "{}", 4 * (k + 1));
    }
    let _ = writeln!(
        s,
        "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    );
    for _ in 0..nc {
        let _ = writeln!(s, "9");
    }
    let _ = writeln!(
        s,
        "</DataArray>\n</Cells>\n<PointData Vectors=\"displacement\">"
    );
    let _ = writeln!(s, "<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">");
    for u in &solver.u {
        let _ = writeln!(s, "{} {} 0", u[0], u[1]);
    }
    let _ = writeln!(
        s,
        "</DataArray>\n</PointData>\n<CellData Scalars=\"pressure\">"
    );
    let _ = writeln!(
        s,
        "<DataArray type=\"Float64\" Name=\"pressure\" format=\"ascii\">"
    );
    for p in &pressures {
        let _ = writeln!(s, "{}", -p);
    }
    let _ = writeln!(s, "</DataArray>");
    let stresses: Vec<[f64; 4]> = mesh
        .elements
        .iter()
        .enumerate()
        .map(|(e, el)| {
            let x = el.map(|n| mesh.nodes[n]);
            let u = el.map(|n| solver.u[n]);
            mean_cauchy_stress(solver.kinematics, &x, &u, pressures[e], mat)
        })
        .collect();
    for (k, name) in ["stress_rr", "stress_zz", "stress_tt", "stress_rz"]
        .iter()
        .enumerate()
    {
        let _ = writeln!(
            s,
            "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
        );
        for st in &stresses {
            let _ = writeln!(s, "{}", st[k]);
        }
        let _ = writeln!(s, "</DataArray>");
    }
    let _ = writeln!(s, "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>");
    s
}
