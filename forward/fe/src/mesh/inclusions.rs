//! A conforming mesh of 9-node quadrilaterals of a rectangle with circular
//! inclusions (R2's silicone block with bonded nodules), block-structured,
//! without Gmsh.
//!
//! Layout (x along the block, y up, the top `y = height` is where tools
//! roll):
//!
//! * Each inclusion sits in a rectangular box `[xc - a, xc + a] x
//!   [yc - b_lo, yc + b_hi]` meshed as an O-grid: a core quadrilateral (the
//!   box scaled about the centre) with `n x n` cells, a ring of inclusion
//!   cells from the core to the circle and a ring of matrix cells from the
//!   circle to the box, each ring `4 n` cells around. The ring lines run
//!   from the box boundary point at parameter `k` to the circle point at
//!   the angle interpolated linearly between the box-corner directions on
//!   each side. Nodes are placed by the mapping at twice the resolution, so
//!   the mid-edge nodes of the cells on the circle lie on the circle (the
//!   edges are exact quadratic arcs to the accuracy of a 3-node
//!   interpolation, not chords).
//! * The box's column of the block (`x` in the box) is a tensor grid above
//!   and below the box: graded from the top (`h` over `band`, then growing
//!   by `growth`), and from the box downwards.
//! * Between boxes (and from the block ends to the first and last box) a
//!   strip with uniform columns of about `h` whose rows blend linearly
//!   (transfinite interpolation between straight sides) from the row
//!   distribution of its left neighbour to that of its right neighbour. All
//!   columns have the same number of rows (rows are added to the shorter
//!   ones by halving their largest non-box intervals), so every strip
//!   boundary is conforming.
//!
//! Nodes of neighbouring blocks are merged by position (tolerance
//! `1e-9 x extent`). Regions: `tissue` (the matrix) and `nodule` (the
//! inclusions). Node sets `bottom` (y = 0), `top` (y = height), `left`
//! (x = 0), `right` (x = width); facet set `top` (Line3, ordered by x).
//! Every cell is counter-clockwise and passes the corner-Jacobian test.

use std::collections::{BTreeMap, HashMap};

use super::jacobian::corner_jacobians;
use super::{CellType, FacetSet, Grading, Mesh};
use crate::FeError;

/// The geometry and sizes of a block with circular inclusions.
#[derive(Debug, Clone, PartialEq)]
pub struct InclusionBlock {
    /// Block size (mm).
    pub width: f64,
    pub height: f64,
    /// Inclusion centres `(x, y)` (mm, y from the bottom).
    pub centres: Vec<[f64; 2]>,
    /// Inclusion radius (mm).
    pub radius: f64,
    /// Element size along the top surface and around the inclusions (mm).
    pub h: f64,
    /// Depth of the uniformly fine band below the top surface (mm).
    pub band: f64,
    /// Growth of the row heights below the band and away from the boxes.
    pub growth: f64,
    /// Thickness of the matrix ring around each inclusion (mm), reduced
    /// where a neighbour, the surface or the bottom is closer.
    pub ring: f64,
}

/// Smallest matrix ring accepted (mm) when neighbours crowd a box.
const MIN_RING: f64 = 0.5;

/// Smallest clearance between an inclusion and the block's faces (mm).
pub const MIN_CLEARANCE: f64 = 1.0;

/// One inclusion's box and O-grid resolution.
#[derive(Debug, Clone, Copy)]
struct Box2 {
    xc: f64,
    yc: f64,
    x_lo: f64,
    x_hi: f64,
    y_lo: f64,
    y_hi: f64,
    /// Cells per box side.
    n: usize,
}

