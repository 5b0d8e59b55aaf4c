//! Unit tests of `contact.rs`.

use super::*;
use crate::motion::Rotation;
use crate::surface::{Revolution3d, Wheel2d};
use crate::tool::ToolShape;

fn options(friction: f64) -> ContactOptions {
    ContactOptions {
        friction,
        penalty_normal: 20.0,
        penalty_tangent: 30.0,
        penetration_tol: 1e-6,
        points: ContactPoints::Nodes,
    }
}

/// A translated and rotated pose (3D: about a skew axis; 2D: about z).
fn pose(dim: usize) -> Pose {
    let axis = if dim == 3 {
        let a = [0.3, -0.5, 0.8];
        let l = dot(a, a).sqrt();
        a.map(|v| v / l)
    } else {
        [0.0, 0.0, 1.0]
    };
    ToolMotion {
        origin: [0.2, -0.1, 0.3],
        translation: vec![(0, [0.1, 0.2, if dim == 3 { -0.3 } else { 0.0 }])],
        rotation: Some(Rotation::About {
            channel: 0,
            axis,
            rate: 0.4,
        }),
    }
    .pose(&[0.7])
}

/// Largest difference between the point stiffness and central finite
/// differences of the point force, relative to the largest entry.
fn stiffness_error(tool: &Tool, c: &PointHistory, x: [f64; 3]) -> f64 {
    let (_, pf) = tool.point(1.3, 0.0, c, x);
    let scale = pf
        .stiffness
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let h = 1e-6;
    let mut worst = 0.0f64;
    for j in 0..tool.dim {
        let (mut xp, mut xm) = (x, x);
        xp[j] += h;
        xm[j] -= h;
        let fp = tool.point(1.3, 0.0, c, xp).1.force;
        let fm = tool.point(1.3, 0.0, c, xm).1.force;
        for i in 0..tool.dim {
            let fd = (fp[i] - fm[i]) / (2.0 * h);
            worst = worst.max((fd - pf.stiffness[i][j]).abs() / scale);
        }
    }
    worst
}

/// The 3D frictional point stiffness equals central finite differences
/// of the point force in stick (mu = 50) and in slip (mu = 0.2), for a
/// stored stick point and at first contact, on a sphere and on the
/// needle's cone (hoop curvature), under a rotated tool; and a slipped
/// point re-evaluated with its moved stick point is at the Coulomb limit
/// with the same force.
#[test]
fn frictional_point_stiffness_3d_equals_finite_differences() {
    let pose = pose(3);
    let surfaces: [(Box<dyn RigidSurface>, [f64; 3]); 2] = [
        (
            Box::new(Revolution3d(ToolShape::Sphere { radius: 1.5 })),
            [0.4, 0.3, 0.05],
        ),
        (
            Box::new(Revolution3d(ToolShape::n1_needle())),
            [2.6, 1.0, 2.6],
        ),
    ];
    for (surface, local) in &surfaces {
        // a point 0.05 mm inside the tool, and a tangent offset
        let sp = surface.project(*local);
        let xl: [f64; 3] = std::array::from_fn(|i| local[i] - (sp.gap + 0.05) * sp.normal[i]);
        let sp = surface.project(xl);
        assert!((sp.gap + 0.05).abs() < 1e-9, "{}", sp.gap);
        let x = pose.to_global_point(xl);
        let xc = sp.closest(xl);
        // a unit tangent
        let a = [0.3, -1.0, 0.5];
        let an = dot(a, sp.normal);
        let e: [f64; 3] = std::array::from_fn(|i| a[i] - an * sp.normal[i]);
        let e = e.map(|v| v / dot(e, e).sqrt());
        for (friction, slips) in [(50.0, false), (0.2, true)] {
            let o = options(friction);
            let tool = Tool {
                surface: &**surface,
                pose: &pose,
                pose_committed: &pose,
                options: &o,
                smoothing: 0.0,
                dim: 3,
            };
            let stuck = PointHistory {
                stick_point: Some(std::array::from_fn(|i| xc[i] + 0.05 * e[i])),
                ..Default::default()
            };
            let first = PointHistory {
                pos: pose.to_global_point(std::array::from_fn(|i| xl[i] - 0.04 * e[i])),
                ..Default::default()
            };
            for c in [stuck, first] {
                let (t, pf) = tool.point(1.3, 0.0, &c, x);
                assert!(t.normal_force > 0.0);
                let n = pose.to_global_vector(sp.normal);
                let fnormal = dot(pf.force, n);
                assert!((fnormal - t.normal_force).abs() < 1e-12 * fnormal);
                let tt: [f64; 3] = std::array::from_fn(|i| pf.force[i] - fnormal * n[i]);
                let ratio = dot(tt, tt).sqrt() / (friction * t.normal_force);
                assert_eq!(
                    ratio > 1.0 - 1e-12,
                    slips,
                    "{} mu {friction}: ratio {ratio}",
                    surface.name()
                );
                let err = stiffness_error(&tool, &c, x);
                assert!(
                    err < 1e-7,
                    "{} mu {friction} first {}: {err:.2e}",
                    surface.name(),
                    c.stick_point.is_none()
                );
                if slips {
                    let (t2, pf2) = tool.point(1.3, 0.0, &t, x);
                    for i in 0..3 {
                        assert!(
                            (pf2.force[i] - pf.force[i]).abs() < 1e-12,
                            "{:?} vs {:?}",
                            pf2.force,
                            pf.force
                        );
                    }
                    assert!(t2.stick_point.is_some());
                }
            }
        }
    }
}

