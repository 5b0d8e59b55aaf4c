//! The old 2D mesh (to be removed when the solver moves onto [`crate::mesh::Mesh`]): structured, graded quadrilateral meshes of the r-z half-section of an
//! axisymmetric body, with named node and edge sets for boundary conditions.

use std::collections::BTreeMap;

use crate::mesh::Grading;
use crate::FeError;

/// A mesh of 4-node quadrilaterals in the (r, z) plane.
///
/// Element corners are counter-clockwise in (r, z). Node sets and edge sets
/// are named (`axis`, `bottom`, `top`, `side`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Node coordinates (r, z) in mm.
    pub nodes: Vec<[f64; 2]>,
    /// Element connectivity, counter-clockwise.
    pub elements: Vec<[usize; 4]>,
    /// Named node sets.
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named boundary edges (node pairs).
    pub edge_sets: BTreeMap<String, Vec<[usize; 2]>>,
}

impl Mesh {
    /// The rectangle `[0, width] x [0, height]` with the fine end of `radial`
    /// at r = 0 (the axis) and the fine end of `axial` at the top z = height
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

    /// Tensor-product mesh of the coordinate lines `rs` (increasing) x `zs` (increasing).
    pub fn tensor(rs: &[f64], zs: &[f64]) -> Mesh {
        let (nr, nz) = (rs.len(), zs.len());
        let id = |i: usize, j: usize| j * nr + i;
        let mut m = Mesh::default();
        for &z in zs {
            for &r in rs {
                m.nodes.push([r, z]);
            }
        }
        for j in 0..nz - 1 {
            for i in 0..nr - 1 {
                m.elements
                    .push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        m.node_sets
            .insert("axis".into(), (0..nz).map(|j| id(0, j)).collect());
        m.node_sets
            .insert("side".into(), (0..nz).map(|j| id(nr - 1, j)).collect());
        m.node_sets
            .insert("bottom".into(), (0..nr).map(|i| id(i, 0)).collect());
        m.node_sets
            .insert("top".into(), (0..nr).map(|i| id(i, nz - 1)).collect());
        m.edge_sets.insert(
            "top".into(),
            (0..nr - 1)
                .map(|i| [id(i, nz - 1), id(i + 1, nz - 1)])
                .collect(),
        );
        m.edge_sets.insert(
            "bottom".into(),
            (0..nr - 1).map(|i| [id(i, 0), id(i + 1, 0)]).collect(),
        );
        m.edge_sets.insert(
            "side".into(),
            (0..nz - 1)
                .map(|j| [id(nr - 1, j), id(nr - 1, j + 1)])
                .collect(),
        );
        m
    }

    /// A node set by name.
    pub fn node_set(&self, name: &str) -> Result<&[usize], FeError> {
        self.node_sets
            .get(name)
            .map(|v| v.as_slice())
            .ok_or_else(|| FeError::InvalidMesh {
                field: name.into(),
                reason: "no such node set".into(),
            })
    }

    /// An edge set by name.
    pub fn edge_set(&self, name: &str) -> Result<&[[usize; 2]], FeError> {
        self.edge_sets
            .get(name)
            .map(|v| v.as_slice())
            .ok_or_else(|| FeError::InvalidMesh {
                field: name.into(),
                reason: "no such edge set".into(),
            })
    }

    /// Smallest element edge length (mm).
    pub fn min_edge(&self) -> f64 {
        let mut h = f64::INFINITY;
        for e in &self.elements {
            for k in 0..4 {
                let (a, b) = (self.nodes[e[k]], self.nodes[e[(k + 1) % 4]]);
                h = h.min(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt());
            }
        }
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_sets_and_orientation() {
        let m =
            Mesh::graded_rectangle(2.0, 3.0, Grading::uniform(2.0, 2), Grading::uniform(3.0, 3))
                .unwrap();
        assert_eq!(m.nodes.len(), 12);
        assert_eq!(m.elements.len(), 6);
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
        for e in &m.elements {
            let p: Vec<_> = e.iter().map(|&n| m.nodes[n]).collect();
            let area2: f64 = (0..4)
                .map(|k| p[k][0] * p[(k + 1) % 4][1] - p[(k + 1) % 4][0] * p[k][1])
                .sum();
            assert!(area2 > 0.0);
        }
        assert!(m.node_set("nope").is_err());
    }
}