impl InclusionBlock {
    /// Checks the geometry: positive sizes, each inclusion inside the block
    /// with [`MIN_CLEARANCE`], no two overlapping, and far enough apart in
    /// x for their boxes to be separated by a strip (the mesh's limit).
    pub fn check(&self) -> Result<(), FeError> {
        let bad = |field: &str, reason: String| FeError::InvalidConfig {
            field: field.into(),
            reason,
        };
        let pos = |v: f64| v > 0.0 && v.is_finite();
        if !(pos(self.width) && pos(self.height) && pos(self.radius)) {
            return Err(bad(
                "block",
                format!(
                    "width {}, height {} and radius {} must be finite and > 0",
                    self.width, self.height, self.radius
                ),
            ));
        }
        if !(pos(self.h) && self.h <= self.height && self.band >= 0.0 && self.growth >= 1.0)
            || !self.growth.is_finite()
            || !pos(self.ring)
        {
            return Err(bad(
                "mesh",
                format!(
                    "need 0 < h ({}) <= height, band ({}) >= 0, growth ({}) >= 1, ring ({}) > 0",
                    self.h, self.band, self.growth, self.ring
                ),
            ));
        }
        let r = self.radius;
        for (i, c) in self.centres.iter().enumerate() {
            let field = format!(
                "nodule {} (x {}, depth {})",
                i + 1,
                c[0],
                self.height - c[1]
            );
            if !(c[0].is_finite() && c[1].is_finite()) {
                return Err(bad(&field, "position must be finite".into()));
            }
            let clear = [
                c[0] - r,
                self.width - c[0] - r,
                c[1] - r,
                self.height - c[1] - r,
            ];
            if clear.iter().any(|&d| d < MIN_CLEARANCE) {
                return Err(bad(
                    &field,
                    format!(
                        "a nodule of radius {r} mm must lie inside the {} x {} mm block with at least {MIN_CLEARANCE} mm to every face: x in [{}, {}], depth in [{}, {}] mm",
                        self.width,
                        self.height,
                        r + MIN_CLEARANCE,
                        self.width - r - MIN_CLEARANCE,
                        r + MIN_CLEARANCE,
                        self.height - r - MIN_CLEARANCE
                    ),
                ));
            }
            for (j, d) in self.centres.iter().enumerate().take(i) {
                let dist = ((c[0] - d[0]).powi(2) + (c[1] - d[1]).powi(2)).sqrt();
                if dist < 2.0 * r {
                    return Err(bad(
                        &field,
                        format!(
                            "overlaps nodule {} (x {}, depth {}): centres {dist:.3} mm apart, less than a diameter ({} mm)",
                            j + 1,
                            d[0],
                            self.height - d[1],
                            2.0 * r
                        ),
                    ));
                }
                let need = 2.0 * (r + MIN_RING) + self.h;
                if (c[0] - d[0]).abs() < need {
                    return Err(bad(
                        &field,
                        format!(
                            "is {:.3} mm from nodule {} in x; the mesh needs nodule centres at least {need} mm apart in x (2 x (radius + {MIN_RING} mm ring) + one element of {} mm)",
                            (c[0] - d[0]).abs(),
                            j + 1,
                            self.h
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The boxes, sorted by x.
    fn boxes(&self) -> Vec<Box2> {
        let mut cs = self.centres.clone();
        cs.sort_by(|a, b| a[0].total_cmp(&b[0]));
        let r = self.radius;
        let mut out = Vec::with_capacity(cs.len());
        for (i, c) in cs.iter().enumerate() {
            // half the free space to each neighbour, less half an element
            let mut side = self.ring;
            let left = if i == 0 { c[0] } else { c[0] - cs[i - 1][0] };
            let right = if i + 1 == cs.len() {
                self.width - c[0]
            } else {
                cs[i + 1][0] - c[0]
            };
            let room = |gap: f64, shared: bool| {
                if shared {
                    0.5 * (gap - self.h) - r
                } else {
                    gap - self.h - r
                }
            };
            side = side
                .min(room(left, i > 0))
                .min(room(right, i + 1 < cs.len()))
                .max(MIN_RING);
            let top = self.ring.min(0.5 * (self.height - c[1] - r));
            let bottom = self.ring.min(0.5 * (c[1] - r));
            let a = r + side;
            let n = ((2.0 * a / self.h).round() as usize).max(4);
            out.push(Box2 {
                xc: c[0],
                yc: c[1],
                x_lo: c[0] - a,
                x_hi: c[0] + a,
                y_lo: c[1] - r - bottom,
                y_hi: c[1] + r + top,
                n,
            });
        }
        out
    }

    /// The mesh (see the [module docs](self)).
    pub fn mesh(&self) -> Result<Mesh, FeError> {
        self.check()?;
        let boxes = self.boxes();
        let grade_top = Grading {
            h_fine: self.h,
            fine_length: self.band,
            growth: self.growth,
        };
        // Row distributions (single resolution, increasing y, 0..height)
        // of every column boundary: the default one, and per box its column
        // (above, box, below) with the box rows locked.
        let default: Vec<f64> = from_top(&grade_top, self.height, self.height)?;
        let mut columns: Vec<(Vec<f64>, (usize, usize))> = Vec::new();
        for b in &boxes {
            let hb = (b.y_hi - b.y_lo) / b.n as f64;
            let below: Vec<f64> = Grading {
                h_fine: hb,
                fine_length: 0.0,
                growth: self.growth,
            }
            .positions(b.y_lo)?
            .iter()
            .rev()
            .map(|p| b.y_lo - p)
            .collect();
            let above = from_top(&grade_top, self.height - b.y_hi, self.height)?;
            let mut ys = below;
            ys.pop();
            let first_box = ys.len();
            ys.extend((0..b.n).map(|j| b.y_lo + (b.y_hi - b.y_lo) * j as f64 / b.n as f64));
            let last_box = ys.len();
            ys.extend(above);
            ys[0] = 0.0;
            columns.push((ys, (first_box, last_box)));
        }
        let rows = columns
            .iter()
            .map(|c| c.0.len())
            .chain([default.len()])
            .max()
            .unwrap_or(2);
        let (default, _) = pad(default, (0, 0), rows);
        let columns: Vec<(Vec<f64>, usize)> = columns
            .into_iter()
            .map(|(ys, lock)| pad(ys, lock, rows))
            .collect();

        let mut b = Builder::new(self.width.max(self.height));
        // strips between boxes
        let mut x_prev = 0.0;
        let mut y_prev = double(&default);
        for (k, bx) in boxes.iter().enumerate() {
            let ycol = double(&columns[k].0);
            b.strip(x_prev, bx.x_lo, &y_prev, &ycol, self.h, "tissue");
            self.box_column(&mut b, bx, &ycol, columns[k].1 * 2, "tissue");
            x_prev = bx.x_hi;
            y_prev = ycol;
        }
        b.strip(
            x_prev,
            self.width,
            &y_prev,
            &double(&default),
            self.h,
            "tissue",
        );
        b.finish(self.width, self.height)
    }

    /// The box's column: tensor blocks above and below the box and the
    /// O-grid inside it. `ys` is the column's rows at double resolution and
    /// `j_lo` the index of the box's bottom in it.
    fn box_column(
        &self,
        b: &mut Builder,
        bx: &Box2,
        ys: &[f64],
        j_lo: usize,
        matrix: &'static str,
    ) {
        let n2 = 2 * bx.n;
        let xs: Vec<f64> = (0..=n2)
            .map(|i| bx.x_lo + (bx.x_hi - bx.x_lo) * i as f64 / n2 as f64)
            .collect();
        let j_hi = j_lo + n2;
        let tensor = |j0: usize, j1: usize| -> Vec<Vec<[f64; 2]>> {
            xs.iter()
                .map(|&x| (j0..=j1).map(|j| [x, ys[j]]).collect())
                .collect()
        };
        if j_lo > 0 {
            b.block(&tensor(0, j_lo), matrix);
        }
        if j_hi + 1 < ys.len() {
            b.block(&tensor(j_hi, ys.len() - 1), matrix);
        }
        // O-grid: the box boundary counter-clockwise from the south-west
        // corner, 4 n cells (8 n + 1 points at double resolution).
        let box_ys: Vec<f64> = ys[j_lo..=j_hi].to_vec();
        let (xc, yc, r) = (bx.xc, bx.yc, self.radius);
        let corner_angle = |x: f64, y: f64| (y - yc).atan2(x - xc);
        let mut th = [
            corner_angle(bx.x_lo, bx.y_lo),
            corner_angle(bx.x_hi, bx.y_lo),
            corner_angle(bx.x_hi, bx.y_hi),
            corner_angle(bx.x_lo, bx.y_hi),
            0.0,
        ];
        th[4] = th[0] + 2.0 * std::f64::consts::PI;
        let m = 8 * bx.n;
        let boundary = |k: usize| -> ([f64; 2], f64) {
            let side = (k / n2).min(3);
            let i = k - side * n2;
            let s = i as f64 / n2 as f64;
            let p = match side {
                0 => [xs[i], bx.y_lo],
                1 => [bx.x_hi, box_ys[i]],
                2 => [xs[n2 - i], bx.y_hi],
                _ => [bx.x_lo, box_ys[n2 - i]],
            };
            (p, th[side] + (th[side + 1] - th[side]) * s)
        };
        // core: the box scaled so that its farthest corner is at 0.55 r
        let far = [
            (bx.x_lo, bx.y_lo),
            (bx.x_hi, bx.y_lo),
            (bx.x_hi, bx.y_hi),
            (bx.x_lo, bx.y_hi),
        ]
        .iter()
        .map(|&(x, y)| ((x - xc).powi(2) + (y - yc).powi(2)).sqrt())
        .fold(0.0, f64::max);
        let lambda = 0.55 * r / far;
        let scale = |p: [f64; 2]| [xc + lambda * (p[0] - xc), yc + lambda * (p[1] - yc)];
        let core: Vec<Vec<[f64; 2]>> = xs
            .iter()
            .map(|&x| box_ys.iter().map(|&y| scale([x, y])).collect())
            .collect();
        b.block(&core, "nodule");
        // radial cells: about h across the nodule ring (from ~0.45 r to r)
        // and across the mean width of the matrix ring
        let n_in = ((0.5 * r / self.h).ceil() as usize).max(2);
        let half = 0.5 * (bx.x_hi - bx.x_lo);
        let n_out = ((0.5 * ((half - r) + (far - r)) / self.h).ceil() as usize).max(1);
        let ring = |from: &dyn Fn(usize) -> [f64; 2], to: &dyn Fn(usize) -> [f64; 2], nr: usize| {
            (0..=m)
                .map(|k| {
                    let (p, q) = (from(k % m), to(k % m));
                    (0..=2 * nr)
                        .map(|j| {
                            let t = j as f64 / (2 * nr) as f64;
                            [p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]
                        })
                        .collect()
                })
                .collect::<Vec<Vec<[f64; 2]>>>()
        };
        let circle = |k: usize| {
            let (_, a) = boundary(k);
            [xc + r * a.cos(), yc + r * a.sin()]
        };
        let core_edge = |k: usize| scale(boundary(k).0);
        let outer = |k: usize| boundary(k).0;
        b.block(&ring(&core_edge, &circle, n_in), "nodule");
        b.block(&ring(&circle, &outer, n_out), matrix);
    }
}

/// Positions from the top down over `length` (graded from the top),
/// returned as increasing y ending at `top`.
fn from_top(g: &Grading, length: f64, top: f64) -> Result<Vec<f64>, FeError> {
    let mut ys: Vec<f64> = g.positions(length)?.iter().rev().map(|p| top - p).collect();
    if let Some(last) = ys.last_mut() {
        *last = top;
    }
    Ok(ys)
}

/// `ys` with rows added (the largest interval outside the locked rows
/// `lock.0..lock.1` halved) until it has `rows` entries, and where the
/// locked rows start now.
fn pad(mut ys: Vec<f64>, lock: (usize, usize), rows: usize) -> (Vec<f64>, usize) {
    let (mut lo, mut hi) = lock;
    while ys.len() < rows {
        let mut best = None;
        let mut best_len = 0.0;
        for k in 0..ys.len() - 1 {
            if k >= lo && k < hi {
                continue;
            }
            let len = ys[k + 1] - ys[k];
            if len > best_len {
                best_len = len;
                best = Some(k);
            }
        }
        let Some(k) = best else { break };
        ys.insert(k + 1, 0.5 * (ys[k] + ys[k + 1]));
        if k < lo {
            lo += 1;
            hi += 1;
        }
    }
    (ys, lo)
}

/// Single-resolution rows to double resolution (midpoints added).
fn double(ys: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(2 * ys.len());
    for w in ys.windows(2) {
        out.push(w[0]);
        out.push(0.5 * (w[0] + w[1]));
    }
    if let Some(&l) = ys.last() {
        out.push(l);
    }
    out
}

/// Collects blocks of points into a merged 9-node mesh.
struct Builder {
    nodes: Vec<[f64; 3]>,
    index: HashMap<(i64, i64), usize>,
    tol: f64,
    cells: Vec<usize>,
    region: Vec<&'static str>,
}

impl Builder {
    fn new(extent: f64) -> Builder {
        Builder {
            nodes: Vec::new(),
            index: HashMap::new(),
            tol: 1e-9 * extent,
            cells: Vec::new(),
            region: Vec::new(),
        }
    }

    /// The node at `p`, merged with an existing one within the tolerance.
    fn node(&mut self, p: [f64; 2]) -> usize {
        let key = |v: f64| (v / (4.0 * self.tol)).round() as i64;
        let (kx, ky) = (key(p[0]), key(p[1]));
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(&n) = self.index.get(&(kx + dx, ky + dy)) {
                    let q = self.nodes[n];
                    if (q[0] - p[0]).abs() <= self.tol && (q[1] - p[1]).abs() <= self.tol {
                        return n;
                    }
                }
            }
        }
        self.nodes.push([p[0], p[1], 0.0]);
        let n = self.nodes.len() - 1;
        self.index.insert((kx, ky), n);
        n
    }

    /// A block of `(2 a + 1) x (2 b + 1)` points `pts[i][j]` (double
    /// resolution): `a x b` cells, each made counter-clockwise.
    fn block(&mut self, pts: &[Vec<[f64; 2]>], region: &'static str) {
        let na = (pts.len() - 1) / 2;
        let nb = (pts[0].len() - 1) / 2;
        for a in 0..na {
            for c in 0..nb {
                let (i, j) = (2 * a, 2 * c);
                let p = |di: usize, dj: usize| pts[i + di][j + dj];
                let area = cross(p(0, 0), p(2, 0), p(2, 2)) + cross(p(0, 0), p(2, 2), p(0, 2));
                let order: [(usize, usize); 9] = if area > 0.0 {
                    [
                        (0, 0),
                        (2, 0),
                        (2, 2),
                        (0, 2),
                        (1, 0),
                        (2, 1),
                        (1, 2),
                        (0, 1),
                        (1, 1),
                    ]
                } else {
                    [
                        (0, 0),
                        (0, 2),
                        (2, 2),
                        (2, 0),
                        (0, 1),
                        (1, 2),
                        (2, 1),
                        (1, 0),
                        (1, 1),
                    ]
                };
                for (di, dj) in order {
                    let n = self.node(p(di, dj));
                    self.cells.push(n);
                }
                self.region.push(region);
            }
        }
    }

    /// A strip `[x0, x1]` of uniform columns of about `h`, rows blending
    /// from `left` to `right` (double resolution, same length).
    fn strip(
        &mut self,
        x0: f64,
        x1: f64,
        left: &[f64],
        right: &[f64],
        h: f64,
        region: &'static str,
    ) {
        if x1 - x0 <= 1e-12 {
            return;
        }
        let n = ((x1 - x0) / h).round().max(1.0) as usize;
        let pts: Vec<Vec<[f64; 2]>> = (0..=2 * n)
            .map(|i| {
                let s = i as f64 / (2 * n) as f64;
                let x = if i == 2 * n { x1 } else { x0 + (x1 - x0) * s };
                left.iter()
                    .zip(right)
                    .map(|(&l, &r)| [x, (1.0 - s) * l + s * r])
                    .collect()
            })
            .collect();
        self.block(&pts, region);
    }

    /// The mesh with its sets, every cell checked.
    fn finish(self, width: f64, height: f64) -> Result<Mesh, FeError> {
        let mut m = Mesh::empty(2, CellType::Quad9);
        m.nodes = self.nodes;
        m.cells = self.cells;
        let tol = self.tol;
        let on = |v: f64, at: f64| (v - at).abs() <= tol;
        let mut regions: BTreeMap<String, Vec<usize>> = BTreeMap::new();
        for (e, r) in self.region.iter().enumerate() {
            regions.entry((*r).into()).or_default().push(e);
        }
        m.regions = regions;
        let set = |pred: &dyn Fn(&[f64; 3]) -> bool, key: usize| {
            let mut v: Vec<usize> = (0..m.nodes.len()).filter(|&n| pred(&m.nodes[n])).collect();
            v.sort_by(|&a, &b| m.nodes[a][key].total_cmp(&m.nodes[b][key]));
            v
        };
        let sets = [
            ("bottom", set(&|p| on(p[1], 0.0), 0)),
            ("top", set(&|p| on(p[1], height), 0)),
            ("left", set(&|p| on(p[0], 0.0), 1)),
            ("right", set(&|p| on(p[0], width), 1)),
        ];
        for (name, v) in sets {
            m.node_sets.insert(name.into(), v);
        }
        let mut top: Vec<[usize; 3]> = Vec::new();
        for c in m.cells() {
            for (a, b, mid) in [(0, 1, 4), (1, 2, 5), (2, 3, 6), (3, 0, 7)] {
                if [c[a], c[b], c[mid]]
                    .iter()
                    .all(|&n| on(m.nodes[n][1], height))
                {
                    top.push([c[a], c[b], c[mid]]);
                }
            }
        }
        top.sort_by(|f, g| m.nodes[f[2]][0].total_cmp(&m.nodes[g[2]][0]));
        m.facet_sets.insert(
            "top".into(),
            FacetSet {
                cell_type: CellType::Line3,
                nodes: top.into_iter().flatten().collect(),
            },
        );
        for (e, c) in m.cells().enumerate() {
            let x: Vec<[f64; 3]> = c.iter().map(|&n| m.nodes[n]).collect();
            let jac = corner_jacobians(CellType::Quad9, &x);
            if let Some(k) = jac.iter().position(|&j| !(j > 0.0)) {
                return Err(FeError::InvalidMesh {
                    field: format!("cell {e}"),
                    reason: format!(
                        "the nodule mesh has an inverted cell (Jacobian {:.3e} at corner {k}, near ({:.3}, {:.3}) mm): nodules too crowded for this mesh size",
                        jac[k], x[k][0], x[k][1]
                    ),
                });
            }
        }
        m.validate()?;
        Ok(m)
    }
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block(centres: Vec<[f64; 2]>, h: f64) -> InclusionBlock {
        InclusionBlock {
            width: 150.0,
            height: 30.0,
            centres,
            radius: 5.0,
            h,
            band: 3.0,
            growth: 1.25,
            ring: 2.0,
        }
    }

    fn area(m: &Mesh, region: &str) -> f64 {
        // the shoelace area of the 8 boundary nodes of each cell (exact for
        // straight edges, the chord-and-parabola error on arcs is ~h^4)
        let mut a = 0.0;
        for &e in m.region(region).unwrap() {
            let c = m.cell(e);
            let ring = [c[0], c[4], c[1], c[5], c[2], c[6], c[3], c[7]];
            for k in 0..8 {
                let (p, q) = (m.nodes[ring[k]], m.nodes[ring[(k + 1) % 8]]);
                a += 0.5 * (p[0] * q[1] - q[0] * p[1]);
            }
        }
        a
    }

    /// Three nodules: conforming (areas add up, every mid-node on the
    /// circle is on it), all cells counter-clockwise, the sets present.
    #[test]
    fn three_nodules_conform_and_fill_the_block() {
        let m = block(vec![[37.5, 20.0], [75.0, 15.0], [112.5, 10.0]], 1.0)
            .mesh()
            .unwrap();
        let (t, n) = (area(&m, "tissue"), area(&m, "nodule"));
        assert!((t + n - 4500.0).abs() < 1e-6, "{t} + {n}");
        let circles = 3.0 * std::f64::consts::PI * 25.0;
        assert!((n - circles).abs() < 2e-3 * circles, "{n} vs {circles}");
        // every node of a nodule cell lies inside or on a circle
        for &e in m.region("nodule").unwrap() {
            for &k in m.cell(e) {
                let p = m.nodes[k];
                let d = [[37.5, 20.0], [75.0, 15.0], [112.5, 10.0]]
                    .iter()
                    .map(|c| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt())
                    .fold(f64::INFINITY, f64::min);
                assert!(d <= 5.0 + 1e-9, "node {k} at {p:?}");
            }
        }
        // conformity: every interior edge is shared by exactly two cells
        let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
        for c in m.cells() {
            for (a, b) in [(0, 1), (1, 2), (2, 3), (3, 0)] {
                *edges.entry((c[a].min(c[b]), c[a].max(c[b]))).or_default() += 1;
            }
        }
        let boundary = edges.values().filter(|&&v| v == 1).count();
        assert!(edges.values().all(|&v| v <= 2));
        let top = m.facet_set("top").unwrap().len();
        let bottom = m.node_set("bottom").unwrap().len();
        let left = m.node_set("left").unwrap().len();
        let right = m.node_set("right").unwrap().len();
        // the boundary edges are exactly those of the four faces
        assert_eq!(
            boundary,
            top + (bottom - 1) / 2 + (left - 1) / 2 + (right - 1) / 2
        );
        assert!(
            (top as f64 - 150.0).abs() <= 6.0,
            "{top} top facets of ~1 mm"
        );
    }

    /// A block without nodules is a plain graded grid.
    #[test]
    fn no_nodules() {
        let m = block(vec![], 2.0).mesh().unwrap();
        assert!(!m.regions.contains_key("nodule"));
        assert!((area(&m, "tissue") - 4500.0).abs() < 1e-6);
    }

    #[test]
    fn bad_nodules_are_named() {
        let e = block(vec![[75.0, 27.0]], 1.0)
            .mesh()
            .unwrap_err()
            .to_string();
        assert!(e.contains("nodule 1") && e.contains("inside"), "{e}");
        let e = block(vec![[75.0, 15.0], [80.0, 15.0]], 1.0)
            .mesh()
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("nodule 2") && e.contains("overlaps nodule 1"),
            "{e}"
        );
        let e = block(vec![[75.0, 22.0], [80.0, 8.0]], 1.0)
            .mesh()
            .unwrap_err()
            .to_string();
        assert!(e.contains("apart in x"), "{e}");
        let e = block(vec![[2.0, 15.0]], 1.0)
            .mesh()
            .unwrap_err()
            .to_string();
        assert!(e.contains("nodule 1"), "{e}");
    }
}
