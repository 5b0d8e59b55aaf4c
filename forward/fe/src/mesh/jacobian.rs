//! Jacobian determinants of the isoparametric map at the corners of a cell,
//! the usual test for an inverted or wrongly ordered element.
//!
//! Reference cells are `[-1, 1]^d` with the corners in Gmsh/VTK order
//! (see [`CellType`]). At a corner the derivative along one reference
//! direction involves only the nodes of the edge in that direction (the
//! other shape functions vanish along it), so for 4- and 8-node cells
//! it is half the edge vector and for the 9-node quadrilateral it is
//! the end derivative of the 3-node Lagrange line through corner, mid-node
//! and far corner: `s (3/2 x_s - 2 x_mid + 1/2 x_-s)` at `xi = s`.
//!
//! In 2D the determinant is that of `d(x, y)/d(xi, eta)`, positive for
//! corners ordered counter-clockwise; in 3D that of `dx/d(xi, eta, zeta)`,
//! positive for a hexahedron whose bottom face 0-1-2-3 turns
//! counter-clockwise seen from the top face.

use super::CellType;
// the reference corners are those of the shape functions
use crate::shape::{HEX8_NODES as HEX_CORNERS, QUAD4_NODES as QUAD_CORNERS};

/// The mid-node of the edge between two corners of a 9-node quadrilateral.
fn quad9_mid(a: usize, b: usize) -> usize {
    match (a.min(b), a.max(b)) {
        (0, 1) => 4,
        (1, 2) => 5,
        (2, 3) => 6,
        _ => 7, // (0, 3)
    }
}

/// The corner of the same reference cell that differs from corner `k` in
/// reference coordinate `axis` only.
fn neighbour<const D: usize>(corners: &[[f64; D]], k: usize, axis: usize) -> usize {
    let mut target = corners[k];
    target[axis] = -target[axis];
    corners.iter().position(|c| *c == target).unwrap_or(k)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Jacobian determinants at the corners of a cell with node coordinates `x`
/// (`cell_type.nodes()` of them), one per corner in corner order. Lines
/// have no orientation to test: empty.
pub fn corner_jacobians(cell_type: CellType, x: &[[f64; 3]]) -> Vec<f64> {
    match cell_type {
        CellType::Line2 | CellType::Line3 => Vec::new(),
        CellType::Quad4 | CellType::Quad9 => (0..4)
            .map(|k| {
                let d: Vec<[f64; 3]> = (0..2)
                    .map(|axis| {
                        let m = neighbour(&QUAD_CORNERS, k, axis);
                        let s = QUAD_CORNERS[k][axis];
                        if cell_type == CellType::Quad9 {
                            let mid = x[quad9_mid(k, m)];
                            let mut t = [0.0; 3];
                            for i in 0..3 {
                                t[i] = s * (1.5 * x[k][i] - 2.0 * mid[i] + 0.5 * x[m][i]);
                            }
                            t
                        } else {
                            let e = sub(x[k], x[m]);
                            [0.5 * s * e[0], 0.5 * s * e[1], 0.5 * s * e[2]]
                        }
                    })
                    .collect();
                d[0][0] * d[1][1] - d[0][1] * d[1][0]
            })
            .collect(),
        CellType::Hex27 => crate::shape::HEX8_NODES
            .iter()
            .map(|xi| {
                // dx/dxi from all 27 shape functions at the corner
                let (_, d) = crate::shape::hex27(xi);
                let mut j = [[0.0; 3]; 3];
                for (a, p) in x.iter().enumerate().take(27) {
                    for i in 0..3 {
                        for k in 0..3 {
                            j[i][k] += p[i] * d[a][k];
                        }
                    }
                }
                j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
                    - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
                    + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0])
            })
            .collect(),
        CellType::Hex8 => (0..8)
            .map(|k| {
                let d: Vec<[f64; 3]> = (0..3)
                    .map(|axis| {
                        let m = neighbour(&HEX_CORNERS, k, axis);
                        let s = HEX_CORNERS[k][axis];
                        let e = sub(x[k], x[m]);
                        [0.5 * s * e[0], 0.5 * s * e[1], 0.5 * s * e[2]]
                    })
                    .collect();
                d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1])
                    - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0])
                    + d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0])
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: [[f64; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 2.0, 0.0],
        [0.0, 2.0, 0.0],
    ];

    #[test]
    fn square_has_unit_jacobian_and_clockwise_is_negative() {
        let j = corner_jacobians(CellType::Quad4, &SQUARE);
        assert_eq!(j, vec![1.0; 4]);
        let cw = [SQUARE[0], SQUARE[3], SQUARE[2], SQUARE[1]];
        assert!(corner_jacobians(CellType::Quad4, &cw)
            .iter()
            .all(|&d| d < 0.0));
        // A dart (re-entrant corner 2): one corner goes negative.
        let dart = [SQUARE[0], SQUARE[1], [0.5, 0.5, 0.0], SQUARE[3]];
        let j = corner_jacobians(CellType::Quad4, &dart);
        assert!(j[2] < 0.0 && j[0] > 0.0);
    }

    #[test]
    fn quad9_uses_the_mid_nodes() {
        let mut x: Vec<[f64; 3]> = SQUARE.to_vec();
        x.extend([
            [1.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
            [0.0, 1.0, 0.0],
        ]);
        x.push([1.0, 1.0, 0.0]);
        assert_eq!(corner_jacobians(CellType::Quad9, &x), vec![1.0; 4]);
        // Moving the mid-node of edge 0-1 past the quarter point folds corner 0.
        x[4] = [0.4, 0.0, 0.0];
        let j = corner_jacobians(CellType::Quad9, &x);
        assert!(j[0] < 0.0 && j[1] > 0.0, "{j:?}");
    }

    #[test]
    fn unit_cube_and_mirrored_cube() {
        let x: Vec<[f64; 3]> = HEX_CORNERS
            .iter()
            .map(|c| [(c[0] + 1.0) / 2.0, (c[1] + 1.0) / 2.0, (c[2] + 1.0) / 2.0])
            .collect();
        assert!(corner_jacobians(CellType::Hex8, &x)
            .iter()
            .all(|&d| (d - 0.125).abs() < 1e-15));
        let mirrored: Vec<[f64; 3]> = x.iter().map(|p| [p[0], p[1], -p[2]]).collect();
        assert!(corner_jacobians(CellType::Hex8, &mirrored)
            .iter()
            .all(|&d| d < 0.0));
    }
}
