//! A quarter O-grid of 8-node hexahedra for a tool pressed on the line
//! x = y = 0 of the box `[0, lx] x [0, ly] x [0, lz]` (N3): in the xy-plane
//! a square core `[0, s]^2` of `n x n` cells around the axis, then rings of
//! `2n` cells that blend from the square to quarter circles (radius
//! `rho_k`) and, beyond `circle_radius`, from the last circle to the
//! rectangular outer boundary; the plane mesh is extruded along z on the
//! graded coordinate lines of `axial` (fine at the top). The hexahedra
//! follow the round contact of an axisymmetric tool the way N1's
//! axisymmetric mesh does, and the far field is coarse in every direction
//! (a graded tensor box repeats its fine lines across the whole block).
//!
//! The radial node positions `rho_k` are those of `radial` over
//! `min(lx, ly)`: the core uses the first `n + 1` of them on both axes
//! (side `s = rho_n`), ring `k` sits at `rho_k`. The square-to-circle blend
//! makes the diagonal radius grow linearly from `sqrt(2) s` at ring `n` to
//! `3 s` (the blend radius, as CalculiX's N1 deck `gen_n1.py` of
//! `tests/data/calculix`), so no cell is squeezed at the corner of
//! the core. Sets as [`Mesh::graded_box`]: node and Quad4 facet sets `x0`,
//! `x1`, `y0`, `y1`, `bottom`, `top`, facets facing out; region `body`.

use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, SQRT_2};

use super::{CellType, FacetSet, Grading, Mesh};
use crate::FeError;

/// The plane quarter O-grid of [`Mesh::quarter_ogrid`]: node positions and
/// counter-clockwise quadrilaterals.
struct Plane {
    nodes: Vec<[f64; 2]>,
    quads: Vec<[usize; 4]>,
}

/// A point of the unit square's upper-right boundary for angular index `j`
/// of `0..=2n`: `(1, rho_j / rho_n)` up to the corner, then
/// `(rho_{2n-j} / rho_n, 1)`.
fn square_point(rho: &[f64], n: usize, j: usize) -> [f64; 2] {
    if j <= n {
        [1.0, rho[j] / rho[n]]
    } else {
        [rho[2 * n - j] / rho[n], 1.0]
    }
}

/// The rectangle's boundary point of angular index `j` of `0..=2n`: the
/// ray at `theta = j / 2n * 90 deg` scaled to hit `x = lx` up to the
/// diagonal (`j = n` is the corner `(lx, ly)`), `y = ly` beyond.
fn boundary_point(lx: f64, ly: f64, n: usize, j: usize) -> [f64; 2] {
    let theta = FRAC_PI_2 * j as f64 / (2 * n) as f64;
    if j == n {
        [lx, ly]
    } else if j < n {
        [lx, ly * theta.tan()]
    } else if j == 2 * n {
        [0.0, ly]
    } else {
        [lx * (FRAC_PI_2 - theta).tan(), ly]
    }
}

fn plane(
    lx: f64,
    ly: f64,
    radial: Grading,
    n: usize,
    circle_radius: f64,
) -> Result<Plane, FeError> {
    let bad = |reason: String| FeError::InvalidMesh {
        field: "o-grid".into(),
        reason,
    };
    let rho = radial.positions(lx.min(ly))?;
    let last = rho.len() - 1;
    if n == 0 || n + 1 > last {
        return Err(bad(format!(
            "a core of {n} cells needs more than {} radial cells",
            n + 1
        )));
    }
    let s = rho[n];
    let blend = 3.0 * s;
    // the last circular ring: at or below circle_radius, beyond the blend
    let kc = (0..=last)
        .rev()
        .find(|&k| rho[k] <= circle_radius + 1e-9)
        .unwrap_or(0);
    if rho[kc] < blend - 1e-9 || kc >= last {
        return Err(bad(format!(
            "the circle radius {circle_radius} mm must lie between the blend radius {blend:.3} mm (3 x the core) and the outer boundary"
        )));
    }
    let mut nodes: Vec<[f64; 2]> = Vec::new();
    let mut quads = Vec::new();
    // core: node (i, j) of the (n+1)^2 grid
    for j in 0..=n {
        for i in 0..=n {
            nodes.push([rho[i], rho[j]]);
        }
    }
    let core = |i: usize, j: usize| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            quads.push([
                core(i, j),
                core(i + 1, j),
                core(i + 1, j + 1),
                core(i, j + 1),
            ]);
        }
    }
    // ring k = n is the core's boundary: angular index a = 0..=2n
    let ring_n: Vec<usize> = (0..=2 * n)
        .map(|a| {
            if a <= n {
                core(n, a)
            } else {
                core(2 * n - a, n)
            }
        })
        .collect();
    let mut rings = vec![ring_n];
    let c = (blend - SQRT_2 * s) / (blend - s);
    for k in n + 1..=last {
        let r = rho[k];
        let mut ring = Vec::with_capacity(2 * n + 1);
        for a in 0..=2 * n {
            let theta = FRAC_PI_2 * a as f64 / (2 * n) as f64;
            let p = if k <= kc {
                // blend weight so that the diagonal radius is linear in rho
                let beta = if r >= blend {
                    1.0
                } else {
                    let diag = SQRT_2 * s + c * (r - s);
                    ((SQRT_2 - diag / r) / (SQRT_2 - 1.0)).clamp(0.0, 1.0)
                };
                let q = square_point(&rho, n, a);
                [
                    r * ((1.0 - beta) * q[0] + beta * theta.cos()),
                    r * ((1.0 - beta) * q[1] + beta * theta.sin()),
                ]
            } else {
                let g = (r - rho[kc]) / (rho[last] - rho[kc]);
                let b = boundary_point(lx, ly, n, a);
                let rc = rho[kc];
                [
                    (1.0 - g) * rc * theta.cos() + g * b[0],
                    (1.0 - g) * rc * theta.sin() + g * b[1],
                ]
            };
            // exact symmetry planes
            let p = match a {
                0 => [p[0], 0.0],
                x if x == 2 * n => [0.0, p[1]],
                _ => p,
            };
            nodes.push(p);
            ring.push(nodes.len() - 1);
        }
        let prev = &rings[rings.len() - 1];
        for a in 0..2 * n {
            quads.push([prev[a], ring[a], ring[a + 1], prev[a + 1]]);
        }
        rings.push(ring);
    }
    Ok(Plane { nodes, quads })
}

