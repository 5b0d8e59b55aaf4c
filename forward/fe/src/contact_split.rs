//! Contact quadrature on a straight surface edge that splits the edge where
//! the contact force stops being smooth, so that the integrated force is
//! continuously differentiable in the nodal positions.
//!
//! With fixed Gauss points, the force `t_N n` of a point is only continuous
//! where its closest point crosses from one smooth piece of the tool to the
//! next (a flat punch's face to its rounded edge: the gap is C1 there, but
//! the normal's derivative, the curvature, jumps from 0 to `1 / rho`), and
//! where the point starts to touch. A residual assembled from fixed points
//! then has kinks, and Newton stalls on them (docs/validation/fe.md, "Q1":
//! the stop near 2 mm). Integrating each smooth stretch of the edge on its
//! own removes the kinks from the integral: for
//!
//! ```text
//! F_a(x) = int_{-1}^{1} N_a(s) f(x(s)) A(s) ds,   f continuous in s,
//! ```
//!
//! the breakpoints `s*(x)` move with the nodes, but since `f` is continuous
//! across them their motion adds nothing to `dF/dx` (Leibniz's rule), and
//! the integral is as smooth as `f` is on each stretch. The quadrature on
//! each stretch is Gauss-Legendre; its points move with the breakpoints,
//! whose effect on the tangent is of the order of the quadrature error and
//! is left out.
//!
//! The breakpoints are where [`RigidSurface::piece`] changes along the edge
//! (bisection between samples) and where the gap crosses the onset of the
//! normal force (`g = delta / 2` with the softened law of width `delta`,
//! `g = 0` with the sharp law). The gap to a convex tool is convex along a
//! straight edge, so it has one minimum (golden section) and at most one
//! such crossing on each side of it.
//!
//! `assemble_split` is [`crate::contact::RigidContact`]'s assembly in
//! this mode ([`crate::ContactPoints::EdgeSplit`]).
//!
//! Written here rather than taken from a crate: it is a few bisections on
//! the tool's own projection, which no quadrature crate knows of.

use crate::contact::{PointForce, PointHistory, Tool};
use crate::contribution::{Assembly, AssemblyContext};
use crate::motion::Pose;
use crate::surface::RigidSurface;
use crate::FeError;

/// A quadrature point of a split edge: the shape-function weights of the
/// edge's two nodes, the current position and the reference area (the
/// reference length times the volume factor) it stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitPoint {
    pub weights: [f64; 2],
    pub x: [f64; 3],
    pub area: f64,
}

/// Gauss-Legendre points and weights on [-1, 1], five points.
const GAUSS5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// Samples along the edge at which the piece is read before bisection.
const SAMPLES: usize = 8;

/// A straight edge of the body's surface for [`split_edge_points`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SplitEdge {
    /// Current positions of its two nodes.
    pub xa: [f64; 3],
    pub xb: [f64; 3],
    /// Reference length, and the volume factors at its two nodes (linear
    /// along the edge).
    pub len0: f64,
    pub va: f64,
    pub vb: f64,
}

