//! Structured (tensor-product) meshes for the reference problems: graded
//! rectangles of 4-node quadrilaterals in 2D and graded boxes of 8-node
//! hexahedra in 3D; every cell is in region `body`.
//!
//! Rectangle sets are named after the sides: node and facet sets `axis`
//! (x = 0), `side` (x = width), `bottom` (y = 0) and `top` (y = height).
//! Box sets: node and Quad4 facet sets `x0`, `x1`, `y0`, `y1`, `bottom`
//! (z = 0) and `top` (z = lz), facets ordered so that their normals (right
//! hand rule) point out of the box.

use super::{CellType, FacetSet, Grading, Mesh};
use crate::FeError;

impl Mesh {
    /// The rectangle `[0, width] x [0, height]` with the fine end of `radial`
    /// at x = 0 (the axis) and the fine end of `axial` at the top y = height
    /// (where tools press).
    pub fn graded_rectangle(
        width: f64,
        height: f64,
        radial: Grading,
        axial: Grading,
    ) -> Result<Mesh, FeError> {
        let rs = radial.positions(width)?;
        let zs: Vec<f64> = axial
            .positions(height)?
            .iter()
            .rev()
            .map(|t| height - t)
            .collect();
        Ok(Self::tensor(&rs, &zs))
    }

    /// [`Mesh::graded_rectangle`] cut into horizontal bands at the given
    /// depths below the top (`interfaces`, increasing, inside `(0,
    /// height)`): each depth is a mesh line (inserted into the axial
    /// grading; a graded line closer to it than a third of the local
    /// spacing is dropped, so no sliver element is made), and the cells of
    /// band `i` (from the top) are region `layer{i}`. Without interfaces it
    /// is exactly [`Mesh::graded_rectangle`] (one region `body`).
    pub fn graded_layers(
        width: f64,
        height: f64,
        radial: Grading,
        axial: Grading,
        interfaces: &[f64],
    ) -> Result<Mesh, FeError> {
        if interfaces.is_empty() {
            return Self::graded_rectangle(width, height, radial, axial);
        }
        Self::lines_in_layers(
            &radial.positions(width)?,
            &axial.positions(height)?,
            height,
            interfaces,
        )
    }

    /// [`Mesh::graded_layers`] on given mesh lines: radial positions `rs`
    /// from the axis and axial ones `from_top` (depths below the top, from
    /// 0 to `height`), e.g. a grading refined about a punch edge
    /// ([`super::grading::refine_towards`]). Without interfaces, one region
    /// `body`.
    pub fn lines_in_layers(
        rs: &[f64],
        from_top: &[f64],
        height: f64,
        interfaces: &[f64],
    ) -> Result<Mesh, FeError> {
        if interfaces.is_empty() {
            let zs: Vec<f64> = from_top.iter().rev().map(|t| height - t).collect();
            return Ok(Self::tensor(rs, &zs));
        }
        let bad = |reason: String| FeError::InvalidMesh {
            field: "interfaces".into(),
            reason,
        };
        let mut last = 0.0;
        for &t in interfaces {
            if !(t > last && t < height) {
                return Err(bad(format!(
                    "depths {interfaces:?} must increase strictly inside (0, {height})"
                )));
            }
            last = t;
        }
        let from_top = with_lines(from_top, interfaces);
        let zs: Vec<f64> = from_top.iter().rev().map(|t| height - t).collect();
        let mut m = Self::tensor(rs, &zs);
        let mut bands: Vec<Vec<usize>> = vec![Vec::new(); interfaces.len() + 1];
        for e in 0..m.cell_count() {
            let yc = m.cell(e).iter().map(|&n| m.nodes[n][1]).sum::<f64>() / 4.0;
            let depth = height - yc;
            let band = interfaces.iter().filter(|&&t| t < depth).count();
            bands[band].push(e);
        }
        m.regions.clear();
        for (i, cells) in bands.into_iter().enumerate() {
            m.regions.insert(format!("layer{i}"), cells);
        }
        Ok(m)
    }

