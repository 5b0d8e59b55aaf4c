//! VTK XML UnstructuredGrid (`.vtu`, ASCII) output of a [`Mesh`] of any cell
//! type, with point and cell data, for ParaView.
//!
//! Source: "VTK File Formats" (VTK User's Guide / docs.vtk.org), XML
//! UnstructuredGrid: `Points` (three coordinates per node; `z = 0` in 2D),
//! `Cells` with `connectivity`, `offsets` (end of each cell's node list) and
//! `types`. VTK cell types: Line2 3 (VTK_LINE), Line3 21
//! (VTK_QUADRATIC_EDGE), Quad4 9 (VTK_QUAD), Quad9 28
//! (VTK_BIQUADRATIC_QUAD), Hex8 12 (VTK_HEXAHEDRON), Hex27 29
//! (VTK_TRIQUADRATIC_HEXAHEDRON); their node orders are VTK's, so
//! connectivity is written as stored.
//!
//! Every cell also gets the Int32 cell-data field `region`: the index, in
//! name order (the `BTreeMap` order of [`Mesh::regions`]), of the first
//! region holding the cell, or -1 for none; the names are listed in an XML
//! comment. Values are written with Rust's shortest round-trip formatting,
//! so a file read back gives the same `f64`s; non-finite values are refused
//! (VTK's ASCII reader does not take them).

use std::fmt::Write;

use super::{CellType, Mesh};
use crate::FeError;

/// A named data array: `components` values per point (or cell), flattened.
#[derive(Debug, Clone, Copy)]
pub struct Field<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: &'a [f64],
}

/// The VTK cell type code of a cell type.
pub const fn vtk_cell_type(t: CellType) -> u8 {
    match t {
        CellType::Line2 => 3,
        CellType::Line3 => 21,
        CellType::Quad4 => 9,
        CellType::Quad9 => 28,
        CellType::Hex8 => 12,
        CellType::Hex27 => 29,
    }
}

/// The mesh as a `.vtu` document with the given point data (one tuple per
/// node) and cell data (one tuple per cell) plus the cell field `region`.
pub fn mesh_vtu(mesh: &Mesh, point_data: &[Field], cell_data: &[Field]) -> Result<String, FeError> {
    let mut region = vec![-1i32; mesh.cell_count()];
    for (k, cells) in mesh.regions.values().enumerate() {
        for &e in cells {
            let r = region.get_mut(e).ok_or_else(|| FeError::InvalidMesh {
                field: "regions".into(),
                reason: format!("cell {e} does not exist"),
            })?;
            if *r < 0 {
                *r = k as i32;
            }
        }
    }
    let names: Vec<&str> = mesh.regions.keys().map(String::as_str).collect();
    write_vtu(
        mesh,
        mesh.cell_type,
        &mesh.cells,
        (&region, &names),
        point_data,
        cell_data,
    )
}

/// One facet set of the mesh as a `.vtu` document: its facets as cells over
/// all the mesh's nodes (so point data is given per mesh node), cell data
/// one tuple per facet; the `region` field is 0 (the set's name).
pub fn facet_set_vtu(
    mesh: &Mesh,
    name: &str,
    point_data: &[Field],
    cell_data: &[Field],
) -> Result<String, FeError> {
    let set = mesh.facet_set(name)?;
    let region = vec![0i32; set.len()];
    write_vtu(
        mesh,
        set.cell_type,
        &set.nodes,
        (&region, &[name]),
        point_data,
        cell_data,
    )
}

fn bad(name: &str, reason: String) -> FeError {
    FeError::InvalidConfig {
        field: format!("vtu field `{name}`"),
        reason,
    }
}

/// Checks a field's name and length against `count` points or cells.
fn check(fields: &[Field], count: usize, what: &str, taken: &[&str]) -> Result<(), FeError> {
    for (k, f) in fields.iter().enumerate() {
        if f.name.is_empty() || f.name.trim() != f.name {
            return Err(bad(f.name, "name is empty or padded with spaces".into()));
        }
        if taken.contains(&f.name) || fields[..k].iter().any(|g| g.name == f.name) {
            return Err(bad(f.name, format!("two {what} fields of this name")));
        }
        if f.components == 0 || f.values.len() != f.components * count {
            return Err(bad(
                f.name,
                format!(
                    "{} values for {count} {what}s x {} components",
                    f.values.len(),
                    f.components
                ),
            ));
        }
        if let Some(i) = f.values.iter().position(|v| !v.is_finite()) {
            return Err(bad(f.name, format!("value {i} is not finite")));
        }
    }
    Ok(())
}

/// Escapes text for an XML attribute or comment.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace("--", "&#45;&#45;")
}