/// The 2D frictional point stiffness (arc-length stick point) equals
/// central finite differences in stick and in slip.
#[test]
fn frictional_point_stiffness_2d_equals_finite_differences() {
    let pose = pose(2);
    let surface = Wheel2d { radius: 1.5 };
    let xl = [0.5, 0.2, 0.0];
    let sp = surface.project(xl);
    assert!(sp.gap < 0.0);
    let x = pose.to_global_point(xl);
    for (friction, stick) in [(50.0, sp.xi + 0.02), (0.2, sp.xi - 0.1)] {
        let o = options(friction);
        let tool = Tool {
            surface: &surface,
            pose: &pose,
            pose_committed: &pose,
            options: &o,
            smoothing: 0.0,
            dim: 2,
        };
        let c = PointHistory {
            stick: Some(stick),
            ..Default::default()
        };
        let (t, _) = tool.point(1.3, 0.0, &c, x);
        assert_eq!(t.stick == Some(stick), friction > 1.0);
        let err = stiffness_error(&tool, &c, x);
        assert!(err < 1e-7, "mu {friction}: {err:.2e}");
    }
}
/// The softened-onset normal law of the pure-penalty mode (lambda = 0,
/// [`RigidContact::pure_penalty`], [`RigidContact::smoothing`] = delta),
/// frictionless, on R2's wheel under a rotated pose: the point
/// stiffness equals central finite differences inside the softened band
/// (penetration s = -g in (-delta/2, delta/2): touching and just
/// separated) and beyond it, and the force is the stated law,
/// `t_N = eps_N (s + delta/2)^2 / (2 delta)` in the band, `eps_N s`
/// beyond, 0 below it. (A slope 20 % off in the band fails at 0.26.)
#[test]
fn softened_pure_penalty_stiffness_equals_finite_differences() {
    let pose = pose(2);
    let surface = Wheel2d { radius: 1.5 };
    let o = options(0.0);
    let delta = 0.2;
    let tool = Tool {
        surface: &surface,
        pose: &pose,
        pose_committed: &pose,
        options: &o,
        smoothing: delta,
        dim: 2,
    };
    let eps = o.penalty_normal * 1.3;
    let c = PointHistory::default();
    for (pen, law) in [
        (0.05, eps * (0.05f64 + 0.1).powi(2) / (2.0 * delta)),
        (0.0, eps * delta / 8.0),
        (-0.06, eps * (0.1f64 - 0.06).powi(2) / (2.0 * delta)),
        (0.3, eps * 0.3),
        (-0.15, 0.0),
    ] {
        // a point at penetration `pen` inside the rim (the circle's
        // centre is at (0, radius) in the tool frame, tip at the origin)
        let r = 1.5 - pen;
        let xl = [0.6 * r, 1.5 - 0.8 * r, 0.0];
        assert!((surface.project(xl).gap + pen).abs() < 1e-12);
        let x = pose.to_global_point(xl);
        let (_, pf) = tool.point(1.3, 0.0, &c, x);
        let tn = (pf.force[0].powi(2) + pf.force[1].powi(2)).sqrt();
        assert!(
            (tn - law).abs() <= 1e-12 * eps,
            "s {pen}: t_N {tn}, law {law}"
        );
        if law > 0.0 {
            let err = stiffness_error(&tool, &c, x);
            assert!(err < 1e-7, "s {pen}: {err:.2e}");
        }
    }
}
