//! Order elevation of a mesh: 4-node to 9-node quadrilaterals, 8-node to
//! 27-node hexahedra.
//!
//! The original nodes keep their indices; new nodes are appended in cell
//! order, each cell adding the mid-nodes of its edges not seen before (edge
//! 0-1, 1-2, 2-3, 3-0; in 3D the twelve edges of
//! [`crate::shape::HEX_EDGES`]), then in 3D the centres of its faces not
//! seen before ([`crate::shape::HEX_FACES`]), then its centre. Mid-nodes sit
//! at the edge midpoints, face and cell centres at the mean of their
//! corners, so the geometry is the bilinear (trilinear) one: curved
//! boundaries stay polygonal (read a second-order Gmsh mesh for those).
//! Node order is Gmsh/VTK for [`CellType::Quad9`], VTK for
//! [`CellType::Hex27`].

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
    /// Hex8 meshes become Hex27 ([`Mesh::to_triquadratic`]); other cell
    /// types are refused.
    pub fn to_quadratic(&self) -> Result<Mesh, FeError> {
        match self.cell_type {
            CellType::Quad4 => {}
            CellType::Hex8 => return self.to_triquadratic(),
            other => {
                return Err(FeError::InvalidMesh {
                    field: "cell_type".into(),
                    reason: format!(
                        "{other:?} cells cannot be made quadratic (need Quad4 or Hex8)"
                    ),
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

        let facet_sets = self.elevated_facet_sets(CellType::Line2, CellType::Line3, |f| {
            let (a, b) = (f[0], f[1]);
            mids.get(&(a.min(b), a.max(b))).map(|&m| vec![m])
        })?;

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

    /// The same Hex8 mesh with 27-node hexahedra (see the
    /// [module docs](self)).
    ///
    /// * Quad4 facet sets become Quad9: the corners as before, the
    ///   mid-nodes of the facet's edges 0-1, 1-2, 2-3, 3-0, its centre; a
    ///   facet that is not a cell face is an error.
    /// * A node set with a facet set of the same name keeps its nodes in
    ///   their old order, followed by the new nodes of the set's facets in
    ///   facet order; any other node set gains every new node (mid-edge,
    ///   face or cell centre) whose corners it all holds, in node order.
    /// * Regions are unchanged (cells keep their indices).
    pub fn to_triquadratic(&self) -> Result<Mesh, FeError> {
        use crate::shape::{HEX_EDGES, HEX_FACES};
        if self.cell_type != CellType::Hex8 {
            return Err(FeError::InvalidMesh {
                field: "cell_type".into(),
                reason: format!(
                    "{:?} cells cannot be made triquadratic (need Hex8)",
                    self.cell_type
                ),
            });
        }
        self.validate()?;
        let mut nodes = self.nodes.clone();
        // each new node with the (sorted) corners it is the centre of
        let mut made: HashMap<Vec<usize>, usize> = HashMap::new();
        let mut parents: Vec<Vec<usize>> = Vec::new();
        let mut centre_of = |corners: Vec<usize>, nodes: &mut Vec<[f64; 3]>| -> usize {
            let mut key = corners;
            key.sort_unstable();
            if let Some(&n) = made.get(&key) {
                return n;
            }
            let mut p = [0.0; 3];
            for &c in &key {
                for i in 0..3 {
                    p[i] += nodes[c][i] / key.len() as f64;
                }
            }
            nodes.push(p);
            let n = nodes.len() - 1;
            made.insert(key.clone(), n);
            parents.push(key);
            n
        };
        let mut cells = Vec::with_capacity(27 * self.cell_count());
        for c in self.cells() {
            let mut cell = [0usize; 27];
            cell[..8].copy_from_slice(c);
            for (k, [a, b]) in HEX_EDGES.iter().enumerate() {
                cell[8 + k] = centre_of(vec![c[*a], c[*b]], &mut nodes);
            }
            for (k, f) in HEX_FACES.iter().enumerate() {
                cell[20 + k] = centre_of(f.iter().map(|&a| c[a]).collect(), &mut nodes);
            }
            cell[26] = centre_of(c.to_vec(), &mut nodes);
            cells.extend_from_slice(&cell);
        }
        let find = |corners: &[usize]| {
            let mut key = corners.to_vec();
            key.sort_unstable();
            made.get(&key).copied()
        };

        let facet_sets = self.elevated_facet_sets(CellType::Quad4, CellType::Quad9, |f| {
            // mid-nodes of the edges 0-1, 1-2, 2-3, 3-0, then the centre
            let mut new: Vec<usize> = (0..4)
                .map(|e| find(&[f[e], f[(e + 1) % 4]]))
                .collect::<Option<_>>()?;
            new.push(find(f)?);
            Some(new)
        })?;

        let first_new = self.nodes.len();
        let mut node_sets = BTreeMap::new();
        for (name, set) in &self.node_sets {
            let mut out = set.clone();
            let mut have: HashSet<usize> = set.iter().copied().collect();
            if let Some(fs) = facet_sets.get(name) {
                for f in fs.iter() {
                    for &n in &f[4..] {
                        if have.insert(n) {
                            out.push(n);
                        }
                    }
                }
            } else {
                for (k, p) in parents.iter().enumerate() {
                    if p.iter().all(|n| have.contains(n)) {
                        out.push(first_new + k);
                    }
                }
                have.clear();
            }
            node_sets.insert(name.clone(), out);
        }

        Ok(Mesh {
            dim: self.dim,
            nodes,
            cell_type: CellType::Hex27,
            cells,
            node_sets,
            facet_sets,
            regions: self.regions.clone(),
        })
    }

    /// The facet sets of `from` facets made `to` facets: each facet's nodes
    /// followed by the new nodes `new_nodes` gives it (`None`: the facet is
    /// not a facet of any cell, an error naming the set and the facet).
    fn elevated_facet_sets(
        &self,
        from: CellType,
        to: CellType,
        new_nodes: impl Fn(&[usize]) -> Option<Vec<usize>>,
    ) -> Result<BTreeMap<String, FacetSet>, FeError> {
        let mut facet_sets = BTreeMap::new();
        for (name, set) in &self.facet_sets {
            let bad = |reason: String| FeError::InvalidMesh {
                field: format!("facet set `{name}`"),
                reason,
            };
            if set.cell_type != from {
                return Err(bad(format!(
                    "{:?} facets in a {:?} mesh",
                    set.cell_type, self.cell_type
                )));
            }
            let mut out = Vec::with_capacity(to.nodes() * set.len());
            for (k, f) in set.iter().enumerate() {
                let new = new_nodes(f)
                    .ok_or_else(|| bad(format!("facet {k} {f:?} is not a facet of any cell")))?;
                out.extend_from_slice(f);
                out.extend(new);
            }
            facet_sets.insert(
                name.clone(),
                FacetSet {
                    cell_type: to,
                    nodes: out,
                },
            );
        }
        Ok(facet_sets)
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

    /// A 2 x 2 x 1 box of hexahedra: shared edge, face and cell nodes made
    /// once, at the right places; facet and node sets gain their new nodes;
    /// the elements are valid and fill the box's volume.
    #[test]
    fn two_by_two_by_one_box_of_hexahedra() {
        use crate::kernel::{kernel_for, PressureSpace};
        use crate::kinematics::Kinematics;
        let g = super::super::Grading::uniform(2.0, 2);
        let gz = super::super::Grading::uniform(1.0, 1);
        let h8 = Mesh::graded_box(2.0, 2.0, 1.0, g, g, gz).unwrap();
        assert_eq!((h8.nodes.len(), h8.cell_count()), (18, 4));
        let m = h8.to_quadratic().unwrap();
        m.validate().unwrap();
        assert_eq!(m.cell_type, CellType::Hex27);
        // a 5 x 5 x 3 lattice of nodes
        assert_eq!(m.nodes.len(), 75);
        let mut seen = HashSet::new();
        for p in &m.nodes {
            assert!(
                seen.insert(p.map(|v| (2.0 * v).round() as i64)),
                "{p:?} twice"
            );
            for v in p {
                assert_eq!(2.0 * v, (2.0 * v).round());
            }
        }
        let kernel = kernel_for(CellType::Hex27, Kinematics::ThreeD, PressureSpace::P1).unwrap();
        let mut volume = 0.0;
        for c in m.cells() {
            let x: Vec<[f64; 3]> = c.iter().map(|&n| m.nodes[n]).collect();
            // every node at its reference position in the unit cell
            for (a, xi) in crate::shape::HEX27_NODES.iter().enumerate() {
                for i in 0..3 {
                    let lo = x[0][i];
                    let size = x[6][i] - x[0][i];
                    assert!((x[a][i] - (lo + 0.5 * (xi[i] + 1.0) * size)).abs() < 1e-12);
                }
            }
            assert!(corner_jacobians(CellType::Hex27, &x)
                .iter()
                .all(|&j| j > 0.0));
            volume += kernel.reference_volume(&x).unwrap();
        }
        assert!((volume - 4.0).abs() < 1e-12, "{volume}");
        let top = m.facet_set("top").unwrap();
        assert_eq!((top.cell_type, top.len()), (CellType::Quad9, 4));
        for f in top.iter() {
            assert!(f.iter().all(|&n| m.nodes[n][2] == 1.0));
            // the facet's own corner order: mid-nodes between consecutive corners
            for e in 0..4 {
                let (a, b, mid) = (m.nodes[f[e]], m.nodes[f[(e + 1) % 4]], m.nodes[f[4 + e]]);
                for i in 0..3 {
                    assert_eq!(mid[i], 0.5 * (a[i] + b[i]));
                }
            }
        }
        // node sets: the top plane's 25 nodes, x0's 15
        let set = m.node_set("top").unwrap();
        assert_eq!(set.len(), 25);
        assert_eq!(&set[..9], h8.node_set("top").unwrap());
        assert!(set.iter().all(|&n| m.nodes[n][2] == 1.0));
        let x0 = m.node_set("x0").unwrap();
        assert_eq!(x0.len(), 15);
        assert!(x0.iter().all(|&n| m.nodes[n][0] == 0.0));
        assert_eq!(m.regions, h8.regions);
    }

    #[test]
    fn refuses_what_it_cannot_elevate() {
        let q = Mesh::tensor(&[0.0, 1.0], &[0.0, 1.0]);
        let m = q.to_quadratic().unwrap();
        assert!(m.to_quadratic().is_err());
        let g = super::super::Grading::uniform(1.0, 1);
        let hex = Mesh::graded_box(1.0, 1.0, 1.0, g, g, g)
            .unwrap()
            .to_quadratic()
            .unwrap();
        assert_eq!(hex.cell_type, CellType::Hex27);
        assert!(hex.to_quadratic().is_err());
        let mut bad = Mesh::graded_box(1.0, 1.0, 1.0, g, g, g).unwrap();
        let top = bad.facet_sets.get_mut("top").unwrap();
        top.nodes.swap(1, 2); // a diagonal is not an edge
        assert!(bad.to_quadratic().is_err());
        let mut bad = q.clone();
        bad.facet_sets.get_mut("top").unwrap().nodes = vec![0, 3];
        match bad.to_quadratic() {
            Err(FeError::InvalidMesh { field, .. }) => assert_eq!(field, "facet set `top`"),
            other => panic!("{other:?}"),
        }
    }
}
