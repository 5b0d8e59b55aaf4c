//! Self-contact of a 2D (plane or axisymmetric) boundary: frictionless
//! node-to-segment penalty between the nodes and the segments of one facet
//! set, so that a surface that creases (folds onto itself) cannot pass
//! through itself.
//!
//! For a node `s` and a segment `(a, b)` of the same boundary, oriented so
//! that its outward normal is `n = (-t_y, t_x)`, `t = (b - a) / L`,
//! `L = |b - a|`, the normal gap and the closest-point coordinate are
//! (Wriggers, *Computational Contact Mechanics*, 2nd ed., 2006, 4.1 and
//! 9.1.1; node-to-segment, 2D)
//!
//! ```text
//! g  = cross(b - a, s - a) / L,    xi = (s - a) . (b - a) / L^2,
//! W  = eps A g^2 / 2   for g < 0, 0 <= xi <= 1 and -g < depth,
//! ```
//!
//! `A` the node's reference tributary length times the volume factor
//! (`2 pi r` in axisymmetry), `eps` the penalty per unit area. The residual
//! is `dW/dx = eps A g dg/dx` and the tangent the exact Hessian
//! `eps A (dg/dx (x) dg/dx + g d2g/dx2)` of `W` in the six coordinates
//! `(s, a, b)`, with `c = cross(e, d)`, `e = b - a`, `d = s - a`:
//!
//! ```text
//! dg   = dc / L - c dL / L^2
//! d2g  = d2c / L - (dc (x) dL + dL (x) dc) / L^2 - c d2L / L^2 + 2 c dL (x) dL / L^3
//! d2c  = Q^T J D + D^T J^T Q,   d2L = Q^T (I / L - e (x) e / L^3) Q
//! ```
//!
//! with `Q = de/dx = [-I, I, 0]`, `D = dd/dx = [-I, 0, I]` and
//! `J = [[0, 1], [-1, 0]]` (`c = e^T J d`). `xi` is held in `[0, 1]` by the
//! pair test, not differentiated: the force acts along the segment's normal
//! (frictionless), shared by `a` and `b` through the tangent of `g` alone.
//!
//! Pairs are limited to nodes and segments whose reference positions lie
//! within `reach` of each other (and a segment never pairs with its own
//! nodes): a crease brings together parts of the surface that were close
//! before it formed, and the sparsity pattern, fixed when the system is
//! built, holds one 6 x 6 block per pair. `depth` (a fraction of the
//! element size) keeps a node from "contacting" a segment on the far side
//! of a thin part of the body.

use crate::contribution::{Assembly, AssemblyContext, Contribution};
use crate::kinematics::Kinematics;
use crate::mesh::{CellType, Mesh};
use crate::FeError;

/// One candidate pair: node `s` against the oriented segment `(a, b)`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pair {
    s: usize,
    a: usize,
    b: usize,
    /// Reference tributary area of `s`.
    area: f64,
}

/// The gap of node `s` against the oriented segment `(a, b)` with its
/// gradient and Hessian in `(s_x, s_y, a_x, a_y, b_x, b_y)`, and the
/// closest-point coordinate `xi`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentGap {
    pub gap: f64,
    pub xi: f64,
    pub grad: [f64; 6],
    pub hess: [[f64; 6]; 6],
}

/// [`SegmentGap`] of `s` against `(a, b)`; `None` for a degenerate segment.
pub fn segment_gap(s: [f64; 2], a: [f64; 2], b: [f64; 2]) -> Option<SegmentGap> {
    let e = [b[0] - a[0], b[1] - a[1]];
    let d = [s[0] - a[0], s[1] - a[1]];
    let l2 = e[0] * e[0] + e[1] * e[1];
    if !(l2 > 0.0) {
        return None;
    }
    let l = l2.sqrt();
    let c = e[0] * d[1] - e[1] * d[0];
    let xi = (d[0] * e[0] + d[1] * e[1]) / l2;
    // Q = de/dx, D = dd/dx as 2 x 6
    let q = [
        [0.0, 0.0, -1.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, -1.0, 0.0, 1.0],
    ];
    let dm = [
        [1.0, 0.0, -1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, -1.0, 0.0, 0.0],
    ];
    // dc/de = J d = (d_y, -d_x), dc/dd = J^T e = (-e_y, e_x)
    let dc_de = [d[1], -d[0]];
    let dc_dd = [-e[1], e[0]];
    let dl_de = [e[0] / l, e[1] / l];
    let row = |v: [f64; 2], m: [[f64; 6]; 2]| -> [f64; 6] {
        std::array::from_fn(|j| v[0] * m[0][j] + v[1] * m[1][j])
    };
    let dc: [f64; 6] = {
        let x = row(dc_de, q);
        let y = row(dc_dd, dm);
        std::array::from_fn(|j| x[j] + y[j])
    };
    let dl = row(dl_de, q);
    let jm = [[0.0, 1.0], [-1.0, 0.0]];
    // second derivatives: d2c = Q^T J D + D^T J^T Q, d2L = Q^T P Q
    let p = [
        [1.0 / l - e[0] * e[0] / (l2 * l), -e[0] * e[1] / (l2 * l)],
        [-e[0] * e[1] / (l2 * l), 1.0 / l - e[1] * e[1] / (l2 * l)],
    ];
    let quad = |a: [[f64; 6]; 2], m: [[f64; 2]; 2], b: [[f64; 6]; 2], i: usize, j: usize| {
        let mut v = 0.0;
        for k in 0..2 {
            for r in 0..2 {
                v += a[k][i] * m[k][r] * b[r][j];
            }
        }
        v
    };
    let gap = c / l;
    let grad: [f64; 6] = std::array::from_fn(|i| dc[i] / l - c * dl[i] / l2);
    let hess = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let d2c = quad(q, jm, dm, i, j) + quad(q, jm, dm, j, i);
            let d2l = quad(q, p, q, i, j);
            d2c / l - (dc[i] * dl[j] + dl[i] * dc[j]) / l2 - c * d2l / l2
                + 2.0 * c * dl[i] * dl[j] / (l2 * l)
        })
    });
    Some(SegmentGap {
        gap,
        xi,
        grad,
        hess,
    })
}

