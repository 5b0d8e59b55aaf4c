//! Meshes of any dimension and cell type, with named node sets, facet sets
//! (boundary edges in 2D, faces in 3D) and element regions.
//!
//! One mesh holds cells of one [`CellType`]; node coordinates are stored as
//! `[x, y, z]` with `z = 0` in 2D (the axisymmetric half-section is `(r, z) =
//! (x, y)`). A region is a named list of cells; a material is given per
//! region, so a stiff inclusion is data. Node numbering follows Gmsh and VTK
//! (corners counter-clockwise, then edge mid-nodes, then the centre); the
//! 27-node hexahedron follows VTK's order (Gmsh's differs).
//!
//! * [`grading`] — graded spacings along one coordinate.
//! * [`structured`] — tensor-product generators for the reference problems.
//! * [`gmsh`] — reader for Gmsh MSH 4.1 ASCII files (physical groups become
//!   regions, facet sets and node sets).
//! * [`jacobian`] — corner Jacobian determinants (the inversion test).
//! * [`ogrid`] — the quarter O-grid of hexahedra around a tool's axis (N3).
//! * [`rim`] — a rectangle refined about one point of its top (a punch's
//!   rim) in a window about it only.
//! * [`quadratic`] — order elevation, 4-node to 9-node quadrilaterals and
//!   8-node to 27-node hexahedra.
//! * [`vtu`] — VTK XML UnstructuredGrid output of a mesh or a facet set,
//!   any cell type, with point and cell data.
//!
//! [`crate::vtu`] writes a solved system (displacements, pressures,
//! stresses) on top of [`vtu`].

pub mod gmsh;
pub mod grading;
pub mod inclusions;
pub mod jacobian;
pub mod locate;
pub mod ogrid;
pub mod quadratic;
pub mod rim;
pub mod structured;
pub mod vtu;

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::FeError;

pub use grading::Grading;
pub use inclusions::InclusionBlock;
pub use locate::{Interpolant, Locator};
pub use rim::RimWindow;

/// The shape of a cell or facet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CellType {
    /// 2-node line (a facet of a 4-node quadrilateral).
    Line2,
    /// 3-node line: ends, then the mid-node (a facet of a 9-node quadrilateral).
    Line3,
    /// 4-node quadrilateral, corners counter-clockwise.
    Quad4,
    /// 9-node quadrilateral: corners, mid-edge nodes (edge 0-1, 1-2, 2-3, 3-0), centre.
    Quad9,
    /// 8-node hexahedron: bottom face 0-1-2-3 counter-clockwise seen from
    /// above, then the top face 4-5-6-7 over it (Gmsh and VTK order).
    Hex8,
    /// 27-node hexahedron in VTK's order ([`crate::shape::HEX27_NODES`]):
    /// corners as Hex8, mid-edge nodes, face centres, the cell centre.
    Hex27,
}

impl CellType {
    /// Number of nodes.
    pub const fn nodes(self) -> usize {
        match self {
            CellType::Line2 => 2,
            CellType::Line3 => 3,
            CellType::Quad4 => 4,
            CellType::Quad9 => 9,
            CellType::Hex8 => 8,
            CellType::Hex27 => 27,
        }
    }

    /// Dimension of the reference cell.
    pub const fn dim(self) -> usize {
        match self {
            CellType::Line2 | CellType::Line3 => 1,
            CellType::Quad4 | CellType::Quad9 => 2,
            CellType::Hex8 | CellType::Hex27 => 3,
        }
    }

    /// The facet type of this cell (edges of a quadrilateral, faces of a hexahedron).
    pub const fn facet(self) -> Option<CellType> {
        match self {
            CellType::Quad4 => Some(CellType::Line2),
            CellType::Quad9 => Some(CellType::Line3),
            CellType::Hex8 => Some(CellType::Quad4),
            CellType::Hex27 => Some(CellType::Quad9),
            CellType::Line2 | CellType::Line3 => None,
        }
    }
}

/// A named set of boundary facets of one type, node lists flattened.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FacetSet {
    pub cell_type: CellType,
    /// `cell_type.nodes()` node indices per facet. Orientation is the
    /// generator's or the file's; nothing relies on it yet (rigid tools give
    /// their own normals).
    pub nodes: Vec<usize>,
}

impl FacetSet {
    /// Number of facets.
    pub fn len(&self) -> usize {
        self.nodes.len() / self.cell_type.nodes()
    }
    /// True when the set has no facets.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
    /// The nodes of facet `k`.
    pub fn facet(&self, k: usize) -> &[usize] {
        let n = self.cell_type.nodes();
        &self.nodes[k * n..(k + 1) * n]
    }
    /// Iterates over the facets' node lists.
    pub fn iter(&self) -> impl Iterator<Item = &[usize]> {
        self.nodes.chunks_exact(self.cell_type.nodes())
    }
}

/// A mesh of cells of one type.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mesh {
    /// Spatial dimension (2 or 3).
    pub dim: usize,
    /// Node coordinates (mm); `z = 0` in 2D.
    pub nodes: Vec<[f64; 3]>,
    pub cell_type: CellType,
    /// Connectivity, `cell_type.nodes()` per cell, flattened.
    pub cells: Vec<usize>,
    /// Named node sets.
    pub node_sets: BTreeMap<String, Vec<usize>>,
    /// Named facet sets (boundary edges in 2D, faces in 3D).
    pub facet_sets: BTreeMap<String, FacetSet>,
    /// Named element regions (cell indices). Every cell belongs to at least
    /// one region; generators put all cells in `body`.
    pub regions: BTreeMap<String, Vec<usize>>,
}

