//! Rigid tools as analytic surfaces of revolution: signed distance, closest
//! point (as an arc-length coordinate `xi` along the profile), normal, and
//! their derivatives with respect to the query point.
//!
//! Coordinates are tool-local (r, z) with the origin at the tool's lowest
//! point on the axis; the body lies below (`z < 0`). The outward normal `n`
//! points from the tool into the body; the tangent `t = (-n_z, n_r)` points
//! along increasing `xi`.

use serde::{Deserialize, Serialize};

/// The shape of a rigid tool.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolShape {
    /// Hemispherical tip of radius `tip_radius` tangent to a cone of
    /// half-angle `half_angle_deg` (docs/benchmarks.md N1: 2.5 mm, 15 degrees; the
    /// cap ends `90 - half_angle` degrees from the pole).
    Needle {
        tip_radius: f64,
        half_angle_deg: f64,
    },
    /// A sphere of the given radius (Hertz).
    Sphere { radius: f64 },
    /// A flat-ended cylindrical punch whose edge is rounded with `edge_radius`
    /// (docs/benchmarks.md Q1: radius 2 mm).
    FlatPunch { radius: f64, edge_radius: f64 },
    /// An infinite flat platen.
    Platen,
}

/// The closest-point projection of a point onto a tool surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Signed distance (mm), negative inside the tool.
    pub gap: f64,
    pub normal: [f64; 2],
    pub tangent: [f64; 2],
    /// Arc length of the closest point along the profile from the pole (mm).
    pub xi: f64,
    /// `d normal / dx` (row i, column j: `d n_i / d x_j`).
    pub dnormal: [[f64; 2]; 2],
    /// `d tangent / dx`.
    pub dtangent: [[f64; 2]; 2],
    /// `d xi / dx`.
    pub dxi: [f64; 2],
}

/// One smooth piece of a tool's profile, in tool-local `(r, z)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segment {
    /// A circular arc of `radius` centred at `centre`, with arc length
    /// `xi = xi0 + radius * phi`, `phi` measured from straight down
    /// (counter-clockwise in the `(r, z)` plane).
    Arc {
        centre: [f64; 2],
        radius: f64,
        xi0: f64,
    },
    /// A straight line through `point` with outward unit `normal`; `xi` is
    /// `xi0` at `point` and increases along the tangent `(-n_z, n_r)`.
    Line {
        point: [f64; 2],
        normal: [f64; 2],
        xi0: f64,
    },
}

impl Segment {
    /// Projection of `p` onto this segment (extended beyond its ends).
    pub fn project(&self, p: [f64; 2]) -> Projection {
        match *self {
            Segment::Arc {
                centre,
                radius,
                xi0,
            } => arc(p, centre, radius, xi0),
            Segment::Line { point, normal, xi0 } => line(p, point, normal, xi0),
        }
    }
}

/// Projection onto a circular arc of radius `radius` centred at `c`, with
/// `xi = xi0 + radius * phi`, `phi` measured from straight down.
fn arc(p: [f64; 2], c: [f64; 2], radius: f64, xi0: f64) -> Projection {
    let d = [p[0] - c[0], p[1] - c[1]];
    let rho = (d[0] * d[0] + d[1] * d[1]).sqrt().max(1e-300);
    let n = [d[0] / rho, d[1] / rho];
    let t = [-n[1], n[0]];
    let phi = d[0].atan2(-d[1]);
    let outer = |a: [f64; 2], b: [f64; 2], s: f64| {
        [
            [s * a[0] * b[0], s * a[0] * b[1]],
            [s * a[1] * b[0], s * a[1] * b[1]],
        ]
    };
    Projection {
        gap: rho - radius,
        normal: n,
        tangent: t,
        xi: xi0 + radius * phi,
        dnormal: outer(t, t, 1.0 / rho),
        dtangent: outer(n, t, -1.0 / rho),
        dxi: [radius * t[0] / rho, radius * t[1] / rho],
    }
}

/// Projection onto a straight line through `a` with outward normal `n`.
fn line(p: [f64; 2], a: [f64; 2], n: [f64; 2], xi0: f64) -> Projection {
    let t = [-n[1], n[0]];
    let d = [p[0] - a[0], p[1] - a[1]];
    Projection {
        gap: d[0] * n[0] + d[1] * n[1],
        normal: n,
        tangent: t,
        xi: xi0 + d[0] * t[0] + d[1] * t[1],
        dnormal: [[0.0; 2]; 2],
        dtangent: [[0.0; 2]; 2],
        dxi: t,
    }
}

impl ToolShape {
    /// The N1 needle of docs/benchmarks.md.
    pub fn n1_needle() -> Self {
        ToolShape::Needle {
            tip_radius: 2.5,
            half_angle_deg: 15.0,
        }
    }