fn write_field(s: &mut String, f: &Field) {
    let _ = writeln!(
        s,
        "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">",
        escape(f.name),
        f.components
    );
    for tuple in f.values.chunks_exact(f.components) {
        let line: Vec<String> = tuple.iter().map(|v| v.to_string()).collect();
        let _ = writeln!(s, "{}", line.join(" "));
    }
    let _ = writeln!(s, "</DataArray>");
}

fn write_vtu(
    mesh: &Mesh,
    cell_type: CellType,
    cells: &[usize],
    (region, region_names): (&[i32], &[&str]),
    point_data: &[Field],
    cell_data: &[Field],
) -> Result<String, FeError> {
    let per = cell_type.nodes();
    let (np, nc) = (mesh.nodes.len(), cells.len() / per);
    if !cells.len().is_multiple_of(per) {
        return Err(FeError::InvalidMesh {
            field: "cells".into(),
            reason: "connectivity length is not a multiple of the cell's node count".into(),
        });
    }
    if let Some(&n) = cells.iter().find(|&&n| n >= np) {
        return Err(FeError::InvalidMesh {
            field: "cells".into(),
            reason: format!("node {n} does not exist ({np} nodes)"),
        });
    }
    if let Some(p) = mesh
        .nodes
        .iter()
        .position(|p| p.iter().any(|v| !v.is_finite()))
    {
        return Err(FeError::InvalidMesh {
            field: format!("node {p}"),
            reason: "coordinate is not finite".into(),
        });
    }
    check(point_data, np, "point", &[])?;
    check(cell_data, nc, "cell", &["region"])?;

    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">"
    );
    let _ = writeln!(s, "<UnstructuredGrid>");
    let _ = writeln!(s, "<Piece NumberOfPoints=\"{np}\" NumberOfCells=\"{nc}\">");
    let _ = writeln!(s, "<PointData>");
    for f in point_data {
        write_field(&mut s, f);
    }
    let _ = writeln!(s, "</PointData>");
    let _ = writeln!(s, "<CellData Scalars=\"region\">");
    let listed: Vec<String> = region_names
        .iter()
        .enumerate()
        .map(|(k, n)| format!("{k} {}", escape(n)))
        .collect();
    let _ = writeln!(s, "<!-- region: {} -->", listed.join(", "));
    let _ = writeln!(
        s,
        "<DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">"
    );
    for r in region {
        let _ = writeln!(s, "{r}");
    }
    let _ = writeln!(s, "</DataArray>");
    for f in cell_data {
        write_field(&mut s, f);
    }
    let _ = writeln!(s, "</CellData>");
    let _ = writeln!(s, "<Points>");
    let _ = writeln!(
        s,
        "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">"
    );
    for p in &mesh.nodes {
        let _ = writeln!(s, "{} {} {}", p[0], p[1], p[2]);
    }
    let _ = writeln!(s, "</DataArray>");
    let _ = writeln!(s, "</Points>");
    let _ = writeln!(s, "<Cells>");
    let _ = writeln!(
        s,
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    );
    for c in cells.chunks_exact(per) {
        let line: Vec<String> = c.iter().map(|n| n.to_string()).collect();
        let _ = writeln!(s, "{}", line.join(" "));
    }
    let _ = writeln!(s, "</DataArray>");
    let _ = writeln!(
        s,
        "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    );
    for k in 1..=nc {
        let _ = writeln!(s, "{}", k * per);
    }
    let _ = writeln!(s, "</DataArray>");
    let _ = writeln!(
        s,
        "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    );
    let code = vtk_cell_type(cell_type);
    for _ in 0..nc {
        let _ = writeln!(s, "{code}");
    }
    let _ = writeln!(s, "</DataArray>");
    let _ = writeln!(s, "</Cells>");
    let _ = writeln!(s, "</Piece>");
    let _ = writeln!(s, "</UnstructuredGrid>");
    let _ = writeln!(s, "</VTKFile>");
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::super::Grading;
    use super::*;

    /// The numbers of the data array whose opening tag contains `tag` (or,
    /// for an element such as `<Points>`, of the first array inside it).
    fn array(doc: &str, tag: &str) -> Vec<f64> {
        let start = doc.find(tag).unwrap_or_else(|| panic!("no {tag}"));
        let mut body = &doc[start..];
        if tag.ends_with('>') {
            body = &body[body.find("<DataArray").unwrap()..];
        }
        let open = body.find('>').unwrap() + 1;
        let close = body.find("</DataArray>").unwrap();
        body[open..close]
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect()
    }

    fn attribute(doc: &str, name: &str) -> usize {
        let key = format!("{name}=\"");
        let at = doc.find(&key).unwrap() + key.len();
        doc[at..at + doc[at..].find('"').unwrap()].parse().unwrap()
    }

    /// Reads back counts, connectivity, offsets, types, coordinates and the
    /// region field, and checks them against the mesh.
    fn round_trip(doc: &str, mesh: &Mesh, cell_type: CellType, cells: &[usize], region: &[f64]) {
        let per = cell_type.nodes();
        let nc = cells.len() / per;
        assert_eq!(attribute(doc, "NumberOfPoints"), mesh.nodes.len());
        assert_eq!(attribute(doc, "NumberOfCells"), nc);
        let conn = array(doc, "Name=\"connectivity\"");
        assert_eq!(conn, cells.iter().map(|&n| n as f64).collect::<Vec<_>>());
        let offsets = array(doc, "Name=\"offsets\"");
        assert_eq!(offsets.len(), nc);
        assert_eq!(offsets.last().copied(), Some(cells.len() as f64));
        assert!(offsets.windows(2).all(|w| w[1] - w[0] == per as f64));
        let types = array(doc, "Name=\"types\"");
        assert_eq!(types, vec![vtk_cell_type(cell_type) as f64; nc]);
        let points = array(doc, "<Points>");
        let flat: Vec<f64> = mesh.nodes.iter().flatten().copied().collect();
        assert_eq!(points, flat);
        assert_eq!(array(doc, "Name=\"region\""), region);
    }

    #[test]
    fn every_cell_type_round_trips() {
        let mut quad4 = Mesh::tensor(&[0.0, 0.1, 0.3], &[0.0, 1.0 / 3.0]);
        quad4.regions.insert("a_first".into(), vec![1]);
        let doc = mesh_vtu(&quad4, &[], &[]).unwrap();
        round_trip(&doc, &quad4, CellType::Quad4, &quad4.cells, &[1.0, 0.0]);
        assert!(doc.contains("<!-- region: 0 a_first, 1 body -->"));

        let quad9 = quad4.to_quadratic().unwrap();
        let doc = mesh_vtu(&quad9, &[], &[]).unwrap();
        round_trip(&doc, &quad9, CellType::Quad9, &quad9.cells, &[1.0, 0.0]);
        for name in ["top", "axis"] {
            let fs = quad9.facet_set(name).unwrap();
            let doc = facet_set_vtu(&quad9, name, &[], &[]).unwrap();
            round_trip(
                &doc,
                &quad9,
                CellType::Line3,
                &fs.nodes,
                &vec![0.0; fs.len()],
            );
            let fs = quad4.facet_set(name).unwrap();
            let doc = facet_set_vtu(&quad4, name, &[], &[]).unwrap();
            round_trip(
                &doc,
                &quad4,
                CellType::Line2,
                &fs.nodes,
                &vec![0.0; fs.len()],
            );
        }

        let g = Grading::uniform(1.0, 2);
        let hex = Mesh::graded_box(1.0, 1.0, 1.0, g, g, g).unwrap();
        let doc = mesh_vtu(&hex, &[], &[]).unwrap();
        round_trip(&doc, &hex, CellType::Hex8, &hex.cells, &[0.0; 8]);
        let top = hex.facet_set("top").unwrap();
        let doc = facet_set_vtu(&hex, "top", &[], &[]).unwrap();
        round_trip(&doc, &hex, CellType::Quad4, &top.nodes, &[0.0; 4]);
    }

    #[test]
    fn fields_are_written_and_checked() {
        let m = Mesh::tensor(&[0.0, 1.0], &[0.0, 1.0]);
        let u: Vec<f64> = (0..8).map(|k| k as f64 * 0.1).collect();
        let p = [2.5];
        let fields = [Field {
            name: "displacement",
            components: 2,
            values: &u,
        }];
        let cells = [Field {
            name: "p<0>",
            components: 1,
            values: &p,
        }];
        let doc = mesh_vtu(&m, &fields, &cells).unwrap();
        assert_eq!(array(&doc, "Name=\"displacement\""), u);
        assert_eq!(array(&doc, "Name=\"p&lt;0&gt;\""), p);
        assert!(doc.contains("NumberOfComponents=\"2\""));

        let short = [Field {
            name: "displacement",
            components: 3,
            values: &u,
        }];
        let err = |r: Result<String, FeError>| match r {
            Err(FeError::InvalidConfig { field, reason }) => format!("{field}: {reason}"),
            other => panic!("{other:?}"),
        };
        let e = err(mesh_vtu(&m, &short, &[]));
        assert!(
            e.contains("`displacement`") && e.contains("8 values"),
            "{e}"
        );
        let region = [Field {
            name: "region",
            components: 1,
            values: &p,
        }];
        assert!(err(mesh_vtu(&m, &[], &region)).contains("`region`"));
        let nan = [f64::NAN];
        let bad = [Field {
            name: "p",
            components: 1,
            values: &nan,
        }];
        assert!(err(mesh_vtu(&m, &[], &bad)).contains("not finite"));
        assert!(facet_set_vtu(&m, "nope", &[], &[]).is_err());
    }
}
