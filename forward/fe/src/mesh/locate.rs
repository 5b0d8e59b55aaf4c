//! Locating points in a 2D mesh of quadrilaterals (reference configuration)
//! and the weights that interpolate a nodal field there.
//!
//! A point `p` lies in cell `e` at reference coordinates `xi` when
//! `x_e(xi) = sum_a N_a(xi) X_a = p` with `|xi_k| <= 1`; `xi` is found by
//! Newton on the isoparametric map (`xi <- xi - J^-1 (x_e(xi) - p)`,
//! `J = sum_a X_a (x) dN_a/dxi`; Hughes, *The Finite Element Method*, 2000,
//! section 3.2), started at the cell centre, among the cells whose
//! (enlarged) bounding box holds `p` (a bucket grid over the mesh). The
//! field at `p` is then `sum_a N_a(xi) u_a`: for a finite-element field,
//! its exact value.

use super::{CellType, Mesh};
use crate::shape::{quad4, quad9};
use crate::FeError;

/// Largest number of nodes of a supported cell.
const MAX_NODES: usize = 9;

/// Where a point lies: its cell and the shape-function weights of the
/// cell's nodes (`mesh.cell(cell)` order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interpolant {
    pub cell: usize,
    pub weights: [f64; MAX_NODES],
}

impl Interpolant {
    /// `sum_a w_a f(node_a)` over the cell's nodes.
    pub fn apply(&self, mesh: &Mesh, f: impl Fn(usize) -> f64) -> f64 {
        mesh.cell(self.cell)
            .iter()
            .zip(&self.weights)
            .map(|(&n, w)| w * f(n))
            .sum()
    }
}

/// A bucket grid of a 2D quadrilateral mesh's cells for point location.
pub struct Locator<'a> {
    mesh: &'a Mesh,
    lo: [f64; 2],
    size: [f64; 2],
    counts: [usize; 2],
    buckets: Vec<Vec<usize>>,
}