/// The quadrature points of `edge` against the tool `surface` at `pose`,
/// for a pure-penalty normal force `t_N = eps (-g)` softened over `|g| <
/// onset` (half the width of [`crate::contact::RigidContact::smoothing`];
/// 0: the sharp law). The stretches are cut where the piece changes and
/// where `g` crosses `onset` (the force starts) and `-onset` (the softened
/// law turns linear). Empty when the edge cannot touch the tool (`g_a + g_b
/// > |xb - xa| + 2 onset`: the gap is 1-Lipschitz).
pub fn split_edge_points(
    surface: &dyn RigidSurface,
    pose: &Pose,
    edge: &SplitEdge,
    onset: f64,
) -> Vec<SplitPoint> {
    let SplitEdge {
        xa,
        xb,
        len0,
        va,
        vb,
    } = *edge;
    let at = |s: f64| -> [f64; 3] {
        let (wa, wb) = (0.5 * (1.0 - s), 0.5 * (1.0 + s));
        std::array::from_fn(|i| wa * xa[i] + wb * xb[i])
    };
    let gap = |s: f64| pose.project(surface, at(s)).gap;
    let piece = |s: f64| surface.piece(pose.to_local(at(s)));
    let len = ((xb[0] - xa[0]).powi(2) + (xb[1] - xa[1]).powi(2) + (xb[2] - xa[2]).powi(2)).sqrt();
    let (ga, gb) = (gap(-1.0), gap(1.0));
    if ga + gb > len + 2.0 * onset {
        return Vec::new();
    }
    let mut cuts = vec![-1.0, 1.0];
    // where the piece changes
    let mut prev = (-1.0, piece(-1.0));
    for k in 1..=SAMPLES {
        let s = -1.0 + 2.0 * k as f64 / SAMPLES as f64;
        let p = piece(s);
        if p != prev.1 {
            let (mut lo, mut hi) = (prev.0, s);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if piece(mid) == prev.1 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            cuts.push(0.5 * (lo + hi));
        }
        prev = (s, p);
    }
    // where the gap crosses the onset: one minimum of the convex gap, and a
    // crossing on either side of it
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (-1.0, 1.0);
    for _ in 0..60 {
        let m1 = hi - phi * (hi - lo);
        let m2 = lo + phi * (hi - lo);
        if gap(m1) < gap(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let smin = 0.5 * (lo + hi);
    let gmin = gap(smin);
    if gmin >= onset {
        return Vec::new();
    }
    let root = |level: f64, mut inside: f64, mut outside: f64| -> f64 {
        for _ in 0..60 {
            let mid = 0.5 * (inside + outside);
            if gap(mid) < level {
                inside = mid;
            } else {
                outside = mid;
            }
        }
        0.5 * (inside + outside)
    };
    // the softened law is quadratic for |g| < onset and linear beyond:
    // its second derivative jumps at g = -onset as well
    let levels: &[f64] = if onset > 0.0 {
        &[onset, -onset]
    } else {
        &[0.0]
    };
    for &level in levels {
        if gmin >= level {
            continue;
        }
        if ga > level {
            cuts.push(root(level, smin, -1.0));
        }
        if gb > level {
            cuts.push(root(level, smin, 1.0));
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < 1e-13);
    let mut out = Vec::with_capacity(5 * (cuts.len() - 1));
    for w in cuts.windows(2) {
        let (s0, s1) = (w[0], w[1]);
        let (mid, half) = (0.5 * (s0 + s1), 0.5 * (s1 - s0));
        if half <= 0.0 {
            continue;
        }
        // a stretch wholly beyond the onset carries no force
        if gap(mid) >= onset && gap(s0) >= onset && gap(s1) >= onset {
            continue;
        }
        for (eta, wq) in GAUSS5 {
            let s = mid + half * eta;
            let weights = [0.5 * (1.0 - s), 0.5 * (1.0 + s)];
            let v = weights[0] * va + weights[1] * vb;
            out.push(SplitPoint {
                weights,
                x: at(s),
                area: wq * half * 0.5 * len0 * v,
            });
        }
    }
    out
}

/// The evaluated points of every edge of `facets` (with `edges`' reference
/// lengths and volume factors at the two nodes), placed for the current
/// configuration ([`crate::contact_split`]) and evaluated with a pure
/// penalty: the facet, its shape weights, trial state and force.
fn split_points(
    tool: &Tool,
    facets: &[Vec<usize>],
    edges: &[(f64, f64, f64)],
    ctx: &AssemblyContext,
) -> Vec<(usize, [f64; 2], PointHistory, PointForce)> {
    let onset = 0.5 * tool.smoothing;
    let none = PointHistory::default();
    let mut out = Vec::new();
    for (k, f) in facets.iter().enumerate() {
        let (len0, va, vb) = edges[k];
        let edge = SplitEdge {
            xa: ctx.position(f[0]),
            xb: ctx.position(f[1]),
            len0,
            va,
            vb,
        };
        for q in split_edge_points(tool.surface, tool.pose, &edge, onset) {
            let (t, pf) = tool.point(q.area, 0.0, &none, q.x);
            if pf.force != [0.0; 3] || pf.stiffness != [[0.0; 3]; 3] {
                out.push((k, q.weights, t, pf));
            }
        }
    }
    out
}

/// [`Contribution::assemble`] with [`ContactPoints::EdgeSplit`]: the
/// points' states and forces replace `state`.
pub(crate) fn assemble_split(
    tool: &Tool,
    facets: &[Vec<usize>],
    edges: &[(f64, f64, f64)],
    ctx: &AssemblyContext,
    out: &mut Assembly,
    state: (&mut Vec<PointHistory>, &mut Vec<PointForce>),
) -> Result<(), FeError> {
    let (trial, forces) = state;
    let dim = ctx.dofs.dim;
    forces.clear();
    trial.clear();
    for (k, w, t, pf) in split_points(tool, facets, edges, ctx) {
        let f = &facets[k];
        out.force_scale2 += (0..dim).map(|i| pf.force[i].powi(2)).sum::<f64>();
        for a in 0..2 {
            let na = f[a];
            for i in 0..dim {
                out.fint[na * dim + i] -= w[a] * pf.force[i];
            }
            if out.values.is_none() {
                continue;
            }
            for b in 0..2 {
                let nb = f[b];
                for i in 0..dim {
                    for j in 0..dim {
                        out.add_entry(
                            na * dim + i,
                            nb * dim + j,
                            -w[a] * w[b] * pf.stiffness[i][j],
                        );
                    }
                }
            }
        }
        trial.push(t);
        forces.push(pf);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::ToolMotion;
    use crate::surface::Profile2d;
    use crate::tool::ToolShape;

    fn punch() -> Profile2d {
        Profile2d(ToolShape::FlatPunch {
            radius: 2.0,
            edge_radius: 0.2,
        })
    }

    fn pose() -> Pose {
        ToolMotion::translating([0.0, 0.0, 0.0], vec![]).pose(&[])
    }

    fn edge(a: [f64; 2], b: [f64; 2]) -> SplitEdge {
        SplitEdge {
            xa: [a[0], a[1], 0.0],
            xb: [b[0], b[1], 0.0],
            len0: 0.2,
            va: 1.0,
            vb: 1.0,
        }
    }

    #[test]
    fn the_points_integrate_the_edge_and_cut_at_the_pieces() {
        let (s, p) = (punch(), pose());
        // an edge under the punch, 0.01 mm into the face, crossing the
        // face-rounding junction at r = 1.8
        let pts = split_edge_points(&s, &p, &edge([1.7, 0.01], [1.9, 0.01]), 0.0);
        let total: f64 = pts.iter().map(|q| q.area).sum();
        // the stretch in contact ends where the rounding lifts off the edge
        // (z = 0.01 above the face: r = 1.8 + sqrt(0.2^2 - 0.19^2))
        let r_end = 1.8 + (0.04f64 - 0.19f64.powi(2)).sqrt();
        assert!((total - (r_end - 1.7)).abs() < 1e-9, "{total}");
        // a cut at the junction: no stretch straddles r = 1.8
        let rs: Vec<f64> = pts.iter().map(|q| q.x[0]).collect();
        assert!(rs.iter().any(|&r| r < 1.8) && rs.iter().any(|&r| r > 1.8));
        for w in pts.chunks(5) {
            let (lo, hi) = (w[0].x[0], w[4].x[0]);
            assert!(hi <= 1.8 + 1e-12 || lo >= 1.8 - 1e-12, "{lo} {hi}");
        }
    }

    #[test]
    fn an_edge_clear_of_the_tool_has_no_points() {
        let pts = split_edge_points(&punch(), &pose(), &edge([2.5, 0.01], [2.7, 0.01]), 0.0);
        assert!(pts.is_empty());
    }
}

#[cfg(test)]
mod fd_tests {
    use super::*;
    use crate::motion::ToolMotion;
    use crate::surface::Profile2d;
    use crate::tool::ToolShape;

    /// Nodal forces of a pure penalty eps on an edge and their tangent
    /// (the breakpoints' motion left out).
    fn forces(x: [f64; 4], onset: f64) -> ([f64; 4], [[f64; 4]; 4]) {
        let s = Profile2d(ToolShape::FlatPunch {
            radius: 2.0,
            edge_radius: 0.2,
        });
        let p = ToolMotion::translating([0.0, 0.0, 0.0], vec![]).pose(&[]);
        let (xa, xb) = ([x[0], x[1], 0.0], [x[2], x[3], 0.0]);
        let eps = 10.0;
        let mut f = [0.0; 4];
        let mut k = [[0.0; 4]; 4];
        let edge = SplitEdge {
            xa,
            xb,
            len0: 0.2,
            va: 1.0,
            vb: 1.0,
        };
        for q in split_edge_points(&s, &p, &edge, onset) {
            let pr = p.project(&s, q.x);
            let tn = -eps * q.area * (pr.gap - onset).min(0.0);
            if tn <= 0.0 {
                continue;
            }
            for a in 0..2 {
                for i in 0..2 {
                    f[2 * a + i] += q.weights[a] * tn * pr.normal[i];
                    for b in 0..2 {
                        for j in 0..2 {
                            k[2 * a + i][2 * b + j] += q.weights[a]
                                * q.weights[b]
                                * (-eps * q.area * pr.normal[i] * pr.normal[j]
                                    + tn * pr.dnormal[i][j]);
                        }
                    }
                }
            }
        }
        (f, k)
    }

    #[test]
    fn the_tangent_of_a_split_edge_equals_finite_differences() {
        for x in [
            [1.7, 0.01, 1.9, 0.02],
            [1.85, 0.005, 1.95, 0.06],
            [1.95, 0.1, 2.0, 0.4],
        ] {
            let (_, k) = forces(x, 0.0);
            // (the sharp law: the real contact's softened one is checked on
            // Q1's assembled system, system_q1_tests.rs)
            let h = 1e-7;
            let mut worst = 0.0f64;
            let scale = k.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            for j in 0..4 {
                let (mut xp, mut xm) = (x, x);
                xp[j] += h;
                xm[j] -= h;
                let (fp, _) = forces(xp, 0.0);
                let (fm, _) = forces(xm, 0.0);
                for i in 0..4 {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    worst = worst.max((fd - k[i][j]).abs() / scale);
                }
            }
            assert!(worst < 1e-5, "{x:?}: {worst:.3e}");
        }
    }
}
