//! Unit tests of `surface.rs`.

use super::*;
use std::f64::consts::PI;

const H: f64 = 1e-7;

fn needle() -> ToolShape {
    ToolShape::n1_needle()
}
fn sphere_shape() -> ToolShape {
    ToolShape::Sphere { radius: 2.5 }
}
fn punch() -> ToolShape {
    ToolShape::FlatPunch {
        radius: 2.0,
        edge_radius: 0.2,
    }
}

/// A point at angle `phi` from straight down about `c`, at distance `rho`.
fn polar(c: [f64; 2], rho: f64, phi_deg: f64) -> [f64; 2] {
    let phi = phi_deg.to_radians();
    [c[0] + rho * phi.sin(), c[1] - rho * phi.cos()]
}

/// Profile points `(r, z)`, r >= 0, for each shape: on, below and above
/// the surface, on the cap, the cone, near the cap-cone junction
/// (75 degrees from the pole), near the punch edge, near the axis.
fn profile_points(s: ToolShape) -> Vec<[f64; 2]> {
    match s {
        ToolShape::Needle { .. } => vec![
            [0.7, -0.4],
            [0.3, -0.01],
            [1.0, 0.3],                      // inside the cap
            polar([0.0, 2.5], 2.5, 40.0),    // on the cap
            polar([0.0, 2.5], 2.6, 74.9),    // cap side of the junction
            polar([0.0, 2.5], 2.6, 75.1),    // cone side of the junction
            polar([0.0, 2.5], 2.5, 75.0001), // on the junction, cone side
            [3.5, 6.0],                      // on the cone (g ~ -0.025)
            [5.0, 10.0],                     // outside the cone
            [2.0, 5.0],                      // inside the cone
            [0.01, 4.0],                     // near the axis, in the cone
            [1e-4, -0.5],                    // near the axis, below the tip
            [1e-9, 0.1],                     // nearer, inside the tip
        ],
        ToolShape::Sphere { .. } => vec![
            [0.7, -0.4],
            [3.0, 1.0],
            [2.5, 2.5], // on the equator
            polar([0.0, 2.5], 2.5, 30.0),
            polar([0.0, 2.5], 2.5, 120.0),
            [1.0, 4.0],  // inside, upper half
            [0.5, 6.0],  // above the top, outside
            [1e-6, 0.2], // near the axis, inside
            [1e-4, -1.0],
            [4.0, -2.0],
            [0.2, 0.01],
            [1.5, 0.4],
        ],
        ToolShape::FlatPunch { .. } => vec![
            [0.5, -0.3],
            [1.7, -0.05],
            [1.0, 0.1], // inside
            [1e-5, -0.2],
            [1.8 - 1e-4, -0.1], // just inside the flat region
            [1.8 + 1e-4, -0.1], // just inside the edge region
            [1.9, 0.0],
            [2.1, 0.1],
            [1.85, -0.1],
            [2.05, 0.15],
            [1.95, 0.19], // inside the edge
            [2.3, 0.5],   // beside the side
            [1.9, 1.0],   // inside the side
        ],
        ToolShape::Platen => vec![
            [0.3, -0.2],
            [5.0, 1.0],
            [1e-6, -3.0],
            [2.0, 0.0],
            [7.0, -0.01],
            [0.5, 2.0],
            [1.0, -1.0],
            [3.0, -10.0],
            [0.02, 0.3],
            [10.0, 5.0],
            [4.0, -0.5],
            [0.1, -0.1],
        ],
    }
}

/// `(r cos a, r sin a, z)`.
fn at_angle(q: [f64; 2], a: f64) -> [f64; 3] {
    [q[0] * a.cos(), q[0] * a.sin(), q[1]]
}

fn close(fd: f64, an: f64) -> bool {
    (fd - an).abs() <= 1e-6 * (1.0 + an.abs())
}

