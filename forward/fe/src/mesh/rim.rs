//! A rectangle mesh refined about one point of its top edge (a flat
//! punch's rim, a platen's edge) in that point's neighbourhood only.
//!
//! A tensor-product mesh refined towards a point
//! ([`super::grading::refine_towards`]) carries its small elements along
//! whole mesh lines: through the body's height under the point and along
//! its whole top. Here the small elements stay in a window about the
//! point: the tensor-product mesh of the given lines has, around the
//! point, a window of `mw x m` cells of one size (the window's half-width
//! `S` over `m`; `mw = 2m`, or `m` where the point is on the body's side),
//! and inside the window nested copies of its boundary scaled towards the
//! point (half-widths `s_0 < s_1 < ... < s_K = S`, growing geometrically,
//! each with as many nodes as the window's boundary) are joined ring by
//! ring; the innermost copy is filled with `mw x m` cells of `s_0 / m`, the
//! element size at the point. The elements grow in proportion to their
//! distance from the point, radially and in depth alike, and the mesh is
//! conforming (every ring shares its nodes with the next).

use super::structured::with_lines;
use super::{CellType, FacetSet, Mesh};
use crate::FeError;

/// The refinement about a point of the top edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RimWindow {
    /// Radial position of the point on the top (mm).
    pub centre: f64,
    /// Half-width (and depth) of the window (mm); reduced to fit the body
    /// (the axis, the side, the base and the first interface).
    pub half_width: f64,
    /// The element size of the tensor-product lines about the window
    /// (mm): the window's cells are `S / m` with `m = round(S / spacing)`.
    pub spacing: f64,
    /// Element size at the point (mm).
    pub h: f64,
    /// Growth of the elements per unit distance from the point (the rings'
    /// half-widths grow by `1 + slope`, at least by the cells' own aspect:
    /// `1 + 1 / m`).
    pub slope: f64,
}

fn bad(reason: String) -> FeError {
    FeError::InvalidMesh {
        field: "rim window".into(),
        reason,
    }
}

/// `lines` (increasing, from 0) with the interval `[from, to]` replaced by
/// `n` equal cells; a line outside it closer to an end than a third of a
/// cell is dropped (no sliver), the first and last lines are kept.
fn splice(lines: &[f64], from: f64, to: f64, n: usize) -> Vec<f64> {
    let h = (to - from) / n as f64;
    let (first, last) = (lines[0], lines[lines.len() - 1]);
    let mut out: Vec<f64> = lines
        .iter()
        .copied()
        .filter(|&x| {
            x == first
                || x == last
                || (x < from && from - x > h / 3.0)
                || (x > to && x - to > h / 3.0)
        })
        .filter(|&x| !(x >= from && x <= to))
        .collect();
    out.extend((0..=n).map(|k| if k == n { to } else { from + h * k as f64 }));
    out.sort_by(f64::total_cmp);
    out.dedup();
    out
}

