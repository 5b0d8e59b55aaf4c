//! Structured (tensor-product) meshes for the reference problems: graded
//! rectangles of 4-node quadrilaterals in 2D. Sets are named after the
//! sides: node and facet sets `axis` (x = 0), `side` (x = width), `bottom`
//! (y = 0) and `top` (y = height); every cell is in region `body`.

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