/// Every derivative of `s` at `p` against central differences in the
/// first `s.dim()` coordinates; `same_piece(p, q)` must confirm that each
/// stencil point lies on the same smooth piece as `p`.
fn check_fd(s: &dyn RigidSurface, p: [f64; 3], same_piece: &dyn Fn([f64; 3]) -> bool) {
    let sp = s.project(p);
    let c0 = sp.closest(p);
    let dc = sp.dclosest();
    let all = |v: &[f64]| v.iter().all(|x| x.is_finite());
    assert!(all(&sp.normal) && sp.gap.is_finite(), "{s:?} {p:?}");
    let nn: f64 = sp.normal.iter().map(|v| v * v).sum();
    assert!((nn - 1.0).abs() < 1e-14, "{s:?} {p:?} |n|^2 = {nn}");
    for j in 0..s.dim() {
        let (mut a, mut b) = (p, p);
        a[j] += H;
        b[j] -= H;
        assert!(
            same_piece(a) && same_piece(b),
            "{s:?} {p:?}: stencil straddles a piece boundary"
        );
        let (pa, pb) = (s.project(a), s.project(b));
        let fd = |x: f64, y: f64| (x - y) / (2.0 * H);
        let msg = format!("{} at {p:?}, d/dp_{j}", s.name());
        assert!(close(fd(pa.gap, pb.gap), sp.normal[j]), "{msg}: gap");
        assert!(close(fd(pa.xi, pb.xi), sp.dxi[j]), "{msg}: xi");
        let (ca, cb) = (pa.closest(a), pb.closest(b));
        for i in 0..3 {
            let dn = fd(pa.normal[i], pb.normal[i]);
            assert!(
                close(dn, sp.dnormal[i][j]),
                "{msg}: n_{i} {dn} vs {}",
                sp.dnormal[i][j]
            );
            let dt = fd(pa.tangent[i], pb.tangent[i]);
            assert!(close(dt, sp.dtangent[i][j]), "{msg}: t_{i}");
            let dcl = fd(ca[i], cb[i]);
            assert!(
                close(dcl, dc[i][j]),
                "{msg}: closest_{i} {dcl} vs {}",
                dc[i][j]
            );
        }
    }
    // The Hessian of a distance function is symmetric and kills n.
    for i in 0..3 {
        let mut dn_n = 0.0;
        for j in 0..3 {
            assert!(
                (sp.dnormal[i][j] - sp.dnormal[j][i]).abs()
                    < 1e-12 * (1.0 + sp.dnormal[i][j].abs())
            );
            dn_n += sp.dnormal[i][j] * sp.normal[j];
        }
        assert!(
            dn_n.abs() < 1e-12 * (1.0 + sp.dnormal[i][i].abs()),
            "{s:?} {p:?}"
        );
    }
    // The closest point projects onto itself with zero gap.
    let back = s.project(c0);
    assert!(
        back.gap.abs() < 1e-12,
        "{s:?} {p:?}: gap at closest point {}",
        back.gap
    );
    if s.dim() == 3 {
        assert_eq!(sp.tangent, [0.0; 3]);
        assert_eq!(sp.xi, 0.0);
        assert_eq!(sp.dxi, [0.0; 3]);
    } else {
        assert_eq!(sp.normal[2], 0.0);
    }
}

fn shapes() -> [ToolShape; 4] {
    [needle(), sphere_shape(), punch(), ToolShape::Platen]
}

#[test]
fn profile2d_derivatives_match_finite_differences() {
    for shape in shapes() {
        let s = Profile2d(shape);
        let piece = |p: [f64; 3]| shape.segment([p[0], p[1]]);
        for q in profile_points(shape) {
            let p = [q[0], q[1], 0.0];
            check_fd(&s, p, &|x| piece(x) == piece(p));
        }
    }
}

