//! Order elevation of a mesh: 4-node to 9-node quadrilaterals.
//!
//! The original nodes keep their indices; new nodes are appended in cell
//! order, each cell adding the mid-nodes of its edges not seen before (edge
//! 0-1, 1-2, 2-3, 3-0) and then its centre. Mid-nodes sit at the edge
//! midpoints and the centre at the mean of the corners, so the geometry is
//! the bilinear one: curved boundaries stay polygonal (read a second-order
//! Gmsh mesh for those). Node order is Gmsh/VTK (see [`CellType::Quad9`]).

use std::collections::{BTreeMap, HashMap, HashSet};

use super::{CellType, FacetSet, Mesh};
use crate::FeError;

impl Mesh {
    /// The same mesh with 9-node quadrilaterals (see the
    /// [module docs](self)).
    ///
    /// * Line2 facet sets become Line3 (ends as before, then the mid-node);
    ///   a facet that is not a cell edge is an error.
    /// * A node set with a facet set of the same name keeps its nodes in
    ///   their old order, followed by the mid-nodes of the set's facets in
    ///   facet order; any other node set gains the mid-nodes of the cell
    ///   edges whose both ends it holds, in node order.
    /// * Regions are unchanged (cells keep their indices).
    ///
    /// Only Quad4 meshes are supported (Hex8 is not yet).
    pub fn to_quadratic(&self) -> Result<Mesh, FeError> {
        match self.cell_type {
            CellType::Quad4 => {}
            CellType::Hex8 => {
                return Err(FeError::InvalidMesh {
                    field: "cell_type".into(),
                    reason: "quadratic hexahedra are not supported yet".into(),
                })
            }
            other => {
                return Err(FeError::InvalidMesh {
                    field: "cell_type".into(),
                    reason: format!("{other:?} cells cannot be made quadratic (need Quad4)"),
                })
            }
        }
        self.validate()?;
        let mut nodes = self.nodes.clone();
        let mut mids: HashMap<(usize, usize), usize> = HashMap::new();
        let mut cells = Vec::with_capacity(9 * self.cell_count());
        for c in self.cells() {
            let mut cell = [0usize; 9];
            cell[..4].copy_from_slice(c);
            for k in 0..4 {
                let (a, b) = (c[k], c[(k + 1) % 4]);
                cell[4 + k] = *mids.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    let (p, q) = (nodes[a], nodes[b]);
                    nodes.push([
                        0.5 * (p[0] + q[0]),
                        0.5 * (p[1] + q[1]),
                        0.5 * (p[2] + q[2]),
                    ]);
                    nodes.len() - 1
                });
            }
            let mut centre = [0.0; 3];
            for &n in c {
                for i in 0..3 {
                    centre[i] += 0.25 * nodes[n][i];
                }
            }
            nodes.push(centre);
            cell[8] = nodes.len() - 1;
            cells.extend_from_slice(&cell);
        }

        let mut facet_sets = BTreeMap::new();
        for (name, set) in &self.facet_sets {
            if set.cell_type != CellType::Line2 {
                return Err(FeError::InvalidMesh {
                    field: format!("facet set `{name}`"),
                    reason: format!("{:?} facets in a Quad4 mesh", set.cell_type),
                });
            }
            let mut out = Vec::with_capacity(3 * set.len());
            for (k, f) in set.iter().enumerate() {
                let (a, b) = (f[0], f[1]);
                let &mid = mids
                    .get(&(a.min(b), a.max(b)))
                    .ok_or_else(|| FeError::InvalidMesh {
                        field: format!("facet set `{name}`"),
                        reason: format!("facet {k} ({a}, {b}) is not an edge of any cell"),
                    })?;
                out.extend([a, b, mid]);
            }
            facet_sets.insert(
                name.clone(),
                FacetSet {
                    cell_type: CellType::Line3,
                    nodes: out,
                },
            );
        }

        // Edges in the order their mid-nodes were made.
        let mut edges: Vec<(usize, usize, usize)> =
            mids.iter().map(|(&(a, b), &m)| (a, b, m)).collect();
        edges.sort_unstable_by_key(|e| e.2);
        let mut node_sets = BTreeMap::new();
        for (name, set) in &self.node_sets {
            let mut out = set.clone();
            let mut have: HashSet<usize> = set.iter().copied().collect();
            if let Some(fs) = facet_sets.get(name) {
                for f in fs.iter() {
                    if have.insert(f[2]) {
                        out.push(f[2]);
                    }
                }
            } else {
                for &(a, b, m) in &edges {
                    if have.contains(&a) && have.contains(&b) {
                        out.push(m);
                    }
                }
            }
            node_sets.insert(name.clone(), out);
        }

        Ok(Mesh {
            dim: self.dim,
            nodes,
            cell_type: CellType::Quad9,
            cells,
            node_sets,
            facet_sets,
            regions: self.regions.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::jacobian::corner_jacobians;
    use super::*;

    #[test]
    fn two_by_two_rectangle() {
        let mut q = Mesh::tensor(&[0.0, 1.0, 3.0], &[0.0, 2.0, 4.0]);
        // Two corners joined by an edge, and two diagonal ones that are not.
        q.node_sets.insert("edge".into(), vec![4, 1]);
        q.node_sets.insert("diagonal".into(), vec![0, 4]);
        let m = q.to_quadratic().unwrap();
        m.validate().unwrap();
        assert_eq!(m.cell_type, CellType::Quad9);
        assert_eq!(m.nodes.len(), 9 + 12 + 4);
        assert_eq!(m.cell_count(), 4);
        assert_eq!(&m.nodes[..9], &q.nodes[..]);
        for (c4, c9) in q.cells().zip(m.cells()) {
            assert_eq!(&c9[..4], c4);
            for k in 0..4 {
                let (p, r) = (m.nodes[c4[k]], m.nodes[c4[(k + 1) % 4]]);
                let mid = m.nodes[c9[4 + k]];
                for i in 0..3 {
                    assert_eq!(mid[i], 0.5 * (p[i] + r[i]));
                }
            }
            let x: Vec<[f64; 3]> = c9.iter().map(|&n| m.nodes[n]).collect();
            assert!(corner_jacobians(CellType::Quad9, &x)
                .iter()
                .all(|&j| j > 0.0));
        }
        // Cells 0 and 1 share the edge 1-4; its mid-node is made once.
        assert_eq!(m.cell(0)[5], m.cell(1)[7]);
        // The first cell's new nodes: its four mid-nodes, then its centre.
        assert_eq!(&m.cell(0)[4..], &[9, 10, 11, 12, 13]);
        assert_eq!(m.nodes[13], [0.5, 1.0, 0.0]);

        let top = m.facet_set("top").unwrap();
        assert_eq!(top.cell_type, CellType::Line3);
        assert_eq!(top.len(), 2);
        let ends = |s: &FacetSet| s.iter().map(|f| [f[0], f[1]]).collect::<Vec<_>>();
        assert_eq!(ends(top), ends(q.facet_set("top").unwrap()));
        let set = m.node_set("top").unwrap();
        assert_eq!(&set[..3], q.node_set("top").unwrap());
        assert_eq!(&set[3..], &[top.facet(0)[2], top.facet(1)[2]]);
        assert!(set.iter().all(|&n| m.nodes[n][1] == 4.0));
        assert_eq!(m.node_set("edge").unwrap(), &[4, 1, 10]);
        assert_eq!(m.node_set("diagonal").unwrap(), &[0, 4]);
        assert_eq!(m.regions, q.regions);
    }

    #[test]
    fn refuses_what_it_cannot_elevate() {
        let q = Mesh::tensor(&[0.0, 1.0], &[0.0, 1.0]);
        let m = q.to_quadratic().unwrap();
        assert!(m.to_quadratic().is_err());
        let g = super::super::Grading::uniform(1.0, 1);
        assert!(Mesh::graded_box(1.0, 1.0, 1.0, g, g, g)
            .unwrap()
            .to_quadratic()
            .is_err());
        let mut bad = q.clone();
        bad.facet_sets.get_mut("top").unwrap().nodes = vec![0, 3];
        match bad.to_quadratic() {
            Err(FeError::InvalidMesh { field, .. }) => assert_eq!(field, "facet set `top`"),
            other => panic!("{other:?}"),
        }
    }
}
