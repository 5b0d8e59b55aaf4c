//! Rigid tool surfaces for plane, axisymmetric and 3D contact, behind one
//! object-safe trait, [`RigidSurface`].
//!
//! # Conventions
//!
//! Coordinates are tool-local. In 2D the point is `(x, y)` (plane) or
//! `(r, z)` (axisymmetric) in the first two slots of a `[f64; 3]`, the third
//! slot is ignored and every z component of the result is zero. In 3D the
//! point is `(x, y, z)` with z up along the tool's axis. The origin is the
//! tool's lowest point on its axis and the body lies below. The normal `n`
//! is the unit outward normal of the tool, pointing from the tool into the
//! body, and the gap is the signed distance along it:
//!
//! ```text
//! p = x_c + g n,   g > 0 outside the tool, g < 0 inside,
//! ```
//!
//! where `x_c` is the closest point of the surface (the normal-gap
//! definition and closest-point projection of Wriggers, *Computational
//! Contact Mechanics*, 2nd ed., Springer 2006, ch. 4). For each smooth piece of surface
//! the gap is a distance function, so `dg/dp = n` and `dn/dp` is its
//! (symmetric) Hessian: in the principal directions of the surface at `x_c`
//! with curvatures `k_a` (positive for a convex tool) its eigenvalues are
//! `k_a / (1 + g k_a)`, and it vanishes along `n`.
//!
//! * Sphere or circle of radius `R` centred at `c`: with `d = p - c`,
//!   `rho = |d|`, `g = rho - R`, `n = d / rho` and
//!   `dn/dp = (I - n (x) n) / rho`.
//! * Cylinder with unit axis `a`: the same with `d` projected off the axis
//!   and `dn/dp = (I - a (x) a - n (x) n) / rho`.
//! * Plane: `n` constant, `dn/dp = 0`.
//! * Surface of revolution about z of a profile `(n_r, n_z)(r, z)`
//!   ([`ToolShape`]): with `e_r = (x/r, y/r, 0)`, `e_t = (-y/r, x/r, 0)`,
//!   `e_z = (0, 0, 1)`, `n = n_r e_r + n_z e_z` and, since
//!   `d r/dp = e_r` and `d e_r/dp = e_t (x) e_t / r`,
//!
//!   ```text
//!   dn/dp = sum_{a,b in {r,z}} (d n_a / d q_b) e_a (x) e_b  +  (n_r / r) e_t (x) e_t,
//!   ```
//!
//!   the second term being the hoop (parallel-circle) curvature of the
//!   distance function at the query point's own radius (the principal
//!   curvature of a surface of revolution along its parallels, normal
//!   component `n_r` over radius; e.g. do Carmo, *Differential Geometry of
//!   Curves and Surfaces*, 1976, ch. 3; here on the offset surface through
//!   `p`).
//!
//! In 2D [`SurfacePoint`] also carries the tangent `t = (-n_y, n_x)` and the
//! arc length `xi` of the closest point along the profile, exactly as
//! [`crate::tool::Projection`], for the 2D frictional slip. In 3D these are
//! zero: 3D friction works with the Cartesian closest point
//! ([`SurfacePoint::closest`], [`SurfacePoint::dclosest`]).
//!
//! # The axis of a 3D surface of revolution
//!
//! At `r = 0` the azimuth is undefined. Profile arcs centred on the axis
//! (the sphere, the needle's spherical cap) are therefore evaluated with the
//! 3D sphere formulas above, which never divide by `r` and give `n = (0, 0,
//! -1)` on the axis below the tip. The flat face of a punch and the platen
//! have `n_r = 0` and no hoop term. The only other piece that reaches the
//! axis is the needle's cone for points inside the tool above the cap
//! centre, where the distance function is genuinely not differentiable (the
//! medial axis); there `e_r` falls back to `(1, 0, 0)` at `r = 0` and the
//! hoop term uses `max(r, 1e-12 L)` (`L` the tool's size), so the results stay
//! finite.

use serde::{Deserialize, Serialize};

use crate::tool::{Projection, Segment, ToolShape};

/// The closest-point projection of a point onto a rigid surface and its
/// derivatives with respect to the query point `p`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SurfacePoint {
    /// Signed distance, negative inside the tool.
    pub gap: f64,
    /// Unit normal from the tool into the body (z component zero in 2D).
    pub normal: [f64; 3],
    /// `d n_i / d p_j` (row i, column j); zero third row and column in 2D.
    pub dnormal: [[f64; 3]; 3],
    /// 2D only: `(-n_y, n_x, 0)`, along increasing `xi`; zero in 3D.
    pub tangent: [f64; 3],
    /// 2D only: `d t_i / d p_j`; zero in 3D.
    pub dtangent: [[f64; 3]; 3],
    /// 2D only: arc length of the closest point along the profile, with the
    /// same origin and sense as [`ToolShape::project`]; zero in 3D.
    pub xi: f64,
    /// 2D only: `d xi / d p`; zero in 3D.
    pub dxi: [f64; 3],
}