impl Mesh {
    /// An empty mesh of the given dimension and cell type.
    pub fn empty(dim: usize, cell_type: CellType) -> Mesh {
        Mesh {
            dim,
            nodes: Vec::new(),
            cell_type,
            cells: Vec::new(),
            node_sets: BTreeMap::new(),
            facet_sets: BTreeMap::new(),
            regions: BTreeMap::new(),
        }
    }

    /// Number of cells.
    pub fn cell_count(&self) -> usize {
        self.cells.len() / self.cell_type.nodes()
    }

    /// The nodes of cell `e`.
    pub fn cell(&self, e: usize) -> &[usize] {
        let n = self.cell_type.nodes();
        &self.cells[e * n..(e + 1) * n]
    }

    /// Iterates over the cells' node lists.
    pub fn cells(&self) -> impl Iterator<Item = &[usize]> {
        self.cells.chunks_exact(self.cell_type.nodes())
    }

    /// A node set by name.
    pub fn node_set(&self, name: &str) -> Result<&[usize], FeError> {
        self.node_sets
            .get(name)
            .map(|v| v.as_slice())
            .ok_or_else(|| FeError::InvalidMesh {
                field: name.into(),
                reason: format!("no such node set (have: {})", keys(&self.node_sets)),
            })
    }

    /// A facet set by name.
    pub fn facet_set(&self, name: &str) -> Result<&FacetSet, FeError> {
        self.facet_sets
            .get(name)
            .ok_or_else(|| FeError::InvalidMesh {
                field: name.into(),
                reason: format!("no such facet set (have: {})", keys(&self.facet_sets)),
            })
    }

    /// An element region by name.
    pub fn region(&self, name: &str) -> Result<&[usize], FeError> {
        self.regions
            .get(name)
            .map(|v| v.as_slice())
            .ok_or_else(|| FeError::InvalidMesh {
                field: name.into(),
                reason: format!("no such region (have: {})", keys(&self.regions)),
            })
    }

    /// Smallest distance between two corner nodes of one cell edge (mm).
    pub fn min_edge(&self) -> f64 {
        let corners: &[(usize, usize)] = match self.cell_type {
            CellType::Line2 | CellType::Line3 => &[(0, 1)],
            CellType::Quad4 | CellType::Quad9 => &[(0, 1), (1, 2), (2, 3), (3, 0)],
            CellType::Hex8 | CellType::Hex27 => &[
                (0, 1),
                (1, 2),
                (2, 3),
                (3, 0),
                (4, 5),
                (5, 6),
                (6, 7),
                (7, 4),
                (0, 4),
                (1, 5),
                (2, 6),
                (3, 7),
            ],
        };
        let mut h = f64::INFINITY;
        for c in self.cells() {
            for &(a, b) in corners {
                let (p, q) = (self.nodes[c[a]], self.nodes[c[b]]);
                let d =
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
                h = h.min(d);
            }
        }
        h
    }

    /// Largest extent of the bounding box (mm).
    pub fn extent(&self) -> f64 {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &self.nodes {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max)
    }

    /// Checks that every cell and set refers to existing nodes and cells and
    /// that every cell is in a region; names the first offender.
    pub fn validate(&self) -> Result<(), FeError> {
        let bad = |field: String, reason: String| FeError::InvalidMesh { field, reason };
        let nn = self.nodes.len();
        if self.dim != 2 && self.dim != 3 {
            return Err(bad("dim".into(), format!("{} is not 2 or 3", self.dim)));
        }
        if self.cell_type.dim() != self.dim {
            return Err(bad(
                "cell_type".into(),
                format!("{:?} cells in a {}D mesh", self.cell_type, self.dim),
            ));
        }
        if !self.cells.len().is_multiple_of(self.cell_type.nodes()) {
            return Err(bad(
                "cells".into(),
                "connectivity length is not a multiple of the cell's node count".into(),
            ));
        }
        if let Some(p) = self
            .nodes
            .iter()
            .position(|p| p.iter().any(|v| !v.is_finite()))
        {
            return Err(bad(format!("node {p}"), "coordinate is not finite".into()));
        }
        for (e, c) in self.cells().enumerate() {
            if let Some(&n) = c.iter().find(|&&n| n >= nn) {
                return Err(bad(
                    format!("cell {e}"),
                    format!("node {n} does not exist ({nn} nodes)"),
                ));
            }
        }
        for (name, set) in &self.node_sets {
            if let Some(&n) = set.iter().find(|&&n| n >= nn) {
                return Err(bad(
                    format!("node set `{name}`"),
                    format!("node {n} does not exist"),
                ));
            }
        }
        for (name, set) in &self.facet_sets {
            if !set.nodes.len().is_multiple_of(set.cell_type.nodes()) {
                return Err(bad(
                    format!("facet set `{name}`"),
                    "ragged facet list".into(),
                ));
            }
            if let Some(&n) = set.nodes.iter().find(|&&n| n >= nn) {
                return Err(bad(
                    format!("facet set `{name}`"),
                    format!("node {n} does not exist"),
                ));
            }
        }
        let nc = self.cell_count();
        let mut covered = vec![false; nc];
        for (name, cells) in &self.regions {
            for &e in cells {
                if e >= nc {
                    return Err(bad(
                        format!("region `{name}`"),
                        format!("cell {e} does not exist"),
                    ));
                }
                covered[e] = true;
            }
        }
        if let Some(e) = covered.iter().position(|c| !c) {
            return Err(bad(format!("cell {e}"), "belongs to no region".into()));
        }
        Ok(())
    }
}

fn keys<V>(m: &BTreeMap<String, V>) -> String {
    if m.is_empty() {
        return "none".into();
    }
    m.keys().cloned().collect::<Vec<_>>().join(", ")
}
