//! Structured, graded quadrilateral meshes of the r-z half-section of an
//! axisymmetric body, with named node and edge sets for boundary conditions.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::FeError;

/// Spacing of nodes along one side of a rectangle, measured from its fine end:
/// uniform steps `h_fine` over `fine_length`, then steps growing by the factor
/// `growth` up to the full length (the graded steps are scaled slightly so the
/// last node lands exactly on the end).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Grading {
    /// Element size in the fine zone (mm).
    pub h_fine: f64,
    /// Length of the uniformly fine zone (mm).
    pub fine_length: f64,
    /// Ratio of consecutive element sizes beyond the fine zone (>= 1).
    pub growth: f64,
}

impl Grading {
    /// A uniform spacing of `n` elements over `length`.
    pub fn uniform(length: f64, n: usize) -> Self {
        Grading {
            h_fine: length / n.max(1) as f64,
            fine_length: length,
            growth: 1.0,
        }
    }

    /// Node positions from 0 (fine end) to `length`.
    pub fn positions(&self, length: f64) -> Result<Vec<f64>, FeError> {
        let bad = |reason: &str| FeError::InvalidMesh {
            field: "grading".into(),
            reason: reason.into(),
        };
        if !(length > 0.0 && length.is_finite()) {
            return Err(bad("length must be positive"));
        }
        if !(self.h_fine > 0.0 && self.h_fine.is_finite())
            || !(self.growth >= 1.0)
            || !(self.fine_length >= 0.0)
        {
            return Err(bad("need h_fine > 0, growth >= 1, fine_length >= 0"));
        }
        let fine = self.fine_length.min(length);
        let n_fine = ((fine / self.h_fine) - 1e-9)
            .ceil()
            .max(if fine > 0.0 { 1.0 } else { 0.0 }) as usize;
        let mut pos: Vec<f64> = (0..=n_fine)
            .map(|i| fine * i as f64 / n_fine.max(1) as f64)
            .collect();
        if n_fine == 0 {
            pos = vec![0.0];
        }
        let rest = length - fine;
        if rest > 1e-12 * length {
            let h0 = if n_fine > 0 {
                fine / n_fine as f64
            } else {
                self.h_fine
            };
            let mut sizes = Vec::new();
            let mut h = h0 * self.growth;
            let mut sum = 0.0;
            while sum < rest * (1.0 - 1e-9) {
                sizes.push(h);
                sum += h;
                h *= self.growth;
                if sizes.len() > 100_000 {
                    return Err(bad("too many elements"));
                }
            }
            // Drop a tiny last step into its neighbour.
            if sizes.len() > 1 && sum - rest > 0.5 * sizes[sizes.len() - 1] {
                let last = sizes.pop().unwrap_or(0.0);
                sum -= last;
            }
            let scale = rest / sum;
            let mut x = fine;
            for s in sizes {
                x += s * scale;
                pos.push(x);
            }
            if let Some(last) = pos.last_mut() {
                *last = length;
            }
        }
        Ok(pos)
    }
}

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
    fn grading_covers_the_length_and_grows() {
        let g = Grading {
            h_fine: 0.25,
            fine_length: 5.0,
            growth: 1.2,
        };
        let p = g.positions(35.0).unwrap();
        assert_eq!(p[0], 0.0);
        assert_eq!(*p.last().unwrap(), 35.0);
        assert!((p[1] - 0.25).abs() < 1e-12);
        assert!((p[20] - 5.0).abs() < 1e-12);
        for w in p.windows(3).skip(20) {
            assert!(w[2] - w[1] >= w[1] - w[0] - 1e-12);
        }
        let u = Grading::uniform(9.0, 9).positions(9.0).unwrap();
        assert_eq!(u.len(), 10);
        assert!(Grading {
            h_fine: 0.0,
            fine_length: 1.0,
            growth: 1.0
        }
        .positions(1.0)
        .is_err());
    }

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