    /// Tensor-product mesh of 4-node quadrilaterals on the coordinate lines
    /// `xs` (increasing) x `ys` (increasing); node `(i, j)` is `j * xs.len() + i`.
    pub fn tensor(xs: &[f64], ys: &[f64]) -> Mesh {
        let (nx, ny) = (xs.len(), ys.len());
        let id = |i: usize, j: usize| j * nx + i;
        let mut m = Mesh::empty(2, CellType::Quad4);
        for &y in ys {
            for &x in xs {
                m.nodes.push([x, y, 0.0]);
            }
        }
        for j in 0..ny.saturating_sub(1) {
            for i in 0..nx.saturating_sub(1) {
                m.cells
                    .extend([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let line = |pts: Vec<usize>| FacetSet {
            cell_type: CellType::Line2,
            nodes: pts.windows(2).flatten().copied().collect(),
        };
        let sides: [(&str, Vec<usize>); 4] = [
            ("axis", (0..ny).map(|j| id(0, j)).collect()),
            ("side", (0..ny).map(|j| id(nx - 1, j)).collect()),
            ("bottom", (0..nx).map(|i| id(i, 0)).collect()),
            ("top", (0..nx).map(|i| id(i, ny - 1)).collect()),
        ];
        for (name, pts) in sides {
            m.facet_sets.insert(name.into(), line(pts.clone()));
            m.node_sets.insert(name.into(), pts);
        }
        m.regions
            .insert("body".into(), (0..m.cell_count()).collect());
        m
    }
}

/// `positions` (increasing, from 0) with the `lines` inserted; a graded
/// position (not an end, not a line) closer to a line than a third of the
/// interval the line falls in is dropped.
pub fn with_lines(positions: &[f64], lines: &[f64]) -> Vec<f64> {
    let mut out = positions.to_vec();
    let mut fixed: Vec<f64> = vec![out[0], out[out.len() - 1]];
    for &l in lines {
        let k = out.partition_point(|&p| p < l);
        // a line on a graded position (to rounding) is that position
        let tol = 1e-9 * out[out.len() - 1];
        if let Some(j) = [k.wrapping_sub(1), k]
            .into_iter()
            .find(|&j| j < out.len() && (out[j] - l).abs() <= tol)
        {
            if j != 0 && j != out.len() - 1 {
                out[j] = l;
            }
            fixed.push(out[j]);
            continue;
        }
        let (lo, hi) = (out[k - 1], out[k]);
        let h = hi - lo;
        out.insert(k, l);
        fixed.push(l);
        // the nearer neighbour, if it is free and too close
        let (near, j) = if l - lo < hi - l {
            (lo, k - 1)
        } else {
            (hi, k + 1)
        };
        if (near - l).abs() < h / 3.0 && !fixed.contains(&near) {
            out.remove(j);
        }
    }
    out
}

impl Mesh {
    /// The box `[0, lx] x [0, ly] x [0, lz]` of 8-node hexahedra with the
    /// fine end of `gx` at x = 0, of `gy` at y = 0 and of `gz` at the top
    /// z = lz (where tools press). Node `(i, j, k)` is
    /// `(k * ny + j) * nx + i`; cells are in Gmsh order (positive volume).
    pub fn graded_box(
        lx: f64,
        ly: f64,
        lz: f64,
        gx: Grading,
        gy: Grading,
        gz: Grading,
    ) -> Result<Mesh, FeError> {
        let xs = gx.positions(lx)?;
        let ys = gy.positions(ly)?;
        let zs: Vec<f64> = gz.positions(lz)?.iter().rev().map(|t| lz - t).collect();
        Ok(Self::tensor3(&xs, &ys, &zs))
    }

    /// Tensor-product mesh of 8-node hexahedra on the increasing coordinate
    /// lines `xs` x `ys` x `zs`, with the sets of [`Mesh::graded_box`].
    pub fn tensor3(xs: &[f64], ys: &[f64], zs: &[f64]) -> Mesh {
        let (nx, ny, nz) = (xs.len(), ys.len(), zs.len());
        let id = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
        let mut m = Mesh::empty(3, CellType::Hex8);
        for &z in zs {
            for &y in ys {
                for &x in xs {
                    m.nodes.push([x, y, z]);
                }
            }
        }
        let (ex, ey, ez) = (
            nx.saturating_sub(1),
            ny.saturating_sub(1),
            nz.saturating_sub(1),
        );
        for k in 0..ez {
            for j in 0..ey {
                for i in 0..ex {
                    m.cells.extend([
                        id(i, j, k),
                        id(i + 1, j, k),
                        id(i + 1, j + 1, k),
                        id(i, j + 1, k),
                        id(i, j, k + 1),
                        id(i + 1, j, k + 1),
                        id(i + 1, j + 1, k + 1),
                        id(i, j + 1, k + 1),
                    ]);
                }
            }
        }
        // A face of the box: the grid of the two free indices `(a, b)`, and
        // whether the quad `(a, b) (a+1, b) (a+1, b+1) (a, b+1)` faces out
        // (otherwise it is reversed).
        let mut face =
            |name: &str, na: usize, nb: usize, node: &dyn Fn(usize, usize) -> usize, out: bool| {
                let mut facets = Vec::new();
                for b in 0..nb.saturating_sub(1) {
                    for a in 0..na.saturating_sub(1) {
                        let q = [
                            node(a, b),
                            node(a + 1, b),
                            node(a + 1, b + 1),
                            node(a, b + 1),
                        ];
                        if out {
                            facets.extend(q);
                        } else {
                            facets.extend([q[0], q[3], q[2], q[1]]);
                        }
                    }
                }
                let mut set: Vec<usize> = (0..nb)
                    .flat_map(|b| (0..na).map(move |a| (a, b)))
                    .map(|(a, b)| node(a, b))
                    .collect();
                set.sort_unstable();
                m.facet_sets.insert(
                    name.into(),
                    FacetSet {
                        cell_type: CellType::Quad4,
                        nodes: facets,
                    },
                );
                m.node_sets.insert(name.into(), set);
            };
        // (a, b) = (y, z) turns about +x, (x, z) about -y, (x, y) about +z.
        face("x0", ny, nz, &|a, b| id(0, a, b), false);
        face("x1", ny, nz, &|a, b| id(nx.saturating_sub(1), a, b), true);
        face("y0", nx, nz, &|a, b| id(a, 0, b), true);
        face("y1", nx, nz, &|a, b| id(a, ny.saturating_sub(1), b), false);
        face("bottom", nx, ny, &|a, b| id(a, b, 0), false);
        face("top", nx, ny, &|a, b| id(a, b, nz.saturating_sub(1)), true);
        m.regions
            .insert("body".into(), (0..m.cell_count()).collect());
        m
    }
}

#[cfg(test)]
mod tests {
    use super::super::jacobian::corner_jacobians;
    use super::*;

    /// Interfaces become mesh lines without slivers, the bands become
    /// regions, and without interfaces the mesh is the graded rectangle.
    #[test]
    fn layers_are_mesh_lines_and_regions() {
        let p = with_lines(&[0.0, 1.0, 2.0, 3.0, 4.0], &[1.1, 2.5, 4.0]);
        assert_eq!(p, vec![0.0, 1.1, 2.0, 2.5, 3.0, 4.0]);
        let g = Grading {
            h_fine: 0.5,
            fine_length: 2.0,
            growth: 1.3,
        };
        let m = Mesh::graded_layers(5.0, 10.0, g, g, &[1.2, 3.0]).unwrap();
        let ys: Vec<f64> = (0..m.nodes.len())
            .filter(|&n| m.nodes[n][0] == 0.0)
            .map(|n| m.nodes[n][1])
            .collect();
        for t in [1.2, 3.0] {
            assert!(ys.iter().any(|&y| (y - (10.0 - t)).abs() < 1e-12), "{ys:?}");
        }
        for w in ys.windows(2) {
            assert!(w[1] - w[0] > 0.15, "{ys:?}");
        }
        let top = m.region("layer0").unwrap().len();
        let mid = m.region("layer1").unwrap().len();
        let bottom = m.region("layer2").unwrap().len();
        assert_eq!(top + mid + bottom, m.cell_count());
        assert!(top > 0 && mid > 0 && bottom > 0);
        assert!(m.region("body").is_err());
        let plain = Mesh::graded_layers(5.0, 10.0, g, g, &[]).unwrap();
        assert_eq!(plain, Mesh::graded_rectangle(5.0, 10.0, g, g).unwrap());
        assert!(Mesh::graded_layers(5.0, 10.0, g, g, &[3.0, 1.0]).is_err());
    }

    #[test]
    fn rectangle_sets_and_orientation() {
        let m =
            Mesh::graded_rectangle(2.0, 3.0, Grading::uniform(2.0, 2), Grading::uniform(3.0, 3))
                .unwrap();
        m.validate().unwrap();
        assert_eq!(m.nodes.len(), 12);
        assert_eq!(m.cell_count(), 6);
        assert!(m
            .node_set("top")
            .unwrap()
            .iter()
            .all(|&n| m.nodes[n][1] == 3.0));
        assert!(m
            .node_set("axis")
            .unwrap()
            .iter()
            .all(|&n| m.nodes[n][0] == 0.0));
        assert_eq!(m.facet_set("top").unwrap().len(), 2);
        for e in m.cells() {
            let p: Vec<_> = e.iter().map(|&n| m.nodes[n]).collect();
            let area2: f64 = (0..4)
                .map(|k| p[k][0] * p[(k + 1) % 4][1] - p[(k + 1) % 4][0] * p[k][1])
                .sum();
            assert!(area2 > 0.0);
        }
        assert!(m.node_set("nope").is_err());
        assert_eq!(m.region("body").unwrap().len(), 6);
    }

    #[test]
    fn box_sets_orientation_and_grading() {
        let g = Grading {
            h_fine: 0.5,
            fine_length: 1.0,
            growth: 1.5,
        };
        let m = Mesh::graded_box(3.0, 2.0, 4.0, g, Grading::uniform(2.0, 2), g).unwrap();
        m.validate().unwrap();
        let xs = g.positions(3.0).unwrap();
        let nz = g.positions(4.0).unwrap().len();
        let (nx, ny) = (xs.len(), 3);
        assert_eq!(m.nodes.len(), nx * ny * nz);
        assert_eq!(m.cell_count(), (nx - 1) * (ny - 1) * (nz - 1));
        assert_eq!(m.region("body").unwrap().len(), m.cell_count());
        // Fine end of x at x = 0, of z at the top.
        assert!((m.nodes[1][0] - 0.5).abs() < 1e-12);
        let top = m.nodes[(nz - 1) * nx * ny][2];
        let below = m.nodes[(nz - 2) * nx * ny][2];
        assert_eq!(top, 4.0);
        assert!((top - below - 0.5).abs() < 1e-12);
        for c in m.cells() {
            let x: Vec<[f64; 3]> = c.iter().map(|&n| m.nodes[n]).collect();
            assert!(corner_jacobians(CellType::Hex8, &x)
                .iter()
                .all(|&j| j > 0.0));
        }
        let centre = [1.5, 1.0, 2.0];
        let planes = [
            ("x0", 0, 0.0),
            ("x1", 0, 3.0),
            ("y0", 1, 0.0),
            ("y1", 1, 2.0),
            ("bottom", 2, 0.0),
            ("top", 2, 4.0),
        ];
        let mut facets = 0;
        for (name, axis, at) in planes {
            let set = m.node_set(name).unwrap();
            assert!(set.iter().all(|&n| m.nodes[n][axis] == at), "{name}");
            let count = m.nodes.iter().filter(|p| p[axis] == at).count();
            assert_eq!(set.len(), count, "{name}");
            let fs = m.facet_set(name).unwrap();
            assert_eq!(fs.cell_type, CellType::Quad4);
            for f in fs.iter() {
                let p: Vec<[f64; 3]> = f.iter().map(|&n| m.nodes[n]).collect();
                assert!(p.iter().all(|q| q[axis] == at), "{name}");
                // Normal from the diagonals' cross product, against the
                // direction from the box centre.
                let d1: Vec<f64> = (0..3).map(|i| p[2][i] - p[0][i]).collect();
                let d2: Vec<f64> = (0..3).map(|i| p[3][i] - p[1][i]).collect();
                let n = [
                    d1[1] * d2[2] - d1[2] * d2[1],
                    d1[2] * d2[0] - d1[0] * d2[2],
                    d1[0] * d2[1] - d1[1] * d2[0],
                ];
                let out: f64 = (0..3).map(|i| n[i] * (p[0][i] - centre[i])).sum();
                assert!(n[axis].abs() > 0.0 && out > 0.0, "{name}");
            }
            facets += fs.len();
        }
        let (ex, ey, ez) = (nx - 1, ny - 1, nz - 1);
        assert_eq!(facets, 2 * (ex * ey + ey * ez + ex * ez));
    }
}