/// Frictionless self-contact of a 2D boundary (node-to-segment penalty).
pub struct SelfContact {
    name: String,
    pairs: Vec<Pair>,
    /// Penalty per unit area (MPa/mm), set per run.
    pub penalty: f64,
    /// A node counts as penetrating only while `-g < depth` (mm).
    pub depth: f64,
    /// Pairs in contact and the largest penetration at the last assembly.
    active: usize,
    max_penetration: f64,
}

impl SelfContact {
    /// Self-contact of the nodes and segments of the Line2 facet set
    /// `facets` of a 2D mesh whose reference positions satisfy `zone`
    /// (both ends of a segment), pairing a node with the segments whose
    /// nodes lie within `reach` (mm, reference) of it. Segments are oriented
    /// outward from the cell they bound. Errors: an unknown set, a set that
    /// is not made of Line2 facets, a facet that bounds no cell.
    pub fn new(
        name: &str,
        mesh: &Mesh,
        facets: &str,
        kinematics: Kinematics,
        zone: impl Fn([f64; 3]) -> bool,
        reach: f64,
    ) -> Result<SelfContact, FeError> {
        let bad = |reason: String| FeError::InvalidConfig {
            field: format!("self-contact `{name}`"),
            reason,
        };
        if mesh.dim != 2 || kinematics.dim() != 2 {
            return Err(bad("self-contact is 2D (plane or axisymmetric)".into()));
        }
        let set = mesh.facet_set(facets)?;
        if set.cell_type != CellType::Line2 {
            return Err(bad(format!(
                "facet set `{facets}` has {:?} facets; self-contact takes Line2",
                set.cell_type
            )));
        }
        if !(reach > 0.0 && reach.is_finite()) {
            return Err(bad(format!("reach {reach} mm must be > 0")));
        }
        let x = |n: usize| mesh.nodes[n];
        // the facets in the zone, oriented outward: the cell holding both
        // nodes lies on the side of -n
        let mut segments = Vec::new();
        for f in set.iter() {
            let (a, b) = (f[0], f[1]);
            if !(zone(x(a)) && zone(x(b))) {
                continue;
            }
            let cell = mesh
                .cells()
                .find(|c| c.contains(&a) && c.contains(&b))
                .ok_or_else(|| bad(format!("facet ({a}, {b}) bounds no cell")))?;
            let k = cell.len() as f64;
            let centre: [f64; 2] =
                std::array::from_fn(|i| cell.iter().map(|&n| mesh.nodes[n][i]).sum::<f64>() / k);
            let (pa, pb) = (x(a), x(b));
            let inside =
                (pb[0] - pa[0]) * (centre[1] - pa[1]) - (pb[1] - pa[1]) * (centre[0] - pa[0]);
            segments.push(if inside < 0.0 { [a, b] } else { [b, a] });
        }
        // tributary areas of the nodes of the zone's segments
        let mut area = std::collections::BTreeMap::<usize, f64>::new();
        for &[a, b] in &segments {
            let (pa, pb) = (x(a), x(b));
            let len = ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2)).sqrt();
            let (fa, fb) = (
                kinematics.volume_factor(pa[0]),
                kinematics.volume_factor(pb[0]),
            );
            *area.entry(a).or_default() += len * (2.0 * fa + fb) / 6.0;
            *area.entry(b).or_default() += len * (fa + 2.0 * fb) / 6.0;
        }
        let dist =
            |p: [f64; 3], q: [f64; 3]| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
        let mut pairs = Vec::new();
        for (&s, &area) in &area {
            for &[a, b] in &segments {
                if s == a || s == b {
                    continue;
                }
                if dist(x(s), x(a)) <= reach && dist(x(s), x(b)) <= reach {
                    pairs.push(Pair { s, a, b, area });
                }
            }
        }
        Ok(SelfContact {
            name: name.into(),
            pairs,
            penalty: 0.0,
            depth: f64::INFINITY,
            active: 0,
            max_penetration: 0.0,
        })
    }

    /// Number of candidate pairs.
    pub fn pairs(&self) -> usize {
        self.pairs.len()
    }

    /// Pairs in contact at the last assembly.
    pub fn active(&self) -> usize {
        self.active
    }

    /// Largest penetration (mm) at the last assembly.
    pub fn max_penetration(&self) -> f64 {
        self.max_penetration
    }
}