impl<'a> Locator<'a> {
    /// The grid of `mesh` (Quad4 or Quad9 cells; another type is refused).
    pub fn new(mesh: &'a Mesh) -> Result<Locator<'a>, FeError> {
        if mesh.dim != 2 || !matches!(mesh.cell_type, CellType::Quad4 | CellType::Quad9) {
            return Err(FeError::InvalidConfig {
                field: "mesh".into(),
                reason: format!(
                    "point location needs a 2D mesh of Quad4 or Quad9 cells, not {:?} in {}D",
                    mesh.cell_type, mesh.dim
                ),
            });
        }
        let n = mesh.cell_count().max(1);
        let boxes: Vec<[f64; 4]> = (0..mesh.cell_count())
            .map(|e| {
                let mut b = [
                    f64::INFINITY,
                    f64::INFINITY,
                    f64::NEG_INFINITY,
                    f64::NEG_INFINITY,
                ];
                for &k in mesh.cell(e) {
                    let x = mesh.nodes[k];
                    b[0] = b[0].min(x[0]);
                    b[1] = b[1].min(x[1]);
                    b[2] = b[2].max(x[0]);
                    b[3] = b[3].max(x[1]);
                }
                // curved (quadratic) edges may bulge past their nodes
                let m = 0.1 * (b[2] - b[0]).max(b[3] - b[1]);
                [b[0] - m, b[1] - m, b[2] + m, b[3] + m]
            })
            .collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for b in &boxes {
            lo = [lo[0].min(b[0]), lo[1].min(b[1])];
            hi = [hi[0].max(b[2]), hi[1].max(b[3])];
        }
        let ext = [(hi[0] - lo[0]).max(1e-12), (hi[1] - lo[1]).max(1e-12)];
        // about one cell per bucket
        let per = ((n as f64) / (ext[0] * ext[1])).sqrt();
        let counts = [
            ((ext[0] * per).ceil() as usize).clamp(1, 4096),
            ((ext[1] * per).ceil() as usize).clamp(1, 4096),
        ];
        let size = [ext[0] / counts[0] as f64, ext[1] / counts[1] as f64];
        let mut buckets = vec![Vec::new(); counts[0] * counts[1]];
        for (e, b) in boxes.iter().enumerate() {
            let i0 = (((b[0] - lo[0]) / size[0]).floor().max(0.0) as usize).min(counts[0] - 1);
            let i1 = (((b[2] - lo[0]) / size[0]).floor().max(0.0) as usize).min(counts[0] - 1);
            let j0 = (((b[1] - lo[1]) / size[1]).floor().max(0.0) as usize).min(counts[1] - 1);
            let j1 = (((b[3] - lo[1]) / size[1]).floor().max(0.0) as usize).min(counts[1] - 1);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    buckets[j * counts[0] + i].push(e);
                }
            }
        }
        Ok(Locator {
            mesh,
            lo,
            size,
            counts,
            buckets,
        })
    }

    /// The cell holding `p` (within `tol` in reference coordinates: a
    /// point on the boundary is inside) and its weights; `None` outside
    /// the mesh.
    pub fn locate(&self, p: [f64; 2], tol: f64) -> Option<Interpolant> {
        let i = ((p[0] - self.lo[0]) / self.size[0]).floor();
        let j = ((p[1] - self.lo[1]) / self.size[1]).floor();
        if i < 0.0 || j < 0.0 || i >= self.counts[0] as f64 || j >= self.counts[1] as f64 {
            return None;
        }
        let b = j as usize * self.counts[0] + i as usize;
        let mut best: Option<(f64, Interpolant)> = None;
        for &e in &self.buckets[b] {
            if let Some((xi, w)) = self.inverse(e, p) {
                let out = xi[0].abs().max(xi[1].abs());
                if out <= 1.0 + tol && best.as_ref().is_none_or(|(o, _)| out < *o) {
                    best = Some((
                        out,
                        Interpolant {
                            cell: e,
                            weights: w,
                        },
                    ));
                    if out <= 1.0 {
                        break;
                    }
                }
            }
        }
        best.map(|(_, i)| i)
    }

    /// Reference coordinates of `p` in cell `e` (Newton on the map) and the
    /// weights there; `None` when Newton does not converge (far outside).
    fn inverse(&self, e: usize, p: [f64; 2]) -> Option<([f64; 2], [f64; MAX_NODES])> {
        let nodes = self.mesh.cell(e);
        let eval = |xi: [f64; 2]| -> ([f64; MAX_NODES], [[f64; 2]; MAX_NODES]) {
            let x3 = [xi[0], xi[1], 0.0];
            let mut n = [0.0; MAX_NODES];
            let mut d = [[0.0; 2]; MAX_NODES];
            match self.mesh.cell_type {
                CellType::Quad4 => {
                    let (a, b) = quad4(&x3);
                    n[..4].copy_from_slice(&a);
                    d[..4].copy_from_slice(&b);
                }
                _ => {
                    let (a, b) = quad9(&x3);
                    n.copy_from_slice(&a);
                    d.copy_from_slice(&b);
                }
            }
            (n, d)
        };
        let scale = {
            let (a, b) = (self.mesh.nodes[nodes[0]], self.mesh.nodes[nodes[2]]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        };
        let mut xi = [0.0f64; 2];
        for _ in 0..30 {
            let (n, d) = eval(xi);
            let mut x = [0.0; 2];
            let mut j = [[0.0; 2]; 2];
            for (a, &k) in nodes.iter().enumerate() {
                let xa = self.mesh.nodes[k];
                for r in 0..2 {
                    x[r] += n[a] * xa[r];
                    for c in 0..2 {
                        j[r][c] += xa[r] * d[a][c];
                    }
                }
            }
            let f = [x[0] - p[0], x[1] - p[1]];
            if (f[0].powi(2) + f[1].powi(2)).sqrt() <= 1e-12 * scale {
                return Some((xi, n));
            }
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if !(det.abs() > 0.0) {
                return None;
            }
            let dxi = [
                (j[1][1] * f[0] - j[0][1] * f[1]) / det,
                (-j[1][0] * f[0] + j[0][0] * f[1]) / det,
            ];
            xi = [
                (xi[0] - dxi[0]).clamp(-3.0, 3.0),
                (xi[1] - dxi[1]).clamp(-3.0, 3.0),
            ];
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::InclusionBlock;

    /// On the inclusion mesh (curved cells on the circle), every located
    /// point maps back to itself through its cell (the node coordinates
    /// interpolated by the weights); boundary points are inside, points
    /// beyond the boundary outside.
    #[test]
    fn located_points_map_back_and_interpolate_node_fields() {
        let block = InclusionBlock {
            width: 40.0,
            height: 20.0,
            centres: vec![[20.0, 10.0]],
            radius: 4.0,
            h: 2.0,
            band: 3.0,
            growth: 1.25,
            ring: 2.0,
        };
        let mesh = block.mesh().unwrap();
        let loc = Locator::new(&mesh).unwrap();
        let mut hits = 0;
        for k in 0..400 {
            let p = [0.1 * k as f64 % 40.0, (0.37 * k as f64 + 0.05) % 20.0];
            let i = loc.locate(p, 1e-9).expect("inside the block");
            // the coordinates are a node field: they interpolate to p
            let x = i.apply(&mesh, |n| mesh.nodes[n][0]);
            let y = i.apply(&mesh, |n| mesh.nodes[n][1]);
            assert!((x - p[0]).abs() < 1e-9 && (y - p[1]).abs() < 1e-9, "{p:?}");
            hits += 1;
        }
        assert_eq!(hits, 400);
        // on the boundary: inside; beyond it: outside
        assert!(loc.locate([0.0, 20.0], 1e-9).is_some());
        assert!(loc.locate([40.0, 0.0], 1e-9).is_some());
        assert!(loc.locate([-0.1, 10.0], 1e-9).is_none());
        assert!(loc.locate([10.0, 20.1], 1e-9).is_none());
    }
}