#[test]
fn revolution3d_derivatives_match_finite_differences() {
    for shape in shapes() {
        let s = Revolution3d(shape);
        let piece = |p: [f64; 3]| shape.segment([p[0].hypot(p[1]), p[2]]);
        for q in profile_points(shape) {
            // Off the x-z plane, in the x-z plane, and on the far side.
            for a in [0.7, 0.0, 2.9, -1.3] {
                let p = at_angle(q, a);
                check_fd(&s, p, &|x| piece(x) == piece(p));
            }
        }
        // On the axis: below the tip (and, for the needle, inside the cap).
        for z in [-0.5, -1e-3, 0.2] {
            let p = [0.0, 0.0, z];
            let sp = s.project(p);
            assert_eq!(sp.normal, [0.0, 0.0, -1.0], "{shape:?} {z}");
            assert!((sp.gap + z).abs() < 1e-15);
            check_fd(&s, p, &|x| piece(x) == piece(p));
        }
    }
}

/// The rigid base: gap is the height above it, the normal points up into
/// the body, `xi = -x` along the tangent `(-1, 0)`.
#[test]
fn floor_derivatives_match_finite_differences() {
    for q in [[0.0, 0.3], [2.0, -0.1], [-1.0, 4.0]] {
        let p = [q[0], q[1], 0.0];
        check_fd(&Floor2d, p, &|_| true);
        let sp = Floor2d.project(p);
        assert_eq!(sp.gap, q[1]);
        assert_eq!(sp.normal, [0.0, 1.0, 0.0]);
        assert_eq!(sp.xi, -q[0]);
    }
}

#[test]
fn wheels_derivatives_match_finite_differences() {
    let w = Wheel2d { radius: 2.5 };
    let c = [0.0, 2.5];
    let pts2 = [
        [0.0, -0.5],
        [-0.7, -0.4],
        [0.7, -0.4],
        [-3.0, 1.0],
        [3.0, 1.0],
        polar(c, 2.5, -40.0),
        polar(c, 2.5, 40.0),
        polar(c, 2.0, -100.0), // inside
        polar(c, 3.0, -170.0), // near the top, left
        polar(c, 3.0, 170.0),  // near the top, right
        [-1e-6, 0.1],
        [-2.5, 2.5],
        [-4.0, -2.0],
    ];
    for q in pts2 {
        check_fd(&w, [q[0], q[1], 0.0], &|_| true);
    }
    // xi: arc length from the bottom point, counter-clockwise.
    for phi in [-150.0, -60.0, -10.0, 0.0, 25.0, 90.0, 170.0] {
        let sp = w.project([polar(c, 2.9, phi)[0], polar(c, 2.9, phi)[1], 0.0]);
        assert!((sp.xi - 2.5 * f64::to_radians(phi)).abs() < 1e-13, "{phi}");
        assert!((sp.gap - 0.4).abs() < 1e-14);
    }

    let cyl = Cylinder3d { radius: 2.5 };
    for q in pts2 {
        for y in [0.0, 1.3, -40.0] {
            check_fd(&cyl, [q[0], y, q[1]], &|_| true);
            // Every section y = const is the 2D wheel.
            let (a, b) = (cyl.project([q[0], y, q[1]]), w.project([q[0], q[1], 0.0]));
            assert!((a.gap - b.gap).abs() < 1e-14);
            assert!((a.normal[0] - b.normal[0]).abs() < 1e-15);
            assert_eq!(a.normal[1], 0.0);
            assert!((a.normal[2] - b.normal[1]).abs() < 1e-15);
        }
    }
    // On its axis: finite, normal down.
    let sp = cyl.project([0.0, 3.0, 2.5]);
    assert_eq!(sp.normal, [0.0, 0.0, -1.0]);
    assert!(sp.dnormal.iter().flatten().all(|v| v.is_finite()));
}