impl SurfacePoint {
    /// The closest point of the surface, `x_c = p - g n`.
    pub fn closest(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|i| p[i] - self.gap * self.normal[i])
    }

    /// `d x_c / d p = I - n (x) n - g dn/dp` (using `dg/dp = n`). In 2D the
    /// `(z, z)` entry is 1: the ignored third coordinate passes through
    /// [`SurfacePoint::closest`] unchanged.
    pub fn dclosest(&self) -> [[f64; 3]; 3] {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                kron(i, j) - self.normal[i] * self.normal[j] - self.gap * self.dnormal[i][j]
            })
        })
    }

    /// A 2D profile projection embedded with zero z components.
    pub(crate) fn from_2d(pr: &Projection) -> Self {
        let v = |a: [f64; 2]| [a[0], a[1], 0.0];
        let m = |a: [[f64; 2]; 2]| [v(a[0]), v(a[1]), [0.0; 3]];
        SurfacePoint {
            gap: pr.gap,
            normal: v(pr.normal),
            dnormal: m(pr.dnormal),
            tangent: v(pr.tangent),
            dtangent: m(pr.dtangent),
            xi: pr.xi,
            dxi: v(pr.dxi),
        }
    }
}

/// A rigid analytic surface in tool-local coordinates (see the module
/// documentation for the conventions). Object safe: models hold a
/// `Box<dyn RigidSurface>`.
pub trait RigidSurface: Send + Sync + std::fmt::Debug {
    /// The spatial dimension of the query points: 2 (plane or axisymmetric)
    /// or 3.
    fn dim(&self) -> usize;
    /// Closest-point projection of the tool-local point `p` (in 2D the third
    /// coordinate is ignored).
    fn project(&self, p: [f64; 3]) -> SurfacePoint;
    /// A short name for messages.
    fn name(&self) -> String;
    /// Checks the dimensions.
    fn check(&self) -> Result<(), String>;
    /// An identifier of the smooth piece of the surface that
    /// [`RigidSurface::project`] uses at the tool-local point `p`: across a
    /// change of piece the curvature, hence the contact force's derivative,
    /// may jump ([`crate::contact_split`]). Default: one smooth piece.
    fn piece(&self, _p: [f64; 3]) -> u64 {
        0
    }
}

/// The Kronecker delta.
fn kron(i: usize, j: usize) -> f64 {
    if i == j {
        1.0
    } else {
        0.0
    }
}

fn check_radius(what: &str, radius: f64) -> Result<(), String> {
    if radius > 0.0 && radius.is_finite() {
        Ok(())
    } else {
        Err(format!(
            "{what} radius must be finite and > 0, not {radius}"
        ))
    }
}

/// A [`ToolShape`] profile for 2D models (plane strain or stress, or
/// axisymmetric with `p = (r, z)`); returns exactly [`ToolShape::project`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Profile2d(pub ToolShape);

impl RigidSurface for Profile2d {
    fn dim(&self) -> usize {
        2
    }
    fn project(&self, p: [f64; 3]) -> SurfacePoint {
        SurfacePoint::from_2d(&self.0.project([p[0], p[1]]))
    }
    fn name(&self) -> String {
        self.0.name()
    }
    fn check(&self) -> Result<(), String> {
        self.0.check()
    }
    fn piece(&self, p: [f64; 3]) -> u64 {
        match self.0.segment([p[0], p[1]]) {
            Segment::Arc { xi0, .. } => xi0.to_bits() << 1,
            Segment::Line { xi0, .. } => (xi0.to_bits() << 1) | 1,
        }
    }
}

/// A wheel in a plane model: the circle of `radius` centred at
/// `(0, radius)`, valid for either sign of x (it is the 2D projection of
/// [`ToolShape::Sphere`], whose arc is not restricted to `x >= 0`). `xi` is
/// the arc length from the bottom point, increasing counter-clockwise
/// (towards +x from the bottom); it jumps by `2 pi radius` across the top
/// of the wheel (`x = 0`, `y > radius`), which contact never reaches.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Wheel2d {
    pub radius: f64,
}

impl RigidSurface for Wheel2d {
    fn dim(&self) -> usize {
        2
    }
    fn project(&self, p: [f64; 3]) -> SurfacePoint {
        let circle = ToolShape::Sphere {
            radius: self.radius,
        };
        SurfacePoint::from_2d(&circle.project([p[0], p[1]]))
    }
    fn name(&self) -> String {
        format!("wheel (radius {} mm, 2D)", self.radius)
    }
    fn check(&self) -> Result<(), String> {
        check_radius("wheel", self.radius)
    }
}

/// A fixed rigid base under a 2D body: the line `y = 0` (tool-local) with
/// the body above it, so its normal is `(0, 1)` (from the base into the
/// body) and its tangent `(-1, 0)`; `xi = -x`. The lower platen or the
/// rigid support a specimen rests on with Coulomb friction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Floor2d;

impl RigidSurface for Floor2d {
    fn dim(&self) -> usize {
        2
    }
    fn project(&self, p: [f64; 3]) -> SurfacePoint {
        SurfacePoint {
            gap: p[1],
            normal: [0.0, 1.0, 0.0],
            tangent: [-1.0, 0.0, 0.0],
            xi: -p[0],
            dxi: [-1.0, 0.0, 0.0],
            ..SurfacePoint::default()
        }
    }
    fn name(&self) -> String {
        "rigid base".into()
    }
    fn check(&self) -> Result<(), String> {
        Ok(())
    }
}