impl Contribution for SelfContact {
    fn name(&self) -> String {
        format!("self-contact `{}`", self.name)
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
    fn couplings(&self, dim: usize) -> Vec<Vec<usize>> {
        self.pairs
            .iter()
            .map(|p| {
                [p.s, p.a, p.b]
                    .iter()
                    .flat_map(|&n| (0..dim).map(move |c| n * dim + c))
                    .collect()
            })
            .collect()
    }
    fn assemble(&mut self, ctx: &AssemblyContext, out: &mut Assembly) -> Result<(), FeError> {
        let dim = ctx.dofs.dim;
        self.active = 0;
        self.max_penetration = 0.0;
        if self.penalty <= 0.0 {
            return Ok(());
        }
        let p2 = |n: usize| {
            let x = ctx.position(n);
            [x[0], x[1]]
        };
        let mut k = [0.0; 36];
        for (group, p) in self.pairs.iter().enumerate() {
            let Some(sg) = segment_gap(p2(p.s), p2(p.a), p2(p.b)) else {
                continue;
            };
            if !(sg.gap < 0.0 && -sg.gap < self.depth && (0.0..=1.0).contains(&sg.xi)) {
                continue;
            }
            self.active += 1;
            self.max_penetration = self.max_penetration.max(-sg.gap);
            let ka = self.penalty * p.area;
            let nodes = [p.s, p.a, p.b];
            let mut f2 = 0.0;
            for (i, &n) in nodes.iter().enumerate() {
                for c in 0..2 {
                    let f = ka * sg.gap * sg.grad[2 * i + c];
                    out.fint[n * dim + c] += f;
                    f2 += f * f;
                }
            }
            out.force_scale2 += f2;
            if out.values.is_some() {
                for i in 0..6 {
                    for j in 0..6 {
                        k[6 * i + j] = ka * (sg.grad[i] * sg.grad[j] + sg.gap * sg.hess[i][j]);
                    }
                }
                out.add_group(group, &k);
            }
        }
        Ok(())
    }
    fn commit(&mut self, _ctx: &AssemblyContext) {}
    fn rollback(&mut self) {}
    fn reset(&mut self, _x0: &[[f64; 3]]) {
        self.active = 0;
        self.max_penetration = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gap's gradient and Hessian equal central finite differences of
    /// the gap and of the gradient, for a node on either side of a tilted
    /// segment; the gap is the signed distance to the segment's line.
    #[test]
    fn gap_derivatives_equal_finite_differences() {
        let a = [0.3, -0.2];
        let b = [1.4, 0.5];
        for s in [[0.9, -0.4], [0.6, 0.7], [1.2, 0.2]] {
            let sg = segment_gap(s, a, b).unwrap();
            let l = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            let n = [-(b[1] - a[1]) / l, (b[0] - a[0]) / l];
            let dist = (s[0] - a[0]) * n[0] + (s[1] - a[1]) * n[1];
            assert!((sg.gap - dist).abs() < 1e-14);
            let x0 = [s[0], s[1], a[0], a[1], b[0], b[1]];
            let at = |x: [f64; 6]| segment_gap([x[0], x[1]], [x[2], x[3]], [x[4], x[5]]).unwrap();
            let h = 1e-6;
            for j in 0..6 {
                let (mut xp, mut xm) = (x0, x0);
                xp[j] += h;
                xm[j] -= h;
                let (gp, gm) = (at(xp), at(xm));
                let fd = (gp.gap - gm.gap) / (2.0 * h);
                assert!(
                    (fd - sg.grad[j]).abs() < 1e-8,
                    "grad {j}: {fd} {}",
                    sg.grad[j]
                );
                for i in 0..6 {
                    let fd = (gp.grad[i] - gm.grad[i]) / (2.0 * h);
                    assert!(
                        (fd - sg.hess[i][j]).abs() < 1e-7,
                        "hess {i} {j}: {fd} {}",
                        sg.hess[i][j]
                    );
                }
            }
        }
    }
}
