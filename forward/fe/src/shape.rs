//! Lagrange shape functions `N_a(xi)` and their reference gradients
//! `dN_a/dxi_k` on the reference cells `[-1, 1]^d`, in the node order of
//! [`crate::mesh::CellType`] (Gmsh and VTK): corners counter-clockwise, then
//! mid-edge nodes, then the centre (Hughes, *The Finite Element Method*,
//! 2000, sections 3.2 and 3.6).
//!
//! Each function returns fixed-size arrays so that element kernels written
//! over `const N: usize` keep all their algebra on the stack.

/// Shape functions and reference gradients of a cell with `N` nodes in `D`
/// reference dimensions.
pub type ShapeEval<const N: usize, const D: usize> = ([f64; N], [[f64; D]; N]);

/// Reference coordinates of the nodes of the 4-node quadrilateral.
pub const QUAD4_NODES: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// Reference coordinates of the nodes of the 9-node quadrilateral.
pub const QUAD9_NODES: [[f64; 2]; 9] = [
    [-1.0, -1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [0.0, -1.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [-1.0, 0.0],
    [0.0, 0.0],
];

/// Reference coordinates of the nodes of the 8-node hexahedron.
pub const HEX8_NODES: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Reference coordinates of the nodes of the 27-node hexahedron, in VTK's
/// order (VTK_TRIQUADRATIC_HEXAHEDRON, `vtkTriQuadraticHexahedron`): the
/// corners as [`HEX8_NODES`]; the mid-edge nodes of the edges 0-1, 1-2,
/// 2-3, 3-0, 4-5, 5-6, 6-7, 7-4, 0-4, 1-5, 2-6, 3-7; the face centres of
/// the faces -x, +x, -y, +y, -z, +z; the cell centre. (Gmsh's 27-node
/// order differs in the edges and faces.)
pub const HEX27_NODES: [[f64; 3]; 27] = hex27_nodes();

/// The corner pairs of the 12 edges of a hexahedron, in the order of the
/// mid-edge nodes 8-19 of [`HEX27_NODES`].
pub const HEX_EDGES: [[usize; 2]; 12] = [
    [0, 1],
    [1, 2],
    [2, 3],
    [3, 0],
    [4, 5],
    [5, 6],
    [6, 7],
    [7, 4],
    [0, 4],
    [1, 5],
    [2, 6],
    [3, 7],
];

/// The corners of the 6 faces of a hexahedron (each a closed loop), in the
/// order of the face centres 20-25 of [`HEX27_NODES`]: -x, +x, -y, +y, -z, +z.
pub const HEX_FACES: [[usize; 4]; 6] = [
    [0, 4, 7, 3],
    [1, 2, 6, 5],
    [0, 1, 5, 4],
    [3, 7, 6, 2],
    [0, 3, 2, 1],
    [4, 5, 6, 7],
];

/// [`HEX27_NODES`] from the corners of [`HEX8_NODES`]: each mid-edge node
/// and face centre the mean of its corners ([`HEX_EDGES`], [`HEX_FACES`]),
/// then the origin.
const fn hex27_nodes() -> [[f64; 3]; 27] {
    let mut x = [[0.0; 3]; 27];
    let mut a = 0;
    while a < 8 {
        x[a] = HEX8_NODES[a];
        a += 1;
    }
    let mut e = 0;
    while e < 12 {
        let [p, q] = HEX_EDGES[e];
        let mut i = 0;
        while i < 3 {
            x[8 + e][i] = 0.5 * (HEX8_NODES[p][i] + HEX8_NODES[q][i]);
            i += 1;
        }
        e += 1;
    }
    let mut f = 0;
    while f < 6 {
        let c = HEX_FACES[f];
        let mut i = 0;
        while i < 3 {
            x[20 + f][i] = 0.25
                * (HEX8_NODES[c[0]][i]
                    + HEX8_NODES[c[1]][i]
                    + HEX8_NODES[c[2]][i]
                    + HEX8_NODES[c[3]][i]);
            i += 1;
        }
        f += 1;
    }
    x
}

/// Bilinear quadrilateral: `N_a = (1 + s s_a)(1 + t t_a) / 4`.
pub fn quad4(xi: &[f64; 3]) -> ShapeEval<4, 2> {
    let (s, t) = (xi[0], xi[1]);
    (
        [
            0.25 * (1.0 - s) * (1.0 - t),
            0.25 * (1.0 + s) * (1.0 - t),
            0.25 * (1.0 + s) * (1.0 + t),
            0.25 * (1.0 - s) * (1.0 + t),
        ],
        [
            [-0.25 * (1.0 - t), -0.25 * (1.0 - s)],
            [0.25 * (1.0 - t), -0.25 * (1.0 + s)],
            [0.25 * (1.0 + t), 0.25 * (1.0 + s)],
            [-0.25 * (1.0 + t), 0.25 * (1.0 - s)],
        ],
    )
}

/// One-dimensional quadratic Lagrange polynomials on the nodes -1, 1, 0
/// and their derivatives.
fn lagrange2(x: f64) -> ([f64; 3], [f64; 3]) {
    (
        [0.5 * x * (x - 1.0), 0.5 * x * (x + 1.0), 1.0 - x * x],
        [x - 0.5, x + 0.5, -2.0 * x],
    )
}

/// Index (0: node -1, 1: node 1, 2: node 0) of a reference coordinate.
fn lagrange_index(c: f64) -> usize {
    if c < -0.5 {
        0
    } else if c > 0.5 {
        1
    } else {
        2
    }
}

/// Biquadratic (Lagrange) quadrilateral: products of 1D quadratics.
pub fn quad9(xi: &[f64; 3]) -> ShapeEval<9, 2> {
    let (ls, ds) = lagrange2(xi[0]);
    let (lt, dt) = lagrange2(xi[1]);
    let mut n = [0.0; 9];
    let mut d = [[0.0; 2]; 9];
    for (a, p) in QUAD9_NODES.iter().enumerate() {
        let (i, j) = (lagrange_index(p[0]), lagrange_index(p[1]));
        n[a] = ls[i] * lt[j];
        d[a] = [ds[i] * lt[j], ls[i] * dt[j]];
    }
    (n, d)
}

/// Trilinear hexahedron: `N_a = (1 + r r_a)(1 + s s_a)(1 + t t_a) / 8`.
pub fn hex8(xi: &[f64; 3]) -> ShapeEval<8, 3> {
    let mut n = [0.0; 8];
    let mut d = [[0.0; 3]; 8];
    for (a, p) in HEX8_NODES.iter().enumerate() {
        let f = [1.0 + p[0] * xi[0], 1.0 + p[1] * xi[1], 1.0 + p[2] * xi[2]];
        n[a] = 0.125 * f[0] * f[1] * f[2];
        d[a] = [
            0.125 * p[0] * f[1] * f[2],
            0.125 * f[0] * p[1] * f[2],
            0.125 * f[0] * f[1] * p[2],
        ];
    }
    (n, d)
}

/// Triquadratic (Lagrange) hexahedron: products of 1D quadratics, nodes in
/// the order of [`HEX27_NODES`].
pub fn hex27(xi: &[f64; 3]) -> ShapeEval<27, 3> {
    let (lr, dr) = lagrange2(xi[0]);
    let (ls, ds) = lagrange2(xi[1]);
    let (lt, dt) = lagrange2(xi[2]);
    let mut n = [0.0; 27];
    let mut d = [[0.0; 3]; 27];
    for (a, p) in HEX27_NODES.iter().enumerate() {
        let (i, j, k) = (
            lagrange_index(p[0]),
            lagrange_index(p[1]),
            lagrange_index(p[2]),
        );
        n[a] = lr[i] * ls[j] * lt[k];
        d[a] = [
            dr[i] * ls[j] * lt[k],
            lr[i] * ds[j] * lt[k],
            lr[i] * ls[j] * dt[k],
        ];
    }
    (n, d)
}

/// Linear line: nodes at -1 and 1.
pub fn line2(xi: &[f64; 3]) -> ShapeEval<2, 1> {
    let s = xi[0];
    ([0.5 * (1.0 - s), 0.5 * (1.0 + s)], [[-0.5], [0.5]])
}

/// Quadratic line: nodes at -1, 1, then the mid-node 0.
pub fn line3(xi: &[f64; 3]) -> ShapeEval<3, 1> {
    let (l, d) = lagrange2(xi[0]);
    (l, [[d[0]], [d[1]], [d[2]]])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Kronecker property at the nodes, partition of unity, and gradients
    /// against central differences at an interior point.
    fn check<const N: usize, const D: usize>(
        f: fn(&[f64; 3]) -> ShapeEval<N, D>,
        nodes: &[[f64; 3]],
    ) {
        for (a, p) in nodes.iter().enumerate() {
            let (n, _) = f(p);
            for (b, v) in n.iter().enumerate() {
                assert!((v - if a == b { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        let x = [0.31, -0.47, 0.22];
        let (n, d) = f(&x);
        assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let h = 1e-6;
        for k in 0..D {
            let (mut xp, mut xm) = (x, x);
            xp[k] += h;
            xm[k] -= h;
            let (np, _) = f(&xp);
            let (nm, _) = f(&xm);
            for a in 0..N {
                assert!(((np[a] - nm[a]) / (2.0 * h) - d[a][k]).abs() < 1e-9);
            }
            assert!(d.iter().map(|g| g[k]).sum::<f64>().abs() < 1e-13);
        }
    }

    /// The 27-node table is VTK's (vtkTriQuadraticHexahedron): spot checks
    /// of mid-edge nodes, every face centre and the centre against VTK's
    /// order, and all 27 nodes distinct.
    #[test]
    fn hex27_nodes_are_in_vtk_order() {
        let expect: [(usize, [f64; 3]); 10] = [
            (8, [0.0, -1.0, -1.0]),
            (11, [-1.0, 0.0, -1.0]),
            (15, [-1.0, 0.0, 1.0]),
            (19, [-1.0, 1.0, 0.0]),
            (20, [-1.0, 0.0, 0.0]),
            (21, [1.0, 0.0, 0.0]),
            (22, [0.0, -1.0, 0.0]),
            (23, [0.0, 1.0, 0.0]),
            (24, [0.0, 0.0, -1.0]),
            (26, [0.0, 0.0, 0.0]),
        ];
        for (a, x) in expect {
            assert_eq!(HEX27_NODES[a], x, "node {a}");
        }
        assert_eq!(HEX27_NODES[25], [0.0, 0.0, 1.0]);
        assert_eq!(&HEX27_NODES[..8], &HEX8_NODES[..]);
        for a in 0..27 {
            for b in a + 1..27 {
                assert_ne!(HEX27_NODES[a], HEX27_NODES[b]);
            }
        }
    }

    #[test]
    fn shape_functions_interpolate_and_differentiate() {
        let to3 = |p: &[f64]| [p[0], *p.get(1).unwrap_or(&0.0), *p.get(2).unwrap_or(&0.0)];
        check(quad4, &QUAD4_NODES.map(|p| to3(&p)));
        check(quad9, &QUAD9_NODES.map(|p| to3(&p)));
        check(hex8, &HEX8_NODES.map(|p| to3(&p)));
        check(hex27, &HEX27_NODES);
        check(line2, &[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        check(line3, &[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
    }
}