    /// Checks the dimensions.
    pub fn check(&self) -> Result<(), String> {
        let pos = |v: f64| v > 0.0 && v.is_finite();
        match *self {
            ToolShape::Needle {
                tip_radius,
                half_angle_deg,
            } => {
                if !pos(tip_radius) || !(half_angle_deg > 0.0 && half_angle_deg < 90.0) {
                    return Err("needle needs tip_radius > 0 and 0 < half_angle_deg < 90".into());
                }
            }
            ToolShape::Sphere { radius } if !pos(radius) => {
                return Err("sphere radius must be > 0".into())
            }
            ToolShape::FlatPunch {
                radius,
                edge_radius,
            } => {
                if !pos(radius) || !pos(edge_radius) || edge_radius >= radius {
                    return Err("flat punch needs 0 < edge_radius < radius".into());
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// Closest-point projection of the tool-local point `p = (r, z)`.
    pub fn project(&self, p: [f64; 2]) -> Projection {
        self.segment(p).project(p)
    }

    /// The profile segment (arc or straight line) that [`ToolShape::project`]
    /// projects `p = (r, z)` onto. The choice is made by region (the angle
    /// about an arc's centre, or the punch's corner coordinates), so a point
    /// deep inside the tool may be assigned a segment that is not the
    /// globally closest one.
    pub fn segment(&self, p: [f64; 2]) -> Segment {
        match *self {
            ToolShape::Sphere { radius } => Segment::Arc {
                centre: [0.0, radius],
                radius,
                xi0: 0.0,
            },
            ToolShape::Needle {
                tip_radius: rt,
                half_angle_deg,
            } => {
                let alpha = half_angle_deg.to_radians();
                let phi_t = std::f64::consts::FRAC_PI_2 - alpha;
                let phi = p[0].atan2(-(p[1] - rt));
                if phi <= phi_t {
                    Segment::Arc {
                        centre: [0.0, rt],
                        radius: rt,
                        xi0: 0.0,
                    }
                } else {
                    let tp = [rt * phi_t.sin(), rt - rt * phi_t.cos()];
                    Segment::Line {
                        point: tp,
                        normal: [alpha.cos(), -alpha.sin()],
                        xi0: rt * phi_t,
                    }
                }
            }
            ToolShape::Platen => Segment::Line {
                point: [0.0, 0.0],
                normal: [0.0, -1.0],
                xi0: 0.0,
            },
            ToolShape::FlatPunch {
                radius,
                edge_radius,
            } => {
                let c = [radius - edge_radius, edge_radius];
                if p[0] <= c[0] {
                    Segment::Line {
                        point: [0.0, 0.0],
                        normal: [0.0, -1.0],
                        xi0: 0.0,
                    }
                } else if p[1] <= c[1] {
                    Segment::Arc {
                        centre: c,
                        radius: edge_radius,
                        xi0: c[0],
                    }
                } else {
                    Segment::Line {
                        point: [radius, edge_radius],
                        normal: [1.0, 0.0],
                        xi0: c[0] + edge_radius * std::f64::consts::FRAC_PI_2 - edge_radius,
                    }
                }
            }
        }
    }

    /// A short name for messages.
    pub fn name(&self) -> String {
        match *self {
            ToolShape::Needle {
                tip_radius,
                half_angle_deg,
            } => format!("needle (tip radius {tip_radius} mm, cone {half_angle_deg} deg)"),
            ToolShape::Sphere { radius } => format!("sphere (radius {radius} mm)"),
            ToolShape::FlatPunch { radius, .. } => format!("flat punch (radius {radius} mm)"),
            ToolShape::Platen => "platen".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shapes() -> Vec<ToolShape> {
        vec![
            ToolShape::n1_needle(),
            ToolShape::Sphere { radius: 2.5 },
            ToolShape::FlatPunch {
                radius: 2.0,
                edge_radius: 0.2,
            },
            ToolShape::Platen,
        ]
    }

    #[test]
    fn needle_geometry_matches_benchmark() {
        // The cap ends at r = 2.4148 mm, 1.8530 mm above the tip.
        let s = ToolShape::n1_needle();
        let p = s.project([2.4148, 1.8530 - 0.01]);
        assert!(
            (p.gap - 0.01 * (15f64).to_radians().sin()).abs() < 2e-4,
            "{}",
            p.gap
        );
        // A point on the cone axis-side far up is inside.
        assert!(s.project([1.0, 5.0]).gap < 0.0);
        assert!((s.project([0.0, -0.3]).gap - 0.3).abs() < 1e-14);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let pts = [
            [0.7, -0.4],
            [2.6, 1.0],
            [3.5, 6.0],
            [1.95, 0.05],
            [2.1, 0.5],
            [0.3, -0.01],
        ];
        let h = 1e-7;
        for s in shapes() {
            for p in pts {
                let pr = s.project(p);
                for j in 0..2 {
                    let (mut a, mut b) = (p, p);
                    a[j] += h;
                    b[j] -= h;
                    let (pa, pb) = (s.project(a), s.project(b));
                    let fd = |x: f64, y: f64| (x - y) / (2.0 * h);
                    assert!(
                        (fd(pa.gap, pb.gap) - pr.normal[j]).abs() < 1e-6,
                        "{s:?} {p:?}"
                    );
                    assert!((fd(pa.xi, pb.xi) - pr.dxi[j]).abs() < 1e-6, "{s:?} {p:?}");
                    for i in 0..2 {
                        assert!((fd(pa.normal[i], pb.normal[i]) - pr.dnormal[i][j]).abs() < 1e-6);
                        assert!(
                            (fd(pa.tangent[i], pb.tangent[i]) - pr.dtangent[i][j]).abs() < 1e-6
                        );
                    }
                }
            }
        }
    }
}