/// `ToolShape::project` as it was before it was split into
/// `segment` + `Segment::project`, kept to prove the numbers unchanged.
fn legacy_project(s: ToolShape, p: [f64; 2]) -> Projection {
    use crate::tool::Segment as S;
    let arc = |c, radius, xi0| {
        S::Arc {
            centre: c,
            radius,
            xi0,
        }
        .project(p)
    };
    let line = |a, n, xi0| {
        S::Line {
            point: a,
            normal: n,
            xi0,
        }
        .project(p)
    };
    match s {
        ToolShape::Sphere { radius } => arc([0.0, radius], radius, 0.0),
        ToolShape::Needle {
            tip_radius: rt,
            half_angle_deg,
        } => {
            let alpha = half_angle_deg.to_radians();
            let phi_t = std::f64::consts::FRAC_PI_2 - alpha;
            let phi = p[0].atan2(-(p[1] - rt));
            if phi <= phi_t {
                arc([0.0, rt], rt, 0.0)
            } else {
                let tp = [rt * phi_t.sin(), rt - rt * phi_t.cos()];
                line(tp, [alpha.cos(), -alpha.sin()], rt * phi_t)
            }
        }
        ToolShape::Platen => line([0.0, 0.0], [0.0, -1.0], 0.0),
        ToolShape::FlatPunch {
            radius,
            edge_radius,
        } => {
            let c = [radius - edge_radius, edge_radius];
            if p[0] <= c[0] {
                line([0.0, 0.0], [0.0, -1.0], 0.0)
            } else if p[1] <= c[1] {
                arc(c, edge_radius, c[0])
            } else {
                line(
                    [radius, edge_radius],
                    [1.0, 0.0],
                    c[0] + edge_radius * std::f64::consts::FRAC_PI_2 - edge_radius,
                )
            }
        }
    }
}

fn bits(pr: &Projection) -> Vec<u64> {
    let mut v = vec![pr.gap.to_bits(), pr.xi.to_bits()];
    for a in [pr.normal, pr.tangent, pr.dxi] {
        v.extend(a.map(f64::to_bits));
    }
    for m in [pr.dnormal, pr.dtangent] {
        v.extend(m.iter().flatten().map(|x| x.to_bits()));
    }
    v
}

#[test]
fn profile2d_is_toolshape_project_bit_for_bit() {
    for shape in shapes() {
        let s = Profile2d(shape);
        for i in 0..41 {
            for k in 0..41 {
                let q = [-0.5 + 0.15 * i as f64, -1.0 + 0.2 * k as f64];
                let pr = shape.project(q);
                assert_eq!(
                    bits(&pr),
                    bits(&legacy_project(shape, q)),
                    "{shape:?} {q:?}"
                );
                let sp = s.project([q[0], q[1], 123.0]);
                let back = Projection {
                    gap: sp.gap,
                    normal: [sp.normal[0], sp.normal[1]],
                    tangent: [sp.tangent[0], sp.tangent[1]],
                    xi: sp.xi,
                    dnormal: [
                        [sp.dnormal[0][0], sp.dnormal[0][1]],
                        [sp.dnormal[1][0], sp.dnormal[1][1]],
                    ],
                    dtangent: [
                        [sp.dtangent[0][0], sp.dtangent[0][1]],
                        [sp.dtangent[1][0], sp.dtangent[1][1]],
                    ],
                    dxi: [sp.dxi[0], sp.dxi[1]],
                };
                assert_eq!(bits(&back), bits(&pr));
                assert_eq!(sp.normal[2], 0.0);
                assert_eq!(sp.dxi[2], 0.0);
                assert!(sp.dnormal[2]
                    .iter()
                    .chain(sp.dtangent[2].iter())
                    .all(|&v| v == 0.0));
            }
        }
    }
    // The 2D wheel is the sphere's profile, for either sign of x.
    let w = Wheel2d { radius: 2.5 };
    for q in [[-1.0, -0.3], [-3.0, 4.0], [2.0, 0.5]] {
        let a = w.project([q[0], q[1], 0.0]);
        let b = Profile2d(sphere_shape()).project([q[0], q[1], 0.0]);
        assert_eq!(a, b);
    }
}

