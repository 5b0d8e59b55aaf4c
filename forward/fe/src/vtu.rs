//! VTK XML UnstructuredGrid (.vtu) output of a solved system for ParaView:
//! the reference mesh (any cell type, [`crate::mesh::vtu`]) with point data
//! `displacement` and, for every cell of the first solid body, `pressure`
//! (hydrostatic, compression positive, MPa) and the volume-average Cauchy
//! stress `stress_xx, stress_yy, stress_zz, stress_xy, stress_yz, stress_zx`
//! (in axisymmetry x, y, z are r, z, theta). Use ParaView's "Warp By
//! Vector" on `displacement` for the deformed shape.

use crate::body::SolidBody;
use crate::mesh::vtu::{mesh_vtu, Field};
use crate::system::System;
use crate::FeError;

/// The current state of `sys` as a .vtu document.
pub fn to_vtu(sys: &System) -> Result<String, FeError> {
    let mesh = &sys.mesh;
    let u: Vec<f64> = sys.displacements().into_iter().flatten().collect();
    let nc = mesh.cell_count();
    let mut pressure = vec![0.0; nc];
    let mut stress = vec![vec![0.0; nc]; 6];
    if let Some(body) = sys
        .contributions
        .iter()
        .find_map(|c| c.as_any().downcast_ref::<SolidBody>())
    {
        let p = body.pressures();
        let s = body.mean_cauchy_stresses(&sys.u, sys.dofs.dim);
        for (k, &cell) in body.cells().iter().enumerate() {
            pressure[cell] = -p[k];
            for (i, st) in stress.iter_mut().enumerate() {
                st[cell] = if s[k][i].is_finite() { s[k][i] } else { 0.0 };
            }
        }
    }
    let names = [
        "stress_xx",
        "stress_yy",
        "stress_zz",
        "stress_xy",
        "stress_yz",
        "stress_zx",
    ];
    let mut cell_data = vec![Field {
        name: "pressure",
        components: 1,
        values: &pressure,
    }];
    for (name, values) in names.iter().zip(&stress) {
        cell_data.push(Field {
            name,
            components: 1,
            values,
        });
    }
    mesh_vtu(
        mesh,
        &[Field {
            name: "displacement",
            components: 3,
            values: &u,
        }],
        &cell_data,
    )
}