impl Mesh {
    /// The rectangle `[0, rs.last] x [0, height]` on the radial lines `rs`
    /// (from the axis) and the depths `from_top` (below the top, from 0 to
    /// `height`), cut into horizontal bands at `interfaces` as
    /// [`Mesh::lines_in_layers`] (regions `layer{i}`; `body` without
    /// interfaces), refined about the top point at `window.centre` (the
    /// module's docs). Sets `axis`, `side`, `bottom` and `top` as
    /// [`Mesh::tensor`]'s, in order along their side.
    pub fn rim_refined(
        rs: &[f64],
        from_top: &[f64],
        height: f64,
        interfaces: &[f64],
        window: RimWindow,
    ) -> Result<Mesh, FeError> {
        let RimWindow {
            centre: c,
            half_width,
            spacing,
            h,
            slope,
        } = window;
        if rs.len() < 2 || from_top.len() < 2 {
            return Err(bad("need at least two radial and two axial lines".into()));
        }
        let radius = rs[rs.len() - 1];
        for (what, v) in [("half_width", half_width), ("spacing", spacing), ("h", h)] {
            if !(v > 0.0 && v.is_finite()) {
                return Err(bad(format!("{what} = {v}: expected a finite length > 0")));
            }
        }
        if !(slope > 0.0 && slope.is_finite()) {
            return Err(bad(format!("slope = {slope}: expected > 0")));
        }
        if !(c > 0.0 && c <= radius) {
            return Err(bad(format!(
                "centre {c} mm: expected inside (0, {radius}] (the top edge)"
            )));
        }
        let mut last = 0.0;
        for &t in interfaces {
            if !(t > last && t < height) {
                return Err(bad(format!(
                    "interfaces {interfaces:?} must increase strictly inside (0, {height})"
                )));
            }
            last = t;
        }
        // the window: inside the body and above the first interface
        let on_side = c == radius;
        let room = if on_side { c } else { c.min(radius - c) };
        let mut s = half_width.min(room).min(height);
        if let Some(&t) = interfaces.first() {
            // an interface just below the window becomes its bottom
            s = if t < s * (1.0 + 1.0 / 3.0) {
                t
            } else {
                s.min(t)
            };
        }
        let m = ((s / spacing).round() as usize).max(1);
        let mw = if on_side { m } else { 2 * m };
        let ts = if interfaces.is_empty() {
            from_top.to_vec()
        } else {
            with_lines(from_top, interfaces)
        };
        let left = c - s;
        let rs = if on_side {
            let mut v = splice(rs, left, c, m);
            v.retain(|&x| x <= c);
            v
        } else {
            splice(rs, left, c + s, mw)
        };
        let ts = splice(&ts, 0.0, s, m);
        let ys: Vec<f64> = ts.iter().rev().map(|t| height - t).collect();
        let mut ys = ys;
        if let Some(top) = ys.last_mut() {
            *top = height;
        }
        let (nx, ny) = (rs.len(), ys.len());
        let i0 = rs
            .iter()
            .position(|&x| x == left)
            .ok_or_else(|| bad("the window's left line is missing".into()))?;
        let jt = ny - 1;
        let j0 = jt - m;
        let id = |i: usize, j: usize| j * nx + i;
        // (on the side, the window's right edge is the body's side, which
        // the copies meet at their own nodes: only its top corner stays)
        let inside = |i: usize, j: usize| {
            j > j0 && i > i0 && (i < i0 + mw || (on_side && i == i0 + mw && j < jt))
        };
        let mut nodes: Vec<[f64; 3]> = Vec::with_capacity(nx * ny);
        let mut index = vec![usize::MAX; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                // the window's interior nodes and its top between its ends
                if inside(i, j) || (j == jt && i > i0 && i < i0 + mw) {
                    continue;
                }
                index[id(i, j)] = nodes.len();
                nodes.push([rs[i], ys[j], 0.0]);
            }
        }
        let mut cells: Vec<usize> = Vec::new();
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                if i >= i0 && i < i0 + mw && j >= j0 {
                    continue;
                }
                cells.extend([
                    index[id(i, j)],
                    index[id(i + 1, j)],
                    index[id(i + 1, j + 1)],
                    index[id(i, j + 1)],
                ]);
            }
        }
        // the window's boundary from its top-left corner down, across and
        // (unless on the side) up: the cell (p, q) of a grid of mw x m
        let path = m + mw + if on_side { 0 } else { m };
        let pq = |k: usize| -> (usize, usize) {
            if k <= m {
                (0, k)
            } else if k <= m + mw {
                (k - m, m)
            } else {
                (mw, m - (k - m - mw))
            }
        };
        let point = |sk: f64, (p, q): (usize, usize)| -> [f64; 3] {
            let r = if p == mw && on_side {
                c
            } else {
                c - sk + sk * p as f64 / m as f64
            };
            let y = if q == 0 {
                height
            } else {
                height - sk * q as f64 / m as f64
            };
            [r, y, 0.0]
        };
        // half-widths of the nested copies, innermost first (s_K = s)
        let s0 = m as f64 * h;
        let halves: Vec<f64> = if s0 >= s {
            vec![s]
        } else {
            let g = (1.0 + slope).max(1.0 + 1.0 / m as f64);
            let k = ((s / s0).ln() / g.ln()).ceil().max(1.0) as usize;
            (0..=k)
                .map(|i| {
                    if i == k {
                        s
                    } else {
                        s0 * (s / s0).powf(i as f64 / k as f64)
                    }
                })
                .collect()
        };
        // the innermost copy's grid
        let mut grid = vec![usize::MAX; (mw + 1) * (m + 1)];
        let outer = halves.len() == 1;
        for q in 0..=m {
            for p in 0..=mw {
                let n = if outer {
                    // the window itself: its boundary is the tensor mesh's
                    let (i, j) = (i0 + p, jt - q);
                    if index[id(i, j)] != usize::MAX {
                        index[id(i, j)]
                    } else {
                        nodes.push(point(s, (p, q)));
                        nodes.len() - 1
                    }
                } else if on_side && p == mw && q == 0 {
                    // the body's top corner, in every copy
                    index[id(i0 + mw, jt)]
                } else {
                    nodes.push(point(halves[0], (p, q)));
                    nodes.len() - 1
                };
                grid[q * (mw + 1) + p] = n;
            }
        }
        for q in 0..m {
            for p in 0..mw {
                let g = |p: usize, q: usize| grid[q * (mw + 1) + p];
                cells.extend([g(p, q + 1), g(p + 1, q + 1), g(p + 1, q), g(p, q)]);
            }
        }
        // the rings, each joining a copy to the next
        let mut inner: Vec<usize> = (0..=path)
            .map(|k| {
                let (p, q) = pq(k);
                grid[q * (mw + 1) + p]
            })
            .collect();
        for (k, &sk) in halves.iter().enumerate().skip(1) {
            let ring: Vec<usize> = (0..=path)
                .map(|t| {
                    let (p, q) = pq(t);
                    if k == halves.len() - 1 {
                        index[id(i0 + p, jt - q)]
                    } else {
                        nodes.push(point(sk, (p, q)));
                        nodes.len() - 1
                    }
                })
                .collect();
            for t in 0..path {
                cells.extend([inner[t], inner[t + 1], ring[t + 1], ring[t]]);
            }
            inner = ring;
        }
        // counter-clockwise cells
        for cell in cells.chunks_exact_mut(4) {
            let x = |a: usize| nodes[cell[a]];
            let area: f64 = (0..4)
                .map(|a| {
                    let (p, q) = (x(a), x((a + 1) % 4));
                    p[0] * q[1] - q[0] * p[1]
                })
                .sum();
            if area < 0.0 {
                cell.swap(1, 3);
            }
        }
        let mut mesh = Mesh::empty(2, CellType::Quad4);
        mesh.nodes = nodes;
        mesh.cells = cells;
        // the sides' sets from the coordinates, in order along each side
        let sides: [(&str, usize, f64, usize); 4] = [
            ("axis", 0, 0.0, 1),
            ("side", 0, radius, 1),
            ("bottom", 1, 0.0, 0),
            ("top", 1, height, 0),
        ];
        for (name, axis, value, along) in sides {
            let mut pts: Vec<usize> = (0..mesh.nodes.len())
                .filter(|&n| mesh.nodes[n][axis] == value)
                .collect();
            pts.sort_by(|&a, &b| mesh.nodes[a][along].total_cmp(&mesh.nodes[b][along]));
            mesh.facet_sets.insert(
                name.into(),
                FacetSet {
                    cell_type: CellType::Line2,
                    nodes: pts.windows(2).flatten().copied().collect(),
                },
            );
            mesh.node_sets.insert(name.into(), pts);
        }
        if interfaces.is_empty() {
            mesh.regions
                .insert("body".into(), (0..mesh.cell_count()).collect());
        } else {
            let mut bands: Vec<Vec<usize>> = vec![Vec::new(); interfaces.len() + 1];
            for e in 0..mesh.cell_count() {
                let yc = mesh.cell(e).iter().map(|&n| mesh.nodes[n][1]).sum::<f64>() / 4.0;
                let depth = height - yc;
                bands[interfaces.iter().filter(|&&t| t < depth).count()].push(e);
            }
            for (i, cells) in bands.into_iter().enumerate() {
                mesh.regions.insert(format!("layer{i}"), cells);
            }
        }
        mesh.validate()?;
        Ok(mesh)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::jacobian::corner_jacobians;
    use crate::mesh::Grading;

    fn lines(length: f64, h: f64, fine: f64) -> Vec<f64> {
        Grading {
            h_fine: h,
            fine_length: fine,
            growth: 1.2,
        }
        .positions(length)
        .unwrap()
    }

    fn check(m: &Mesh, radius: f64, height: f64) {
        // every cell counter-clockwise and convex
        for c in m.cells() {
            let x: Vec<[f64; 3]> = c.iter().map(|&n| m.nodes[n]).collect();
            for j in corner_jacobians(CellType::Quad4, &x) {
                assert!(j > 0.0, "{x:?}");
            }
        }
        // the cells tile the rectangle
        let area: f64 = m
            .cells()
            .map(|c| {
                (0..4)
                    .map(|a| {
                        let (p, q) = (m.nodes[c[a]], m.nodes[c[(a + 1) % 4]]);
                        0.5 * (p[0] * q[1] - q[0] * p[1])
                    })
                    .sum::<f64>()
            })
            .sum();
        assert!((area / (radius * height) - 1.0).abs() < 1e-12, "{area}");
        // conforming: every interior edge is shared by two cells, every
        // boundary edge is on one of the four sides
        let mut edges = std::collections::HashMap::new();
        for c in m.cells() {
            for a in 0..4 {
                let (p, q) = (c[a], c[(a + 1) % 4]);
                *edges.entry((p.min(q), p.max(q))).or_insert(0) += 1;
            }
        }
        let on_boundary: std::collections::HashSet<(usize, usize)> =
            ["axis", "side", "top", "bottom"]
                .iter()
                .flat_map(|s| {
                    m.facet_set(s)
                        .unwrap()
                        .iter()
                        .map(|f| (f[0].min(f[1]), f[0].max(f[1])))
                        .collect::<Vec<_>>()
                })
                .collect();
        for (e, n) in &edges {
            assert!(
                *n == 2 || (*n == 1 && on_boundary.contains(e)),
                "edge {e:?} ({:?}, {:?}) in {n} cells",
                m.nodes[e.0],
                m.nodes[e.1]
            );
        }
        for e in &on_boundary {
            assert_eq!(
                edges.get(e),
                Some(&1),
                "boundary facet {e:?} is a cell edge"
            );
        }
    }

    /// The size of the cells along the top at radius r.
    fn top_size(m: &Mesh, r: f64) -> f64 {
        let top = m.node_set("top").unwrap();
        top.windows(2)
            .map(|w| (m.nodes[w[0]][0], m.nodes[w[1]][0]))
            .find(|(a, b)| *a <= r && r < *b)
            .map(|(a, b)| b - a)
            .unwrap()
    }

    #[test]
    fn a_window_about_a_rim_is_fine_there_only() {
        let (radius, height) = (20.0, 10.0);
        let (rs, ts) = (lines(radius, 0.1, 1.5), lines(height, 0.1, 1.5));
        let w = RimWindow {
            centre: 1.0,
            half_width: 0.5,
            spacing: 0.1,
            h: 0.0025,
            slope: 0.2,
        };
        let m = Mesh::rim_refined(&rs, &ts, height, &[], w).unwrap();
        check(&m, radius, height);
        // (the first ring a little thinner: the rings grow geometrically)
        assert!(m.min_edge() > 0.9 * 0.0025, "{}", m.min_edge());
        assert!((top_size(&m, 0.999) - 0.0025).abs() < 1e-9);
        assert!((top_size(&m, 1.001) - 0.0025).abs() < 1e-9);
        // grown away from it, the tensor mesh's size on the axis and at
        // the base
        assert!(top_size(&m, 1.2) > 0.02 && top_size(&m, 1.2) < 0.1);
        assert!((top_size(&m, 0.1) - 0.1).abs() < 1e-9);
        // far fewer cells than the tensor product refined towards the rim
        let band = Mesh::tensor(
            &crate::mesh::grading::refine_towards(&rs, 1.0, 0.0025, 0.2),
            &crate::mesh::grading::refine_towards(&ts, 0.0, 0.0025, 0.2),
        );
        let plain = Mesh::tensor(&rs, &ts);
        assert!(
            m.cell_count() < plain.cell_count() + 500,
            "{}",
            m.cell_count()
        );
        assert!(
            5 * m.cell_count() < band.cell_count(),
            "{}",
            band.cell_count()
        );
        assert_eq!(m.regions["body"].len(), m.cell_count());
        // the whole mesh made quadratic keeps its sets
        let q = m.to_quadratic().unwrap();
        assert_eq!(
            q.facet_set("top").unwrap().len(),
            m.facet_set("top").unwrap().len()
        );
    }

    #[test]
    fn a_window_at_the_side_and_above_an_interface() {
        let (radius, height) = (5.0, 3.0);
        let (rs, ts) = (lines(radius, 0.25, 1.0), lines(height, 0.25, 1.0));
        let w = RimWindow {
            centre: radius,
            half_width: 1.0,
            spacing: 0.25,
            h: 0.01,
            slope: 0.5,
        };
        let m = Mesh::rim_refined(&rs, &ts, height, &[0.8, 2.0], w).unwrap();
        check(&m, radius, height);
        assert!((top_size(&m, radius - 1e-6) - 0.01).abs() < 1e-9);
        let side = m.node_set("side").unwrap();
        let dz = m.nodes[side[side.len() - 1]][1] - m.nodes[side[side.len() - 2]][1];
        assert!((dz - 0.01).abs() < 1e-9, "{dz}");
        // the window stops at the first interface: every cell in one band
        let total: usize = m.regions.values().map(Vec::len).sum();
        assert_eq!(total, m.cell_count());
        for e in &m.regions["layer0"] {
            assert!(m
                .cell(*e)
                .iter()
                .all(|&n| m.nodes[n][1] >= height - 0.8 - 1e-12));
        }
        // bad windows are refused by field
        let e = Mesh::rim_refined(&rs, &ts, height, &[], RimWindow { centre: 6.0, ..w })
            .unwrap_err()
            .to_string();
        assert!(e.contains("centre"), "{e}");
    }
}