#[test]
fn revolution3d_matches_profile_and_is_axisymmetric() {
    for shape in shapes() {
        let s = Revolution3d(shape);
        for q in profile_points(shape) {
            if q[0] <= 0.0 {
                continue;
            }
            let pr = shape.project(q);
            let sp = s.project([q[0], 0.0, q[1]]);
            let msg = format!("{shape:?} {q:?}");
            assert!(
                (sp.gap - pr.gap).abs() < 1e-14 * (1.0 + pr.gap.abs()),
                "{msg}"
            );
            assert!((sp.normal[0] - pr.normal[0]).abs() < 1e-15, "{msg}");
            assert_eq!(sp.normal[1], 0.0, "{msg}");
            assert!((sp.normal[2] - pr.normal[1]).abs() < 1e-15, "{msg}");
            // The meridional block is the profile's; the hoop entry is n_r / r.
            for (i3, i2) in [(0, 0), (2, 1)] {
                for (j3, j2) in [(0, 0), (2, 1)] {
                    let (a, b) = (sp.dnormal[i3][j3], pr.dnormal[i2][j2]);
                    assert!((a - b).abs() < 1e-12 * (1.0 + b.abs()), "{msg}");
                }
            }
            let hoop = pr.normal[0] / q[0];
            assert!(
                (sp.dnormal[1][1] - hoop).abs() < 1e-12 * (1.0 + hoop.abs()),
                "{msg}"
            );

            let base = s.project(at_angle(q, 0.0));
            for a in [0.3, PI / 2.0, 2.0, PI, -0.8] {
                let rot = |v: [f64; 3]| {
                    [
                        a.cos() * v[0] - a.sin() * v[1],
                        a.sin() * v[0] + a.cos() * v[1],
                        v[2],
                    ]
                };
                let sp = s.project(at_angle(q, a));
                assert!(
                    (sp.gap - base.gap).abs() < 1e-14 * (1.0 + base.gap.abs()),
                    "{msg} {a}"
                );
                let rn = rot(base.normal);
                for i in 0..3 {
                    assert!((sp.normal[i] - rn[i]).abs() < 1e-14, "{msg} {a}");
                }
                // dn(R p) = R dn(p) R^T.
                let cols: [[f64; 3]; 3] =
                    std::array::from_fn(|j| rot(std::array::from_fn(|i| base.dnormal[i][j])));
                for i in 0..3 {
                    let row = rot(std::array::from_fn(|j| cols[j][i]));
                    for j in 0..3 {
                        let scale = 1.0
                            + base
                                .dnormal
                                .iter()
                                .flatten()
                                .fold(0.0f64, |m, v| m.max(v.abs()));
                        assert!(
                            (sp.dnormal[i][j] - row[j]).abs() < 1e-13 * scale,
                            "{msg} {a}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn axis_is_finite_and_points_down() {
    for shape in shapes() {
        let s = Revolution3d(shape);
        for z in [-2.0, -1e-9, 0.0, 0.5, 2.5, 3.0, 10.0] {
            for r in [0.0, 1e-300, 1e-200, 1e-12, 1e-6] {
                let sp = s.project([r, 0.0, z]);
                let vals = std::iter::once(sp.gap)
                    .chain(sp.normal)
                    .chain(sp.dnormal.into_iter().flatten());
                for v in vals {
                    assert!(v.is_finite(), "{shape:?} r {r} z {z}: {sp:?}");
                }
                if z < 0.1 {
                    // Below (or just inside) the tip the normal tends to -e_z.
                    assert!(sp.normal[2] < -0.999_999, "{shape:?} r {r} z {z}");
                    assert!(sp.normal[0].abs() <= 1e-6, "{shape:?} r {r} z {z}");
                    if z <= 0.0 {
                        assert!((sp.gap + z).abs() < 1e-12, "{shape:?} r {r} z {z}");
                    }
                }
            }
        }
    }
    // The sphere's hoop curvature on the axis is its meridional one.
    let sp = Revolution3d(sphere_shape()).project([0.0, 0.0, -1.5]);
    assert!((sp.dnormal[0][0] - 0.25).abs() < 1e-15 && (sp.dnormal[1][1] - 0.25).abs() < 1e-15);
}

#[test]
fn platen_3d_is_the_plane_z_0() {
    let s = Revolution3d(ToolShape::Platen);
    for p in [
        [0.0, 0.0, -1.0],
        [3.0, -4.0, 0.5],
        [-1e-9, 2.0, -7.0],
        [1e6, 1e6, 0.0],
    ] {
        let sp = s.project(p);
        assert_eq!(sp.gap, -p[2]);
        assert_eq!(sp.normal, [0.0, 0.0, -1.0]);
        assert_eq!(sp.dnormal, [[0.0; 3]; 3]);
        assert_eq!(sp.closest(p), [p[0], p[1], 0.0]);
    }
}

#[test]
fn gaps_are_negative_inside() {
    let inside: Vec<(Box<dyn RigidSurface>, [f64; 3])> = vec![
        (Box::new(Profile2d(needle())), [0.5, 0.5, 0.0]),
        (Box::new(Profile2d(needle())), [1.0, 5.0, 0.0]),
        (Box::new(Profile2d(sphere_shape())), [1.0, 2.0, 0.0]),
        (Box::new(Profile2d(punch())), [1.0, 0.1, 0.0]),
        (Box::new(Profile2d(punch())), [1.95, 0.19, 0.0]),
        (Box::new(Profile2d(punch())), [1.9, 1.0, 0.0]),
        (Box::new(Profile2d(ToolShape::Platen)), [3.0, 0.01, 0.0]),
        (Box::new(Wheel2d { radius: 2.5 }), [-1.0, 2.0, 0.0]),
        (Box::new(Revolution3d(needle())), [0.3, -0.4, 0.5]),
        (Box::new(Revolution3d(needle())), [-0.7, 0.7, 5.0]),
        (Box::new(Revolution3d(needle())), [0.0, 0.0, 4.0]),
        (Box::new(Revolution3d(sphere_shape())), [-1.0, 1.0, 2.0]),
        (Box::new(Revolution3d(punch())), [0.0, -1.0, 0.1]),
        (Box::new(Revolution3d(punch())), [1.3, -1.3, 1.0]),
        (Box::new(Revolution3d(ToolShape::Platen)), [5.0, -7.0, 0.2]),
        (Box::new(Cylinder3d { radius: 2.5 }), [-1.0, 30.0, 2.0]),
    ];
    for (s, p) in &inside {
        assert!(s.project(*p).gap < 0.0, "{} {p:?}", s.name());
        assert!(s.check().is_ok());
    }
    for (s, p) in &inside {
        // Mirror the point below the tool's lowest point: outside.
        let q = [
            p[0],
            if s.dim() == 2 { -1.0 } else { p[1] },
            if s.dim() == 2 { 0.0 } else { -1.0 },
        ];
        assert!(s.project(q).gap > 0.0, "{} {q:?}", s.name());
    }
}

#[test]
fn check_rejects_bad_dimensions() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let s: [Box<dyn RigidSurface>; 8] = [
            Box::new(Wheel2d { radius: bad }),
            Box::new(Cylinder3d { radius: bad }),
            Box::new(Profile2d(ToolShape::Sphere { radius: bad })),
            Box::new(Revolution3d(ToolShape::Sphere { radius: bad })),
            Box::new(Revolution3d(ToolShape::Needle {
                tip_radius: bad,
                half_angle_deg: 15.0,
            })),
            Box::new(Profile2d(ToolShape::Needle {
                tip_radius: 2.5,
                half_angle_deg: if bad.is_nan() { bad } else { 90.0 - bad },
            })),
            Box::new(Revolution3d(ToolShape::FlatPunch {
                radius: bad,
                edge_radius: 0.1,
            })),
            Box::new(Profile2d(ToolShape::FlatPunch {
                radius: 2.0,
                edge_radius: bad,
            })),
        ];
        for s in &s {
            assert!(s.check().is_err(), "{s:?}");
        }
    }
    // Edge radius as large as the punch.
    let p = Revolution3d(ToolShape::FlatPunch {
        radius: 2.0,
        edge_radius: 2.0,
    });
    assert!(p.check().is_err());
    for s in [
        &Revolution3d(needle()) as &dyn RigidSurface,
        &Wheel2d { radius: 1.0 },
        &Cylinder3d { radius: 1.0 },
    ] {
        assert!(s.check().is_ok());
        assert!(!s.name().is_empty());
    }
}