impl Mesh {
    /// The quarter O-grid of this module's doc: `n` core cells per side
    /// (`2n` around each ring), radial positions from `radial`, circles up to
    /// `circle_radius` (mm), z lines from `axial` (fine at the top z = lz).
    pub fn quarter_ogrid(
        lx: f64,
        ly: f64,
        lz: f64,
        radial: Grading,
        axial: Grading,
        n: usize,
        circle_radius: f64,
    ) -> Result<Mesh, FeError> {
        let p = plane(lx, ly, radial, n, circle_radius)?;
        let zs: Vec<f64> = axial.positions(lz)?.iter().rev().map(|t| lz - t).collect();
        let np = p.nodes.len();
        let nz = zs.len();
        let id = |q: usize, k: usize| k * np + q;
        let mut m = Mesh::empty(3, CellType::Hex8);
        for &z in &zs {
            for q in &p.nodes {
                m.nodes.push([q[0], q[1], z]);
            }
        }
        for k in 0..nz - 1 {
            for q in &p.quads {
                m.cells.extend([
                    id(q[0], k),
                    id(q[1], k),
                    id(q[2], k),
                    id(q[3], k),
                    id(q[0], k + 1),
                    id(q[1], k + 1),
                    id(q[2], k + 1),
                    id(q[3], k + 1),
                ]);
            }
        }
        // boundary edges of the plane mesh (domain on their left)
        let mut count: HashMap<(usize, usize), usize> = HashMap::new();
        for q in &p.quads {
            for e in 0..4 {
                let (a, b) = (q[e], q[(e + 1) % 4]);
                *count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let tol = 1e-9 * lx.max(ly);
        let on = |name: &str, x: [f64; 2]| match name {
            "x0" => x[0].abs() < tol,
            "x1" => (x[0] - lx).abs() < tol,
            "y0" => x[1].abs() < tol,
            _ => (x[1] - ly).abs() < tol,
        };
        for name in ["x0", "x1", "y0", "y1"] {
            let mut facets = Vec::new();
            for q in &p.quads {
                for e in 0..4 {
                    let (a, b) = (q[e], q[(e + 1) % 4]);
                    if count[&(a.min(b), a.max(b))] == 1
                        && on(name, p.nodes[a])
                        && on(name, p.nodes[b])
                    {
                        for k in 0..nz - 1 {
                            facets.extend([id(a, k), id(b, k), id(b, k + 1), id(a, k + 1)]);
                        }
                    }
                }
            }
            let mut set: Vec<usize> = (0..nz)
                .flat_map(|k| {
                    (0..np)
                        .filter(|&q| on(name, p.nodes[q]))
                        .map(move |q| id(q, k))
                })
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
        }
        for (name, k, up) in [("bottom", 0, false), ("top", nz - 1, true)] {
            let mut facets = Vec::new();
            for q in &p.quads {
                let f = q.map(|a| id(a, k));
                if up {
                    facets.extend(f);
                } else {
                    facets.extend([f[0], f[3], f[2], f[1]]);
                }
            }
            m.facet_sets.insert(
                name.into(),
                FacetSet {
                    cell_type: CellType::Quad4,
                    nodes: facets,
                },
            );
            m.node_sets
                .insert(name.into(), (0..np).map(|q| id(q, k)).collect());
        }
        m.regions
            .insert("body".into(), (0..m.cell_count()).collect());
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::super::jacobian::corner_jacobians;
    use super::*;

    fn hex_volume(x: &[[f64; 3]]) -> f64 {
        // 2x2x2 Gauss rule of the trilinear map's Jacobian
        let g = 1.0 / 3f64.sqrt();
        let corners = crate::shape::HEX8_NODES;
        let mut v = 0.0;
        for &a in &[-g, g] {
            for &b in &[-g, g] {
                for &c in &[-g, g] {
                    let mut j = [[0.0; 3]; 3];
                    for (k, r) in corners.iter().enumerate() {
                        let d = [
                            0.125 * r[0] * (1.0 + r[1] * b) * (1.0 + r[2] * c),
                            0.125 * r[1] * (1.0 + r[0] * a) * (1.0 + r[2] * c),
                            0.125 * r[2] * (1.0 + r[0] * a) * (1.0 + r[1] * b),
                        ];
                        for i in 0..3 {
                            for l in 0..3 {
                                j[i][l] += x[k][i] * d[l];
                            }
                        }
                    }
                    v += j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
                        - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
                        + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
                }
            }
        }
        v
    }

    #[test]
    fn the_ogrid_fills_the_box_with_positive_cells_and_faces_out() {
        let g = Grading {
            h_fine: 0.8,
            fine_length: 4.0,
            growth: 1.4,
        };
        let (lx, ly, lz) = (35.0, 40.0, 80.0);
        let m = Mesh::quarter_ogrid(lx, ly, lz, g, g, 3, 17.5).unwrap();
        m.validate().unwrap();
        let mut volume = 0.0;
        for c in m.cells() {
            let x: Vec<[f64; 3]> = c.iter().map(|&n| m.nodes[n]).collect();
            let j = corner_jacobians(CellType::Hex8, &x);
            assert!(j.iter().all(|&d| d > 0.0), "{x:?}: {j:?}");
            volume += hex_volume(&x);
        }
        // the round core (quarter circles) is inside the straight-sided box:
        // the trilinear cells' chords lose a little of the circle between
        // rings, but the outer boundary is the rectangle, so the total is exact
        assert!((volume / (lx * ly * lz) - 1.0).abs() < 1e-9, "{volume}");
        let centre = [lx / 2.0, ly / 2.0, lz / 2.0];
        let planes = [
            ("x0", 0, 0.0),
            ("x1", 0, lx),
            ("y0", 1, 0.0),
            ("y1", 1, ly),
            ("bottom", 2, 0.0),
            ("top", 2, lz),
        ];
        let mut area = 0.0;
        for (name, axis, at) in planes {
            let set = m.node_set(name).unwrap();
            assert!(
                set.iter().all(|&n| (m.nodes[n][axis] - at).abs() < 1e-9),
                "{name}"
            );
            let count = m
                .nodes
                .iter()
                .filter(|p| (p[axis] - at).abs() < 1e-9)
                .count();
            assert_eq!(set.len(), count, "{name}");
            for f in m.facet_set(name).unwrap().iter() {
                let p: Vec<[f64; 3]> = f.iter().map(|&n| m.nodes[n]).collect();
                let d1: Vec<f64> = (0..3).map(|i| p[2][i] - p[0][i]).collect();
                let d2: Vec<f64> = (0..3).map(|i| p[3][i] - p[1][i]).collect();
                let nrm = [
                    d1[1] * d2[2] - d1[2] * d2[1],
                    d1[2] * d2[0] - d1[0] * d2[2],
                    d1[0] * d2[1] - d1[1] * d2[0],
                ];
                let out: f64 = (0..3).map(|i| nrm[i] * (p[0][i] - centre[i])).sum();
                assert!(out > 0.0, "{name}");
                area += 0.5 * nrm[axis].abs();
            }
        }
        let total = 2.0 * (lx * ly + ly * lz + lx * lz);
        assert!((area / total - 1.0).abs() < 1e-9, "{area} vs {total}");
        // the rings between the blend (3 x the core) and the circle radius
        // are circles: 2n + 1 top nodes on each
        let rho = g.positions(lx).unwrap();
        let top = m.node_set("top").unwrap();
        let mut circles = 0;
        for &r in rho.iter().filter(|&&r| r >= 3.0 * rho[3] && r <= 17.5) {
            let on = top
                .iter()
                .filter(|&&q| (m.nodes[q][0].hypot(m.nodes[q][1]) - r).abs() < 1e-9)
                .count();
            assert_eq!(on, 7, "ring at {r}");
            circles += 1;
        }
        assert!(circles >= 2, "{circles}");
        // too small a circle (inside the blend) is refused with the reason
        let e = Mesh::quarter_ogrid(lx, ly, lz, g, g, 3, 3.0).unwrap_err();
        assert!(e.to_string().contains("circle radius"), "{e}");
    }
}