/// A [`ToolShape`] profile revolved about the tool's z axis, for 3D models
/// (`r = sqrt(x^2 + y^2)`). `Revolution3d(ToolShape::Platen)` is the plane
/// `z = 0` with normal `(0, 0, -1)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Revolution3d(pub ToolShape);

/// Relative floor on `r` in the hoop term of a profile piece that does not
/// flatten at the axis (see the module documentation).
const AXIS_FLOOR: f64 = 1e-12;

impl Revolution3d {
    /// The tool's characteristic size, which scales [`AXIS_FLOOR`].
    fn size(&self) -> f64 {
        match self.0 {
            ToolShape::Needle { tip_radius, .. } => tip_radius,
            ToolShape::Sphere { radius } => radius,
            ToolShape::FlatPunch { radius, .. } => radius,
            ToolShape::Platen => 1.0,
        }
    }
}

/// Sphere of `radius` centred at `c`; on the centre the normal is taken as
/// `(0, 0, -1)`.
fn sphere(p: [f64; 3], c: [f64; 3], radius: f64) -> SurfacePoint {
    let d: [f64; 3] = std::array::from_fn(|i| p[i] - c[i]);
    let rho = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let n = if rho > 0.0 {
        d.map(|v| v / rho)
    } else {
        [0.0, 0.0, -1.0]
    };
    let inv = 1.0 / rho.max(1e-300);
    SurfacePoint {
        gap: rho - radius,
        normal: n,
        dnormal: std::array::from_fn(|i| std::array::from_fn(|j| (kron(i, j) - n[i] * n[j]) * inv)),
        ..SurfacePoint::default()
    }
}

/// Lifts the profile projection `pr` at `(r, z)` to 3D at `p`.
fn lift(pr: &Projection, p: [f64; 3], r: f64, r_floor: f64) -> SurfacePoint {
    let er = if r > 0.0 {
        [p[0] / r, p[1] / r, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let et = [-er[1], er[0], 0.0];
    let ez = [0.0, 0.0, 1.0];
    let basis = [er, ez];
    let nr = pr.normal[0];
    let hoop = if nr == 0.0 { 0.0 } else { nr / r.max(r_floor) };
    SurfacePoint {
        gap: pr.gap,
        normal: std::array::from_fn(|i| nr * er[i] + pr.normal[1] * ez[i]),
        dnormal: std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let mut s = hoop * et[i] * et[j];
                for a in 0..2 {
                    for b in 0..2 {
                        s += pr.dnormal[a][b] * basis[a][i] * basis[b][j];
                    }
                }
                s
            })
        }),
        ..SurfacePoint::default()
    }
}

impl RigidSurface for Revolution3d {
    fn dim(&self) -> usize {
        3
    }
    fn project(&self, p: [f64; 3]) -> SurfacePoint {
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let q = [r, p[2]];
        match self.0.segment(q) {
            Segment::Arc { centre, radius, .. } if centre[0] == 0.0 => {
                sphere(p, [0.0, 0.0, centre[1]], radius)
            }
            seg => lift(&seg.project(q), p, r, AXIS_FLOOR * self.size()),
        }
    }
    fn name(&self) -> String {
        format!("{} (3D)", self.0.name())
    }
    fn check(&self) -> Result<(), String> {
        self.0.check()
    }
}

/// A wheel in 3D: an infinitely long cylinder of `radius` with its axis
/// along y through `(0, *, radius)`, touching the plane `z = 0` along the
/// y axis; it rolls along x with z up. On its axis the normal is taken as
/// `(0, 0, -1)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cylinder3d {
    pub radius: f64,
}

impl RigidSurface for Cylinder3d {
    fn dim(&self) -> usize {
        3
    }
    fn project(&self, p: [f64; 3]) -> SurfacePoint {
        let d = [p[0], 0.0, p[2] - self.radius];
        let rho = (d[0] * d[0] + d[2] * d[2]).sqrt();
        let n = if rho > 0.0 {
            d.map(|v| v / rho)
        } else {
            [0.0, 0.0, -1.0]
        };
        let inv = 1.0 / rho.max(1e-300);
        // I - a (x) a with a = e_y.
        let perp = |i: usize, j: usize| if i == 1 { 0.0 } else { kron(i, j) };
        SurfacePoint {
            gap: rho - self.radius,
            normal: n,
            dnormal: std::array::from_fn(|i| {
                std::array::from_fn(|j| (perp(i, j) - n[i] * n[j]) * inv)
            }),
            ..SurfacePoint::default()
        }
    }
    fn name(&self) -> String {
        format!("wheel (radius {} mm, 3D cylinder along y)", self.radius)
    }
    fn check(&self) -> Result<(), String> {
        check_radius("wheel", self.radius)
    }
}

#[cfg(test)]
#[path = "surface_tests.rs"]
mod tests;
