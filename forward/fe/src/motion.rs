//! Rigid-body motion of a tool driven by loading channels.
//!
//! Loading channels are scalar functions of (pseudo-)time evaluated
//! elsewhere; a [`ToolMotion`] receives their current values as
//! `values: &[f64]` and returns the tool's [`Pose`]: the map from tool-local
//! coordinates `X` (those of [`crate::surface`]) to global coordinates `x`,
//!
//! ```text
//! x = p + R X,        X = R^T (x - p),
//! ```
//!
//! with `p` the global position of the tool-local origin and `R` a proper
//! rotation. The motion is
//!
//! ```text
//! u = sum_k values[c_k] d_k                 (translation of the tool)
//! p = origin + u + (I - R) c                (c: the rotation's pivot, local)
//! ```
//!
//! so that the pivot `c` (the tool origin for [`Rotation::About`], the wheel
//! centre for [`Rotation::Rolling`]) is carried to `origin + c + u` and the
//! tool turns about it. Without a rotation `R = I` and `p = origin + u`.
//!
//! # Rotations
//!
//! `R(a, theta)` is the right-hand rotation by `theta` about the unit axis
//! `a`, by Rodrigues' formula with `K = [a]_x` (`K v = a x v`):
//!
//! ```text
//! R = I + sin(theta) K + (1 - cos(theta)) K^2.
//! ```
//!
//! (Written with `K^2 = a (x) a - I` so that, for an axis along z, the
//! `(z, z)` entry is exactly 1 and the plane block is exactly decoupled.)
//!
//! * [`Rotation::About`]: `theta = values[channel] * rate` about `axis`
//!   through the tool origin.
//! * [`Rotation::Rolling`]: rolling without slip along the unit `direction`
//!   on a wheel of `radius` whose centre is at `c = radius * up` in the tool
//!   frame (the surfaces' convention: the origin is the wheel's lowest
//!   point, [`crate::surface::Wheel2d`], [`crate::surface::Cylinder3d`]).
//!   With `s = u . direction` the centre's travel along `direction`,
//!
//!   ```text
//!   theta = s / radius   about   a = up x direction.
//!   ```
//!
//!   Reasoning: the contact point `c - radius * up` (relative position
//!   `-radius * up` from the centre) must have zero velocity,
//!   `ds/dt direction + omega x (-radius up) = 0`; with `omega = w a`,
//!   `a x up = (up x direction) x up = direction` (for `up` orthogonal to
//!   `direction`), so `ds/dt - w radius = 0`, `w = (ds/dt) / radius > 0`.
//!   In 2D (y up, rolling in +x) `a = e_y x e_x = -e_z`: the wheel turns
//!   clockwise, by `-dx / radius` about +z. In 3D (z up, rolling in +x)
//!   `a = e_z x e_x = +e_y`: it turns by `+dx / radius` about +y.
//!
//!   On the 2D wheel, whose `xi` is the arc length from the bottom point
//!   counter-clockwise, the material point in contact with the ground after
//!   a travel `dx` is the one at `xi = +dx` (modulo `2 pi radius`): the
//!   material ahead of the wheel (towards +x, counter-clockwise from the
//!   bottom in the tool frame) rolls onto the ground.
//!
//! # Projection in the global frame
//!
//! With `X = R^T (x - p)` and the tool-local projection `g, n, t, xi` at
//! `X` ([`RigidSurface::project`]), the global projection is
//!
//! ```text
//! g(x)  = g(X),                 dg/dx  = R n              (the global normal)
//! n(x)  = R n(X),               dn/dx  = R (dn/dX) R^T
//! t(x)  = R t(X),               dt/dx  = R (dt/dX) R^T
//! xi(x) = xi(X),                dxi/dx = R dxi/dX,
//! ```
//!
//! by the chain rule with `dX/dx = R^T`. `xi` stays the tool-frame arc
//! length: a stick point stored as `xi` is a material point of the tool and
//! moves with it.
//!
//! # Bit-for-bit translation
//!
//! Without a rotation the local point is computed as
//! `(x - origin) - u`, in that order and with `u` summed from its first
//! term, which is exactly what the original axisymmetric contact code (`RigidTool::local`, before the layer)
//! computes (`x - origin - travel * direction`); and the local projection is
//! returned unchanged (no multiplications by the identity). The N1 needle
//! therefore gives the same numbers through a [`ToolMotion`]. (Forming
//! `p = origin + u` first and then `x - p` would not: it rounds differently.)

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::surface::{RigidSurface, SurfacePoint};

/// How a rigid tool moves with the loading channels (see the module
/// documentation for the equations).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ToolMotion {
    /// Global position of the tool-local origin when every channel is zero.
    pub origin: [f64; 3],
    /// `(channel index, direction)`: the translation is
    /// `u = sum values[channel] * direction` (directions need not be unit;
    /// a channel's unit is then "direction lengths").
    pub translation: Vec<(usize, [f64; 3])>,
    /// The tool's rotation, if any.
    pub rotation: Option<Rotation>,
}

/// The rotation of a [`ToolMotion`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Rotation {
    /// Rotation angle `theta = values[channel] * rate` (rad per channel
    /// unit) about the unit `axis` through the tool origin (right-hand
    /// rule).
    About {
        channel: usize,
        axis: [f64; 3],
        rate: f64,
    },
    /// Rolling without slip along the unit `direction`, on a wheel of
    /// `radius` centred at `radius * up` in the tool frame (`up` unit and
    /// orthogonal to `direction`): `theta = (u . direction) / radius` about
    /// `up x direction`, `u` the translation. In 2D (y up, rolling in +x) the
    /// wheel turns clockwise; in 3D (z up, rolling in +x) about +y. The
    /// radius should be that of the surface.
    Rolling {
        direction: [f64; 3],
        up: [f64; 3],
        radius: f64,
    },
}

/// The placement of the tool: `x = p + R X` (see the module documentation).
///
/// `p` is kept as `origin + displacement` (not summed) so that, without a
/// rotation, [`Pose::to_local`] reproduces the legacy translation-only
/// arithmetic bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The motion's origin.
    pub origin: [f64; 3],
    /// `p - origin = u + (I - R) c`.
    pub displacement: [f64; 3],
    /// The rotation `R` from the tool frame to the global frame.
    pub rotation: Matrix3<f64>,
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| a[i] + b[i])
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

fn finite(a: [f64; 3]) -> bool {
    a.iter().all(|v| v.is_finite())
}

/// Tolerance on unit lengths and orthogonality in [`ToolMotion::check`].
const UNIT_TOL: f64 = 1e-12;

fn check_unit(what: &str, a: [f64; 3]) -> Result<(), String> {
    if finite(a) && (norm(a) - 1.0).abs() <= UNIT_TOL {
        Ok(())
    } else {
        Err(format!("{what} must be a finite unit vector, not {a:?}"))
    }
}

/// `R(a, theta) = I + sin(theta) K + (1 - cos(theta)) K^2`, `K = [a]_x`,
/// `K^2 = a (x) a - I`.
pub fn axis_angle(a: [f64; 3], theta: f64) -> Matrix3<f64> {
    let (s, c) = theta.sin_cos();
    let k = Matrix3::new(0.0, -a[2], a[1], a[2], 0.0, -a[0], -a[1], a[0], 0.0);
    let k2 = Matrix3::from_fn(|i, j| a[i] * a[j] - if i == j { 1.0 } else { 0.0 });
    Matrix3::identity() + k * s + k2 * (1.0 - c)
}

impl ToolMotion {
    /// A translation-only motion.
    pub fn translating(origin: [f64; 3], translation: Vec<(usize, [f64; 3])>) -> Self {
        ToolMotion {
            origin,
            translation,
            rotation: None,
        }
    }

    /// A wheel of `radius` pressed along `press = (channel, direction)` and
    /// travelling along `travel = (channel, direction)`, rolling without
    /// slip ([`Rotation::Rolling`] along the normalised travel direction).
    /// `up` is the surfaces' convention, e_y in 2D ([`crate::surface::Wheel2d`])
    /// and e_z in 3D ([`crate::surface::Cylinder3d`], whose axis is y, so the
    /// travel must then be along ±x); `origin` is the global position of the
    /// wheel's lowest point at rest. [`ToolMotion::check`] and
    /// [`ToolMotion::check_dim`] report a travel that is zero or not
    /// orthogonal to `up`.
    pub fn rolling(
        origin: [f64; 3],
        press: (usize, [f64; 3]),
        travel: (usize, [f64; 3]),
        radius: f64,
        dim: usize,
    ) -> Self {
        let up = if dim == 2 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        let l = norm(travel.1);
        ToolMotion {
            origin,
            translation: vec![press, travel],
            rotation: Some(Rotation::Rolling {
                direction: travel.1.map(|v| v / l),
                up,
                radius,
            }),
        }
    }

    /// The channels the motion follows (translation, then an explicit
    /// rotation's), sorted and without repeats.
    pub fn channels(&self) -> Vec<usize> {
        let mut c: Vec<usize> = self.translation.iter().map(|t| t.0).collect();
        if let Some(Rotation::About { channel, .. }) = self.rotation {
            c.push(channel);
        }
        c.sort_unstable();
        c.dedup();
        c
    }

    /// Checks that every channel index is below `channels`, the origin is
    /// finite, the translation directions are finite and non-zero, and the
    /// rotation is well posed (unit axis and finite rate; unit, orthogonal
    /// `direction` and `up` and a finite positive radius).
    pub fn check(&self, channels: usize) -> Result<(), String> {
        let channel = |c: usize| {
            if c < channels {
                Ok(())
            } else {
                Err(format!(
                    "tool motion uses channel {c}, but there are only {channels}"
                ))
            }
        };
        if !finite(self.origin) {
            return Err(format!("tool origin must be finite, not {:?}", self.origin));
        }
        for &(c, d) in &self.translation {
            channel(c)?;
            if !finite(d) || !(norm(d) > 0.0) {
                return Err(format!(
                    "translation direction of channel {c} must be finite and non-zero, not {d:?}"
                ));
            }
        }
        match self.rotation {
            None => Ok(()),
            Some(Rotation::About {
                channel: c,
                axis,
                rate,
            }) => {
                channel(c)?;
                check_unit("rotation axis", axis)?;
                if rate.is_finite() {
                    Ok(())
                } else {
                    Err(format!("rotation rate must be finite, not {rate}"))
                }
            }
            Some(Rotation::Rolling {
                direction,
                up,
                radius,
            }) => {
                check_unit("rolling direction", direction)?;
                check_unit("rolling 'up'", up)?;
                if dot(direction, up).abs() > UNIT_TOL {
                    return Err(format!(
                        "rolling direction {direction:?} must be orthogonal to 'up' {up:?}"
                    ));
                }
                if radius > 0.0 && radius.is_finite() {
                    Ok(())
                } else {
                    Err(format!(
                        "rolling radius must be finite and > 0, not {radius}"
                    ))
                }
            }
        }
    }

    /// Checks that the motion fits a model of dimension `dim`: in 2D every
    /// translation and the origin lie in the plane (zero z) and the rotation
    /// axis is ±z (the 2D surfaces ignore the third coordinate).
    pub fn check_dim(&self, dim: usize) -> Result<(), String> {
        if dim != 2 {
            return if dim == 3 {
                Ok(())
            } else {
                Err(format!("dimension must be 2 or 3, not {dim}"))
            };
        }
        let in_plane = std::iter::once(self.origin)
            .chain(self.translation.iter().map(|t| t.1))
            .all(|v| v[2] == 0.0);
        if !in_plane {
            return Err("a 2D tool motion must have zero z components".into());
        }
        let axis = match self.rotation {
            None => return Ok(()),
            Some(Rotation::About { axis, .. }) => axis,
            Some(Rotation::Rolling { direction, up, .. }) => cross(up, direction),
        };
        if axis[0] == 0.0 && axis[1] == 0.0 {
            Ok(())
        } else {
            Err(format!(
                "a 2D tool must rotate about the z axis, not {axis:?}"
            ))
        }
    }

    /// The pose at channel values `values`. Panics if a channel index is out
    /// of range (see [`ToolMotion::check`]).
    pub fn pose(&self, values: &[f64]) -> Pose {
        // u, summed from its first term (bit-for-bit with the legacy path).
        let mut u: Option<[f64; 3]> = None;
        for &(c, d) in &self.translation {
            let term = d.map(|v| values[c] * v);
            u = Some(match u {
                None => term,
                Some(s) => add(s, term),
            });
        }
        let u = u.unwrap_or([0.0; 3]);
        let (rotation, pivot) = match self.rotation {
            None => {
                return Pose {
                    origin: self.origin,
                    displacement: u,
                    rotation: Matrix3::identity(),
                }
            }
            Some(Rotation::About {
                channel,
                axis,
                rate,
            }) => (axis_angle(axis, values[channel] * rate), [0.0; 3]),
            Some(Rotation::Rolling {
                direction,
                up,
                radius,
            }) => (
                axis_angle(cross(up, direction), dot(u, direction) / radius),
                up.map(|v| v * radius),
            ),
        };
        let rc = rotation * Vector3::from(pivot);
        Pose {
            origin: self.origin,
            displacement: std::array::from_fn(|i| u[i] + (pivot[i] - rc[i])),
            rotation,
        }
    }
}

impl Pose {
    /// The pose at rest at `origin`.
    pub fn at(origin: [f64; 3]) -> Self {
        Pose {
            origin,
            displacement: [0.0; 3],
            rotation: Matrix3::identity(),
        }
    }

    /// The global position of the tool-local origin, `p = origin + displacement`.
    pub fn position(&self) -> [f64; 3] {
        add(self.origin, self.displacement)
    }

    fn is_translation(&self) -> bool {
        self.rotation == Matrix3::identity()
    }

    /// Tool-local coordinates `X = R^T (x - p)` of the global point `x`,
    /// computed as `R^T ((x - origin) - displacement)`; without a rotation
    /// the multiplication is skipped.
    pub fn to_local(&self, x: [f64; 3]) -> [f64; 3] {
        let d: [f64; 3] = std::array::from_fn(|i| x[i] - self.origin[i] - self.displacement[i]);
        if self.is_translation() {
            d
        } else {
            (self.rotation.transpose() * Vector3::from(d)).into()
        }
    }

    /// Global coordinates `x = p + R X` of the tool-local point `X`.
    pub fn to_global_point(&self, local: [f64; 3]) -> [f64; 3] {
        let v = self.to_global_vector(local);
        std::array::from_fn(|i| v[i] + self.origin[i] + self.displacement[i])
    }

    /// A tool-frame vector in the global frame, `R v`.
    pub fn to_global_vector(&self, v: [f64; 3]) -> [f64; 3] {
        if self.is_translation() {
            v
        } else {
            (self.rotation * Vector3::from(v)).into()
        }
    }

    /// The projection of the global point `x` onto `surface` (given in the
    /// tool frame), in the global frame: gap and `xi` unchanged, `n -> R n`,
    /// `t -> R t`, `dn -> R dn R^T`, `dt -> R dt R^T`, `dxi -> R dxi`.
    /// Without a rotation this is exactly `surface.project(self.to_local(x))`.
    pub fn project(&self, surface: &dyn RigidSurface, x: [f64; 3]) -> SurfacePoint {
        let sp = surface.project(self.to_local(x));
        if self.is_translation() {
            return sp;
        }
        let r = &self.rotation;
        let vec = |v: [f64; 3]| -> [f64; 3] { (r * Vector3::from(v)).into() };
        let mat = |m: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
            let g = r * Matrix3::from_fn(|i, j| m[i][j]) * r.transpose();
            std::array::from_fn(|i| std::array::from_fn(|j| g[(i, j)]))
        };
        SurfacePoint {
            gap: sp.gap,
            normal: vec(sp.normal),
            dnormal: mat(sp.dnormal),
            tangent: vec(sp.tangent),
            dtangent: mat(sp.dtangent),
            xi: sp.xi,
            dxi: vec(sp.dxi),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Cylinder3d, Profile2d, Revolution3d, Wheel2d};
    use crate::tool::ToolShape;
    use std::f64::consts::PI;

    const H: f64 = 1e-7;

    /// The tool-local point of the original axisymmetric contact code
    /// (`x - origin - travel * direction`, in that order).
    struct RigidTool {
        origin: [f64; 2],
        direction: [f64; 2],
    }

    impl RigidTool {
        fn local(&self, x: [f64; 2], travel: f64) -> [f64; 2] {
            [
                x[0] - self.origin[0] - travel * self.direction[0],
                x[1] - self.origin[1] - travel * self.direction[1],
            ]
        }
    }

    fn bits(sp: &SurfacePoint) -> Vec<u64> {
        let mut v = vec![sp.gap.to_bits(), sp.xi.to_bits()];
        for a in [sp.normal, sp.tangent, sp.dxi] {
            v.extend(a.map(f64::to_bits));
        }
        for m in [sp.dnormal, sp.dtangent] {
            v.extend(m.iter().flatten().map(|x| x.to_bits()));
        }
        v
    }

    #[test]
    fn translation_is_the_legacy_n1_path_bit_for_bit() {
        let shape = ToolShape::n1_needle();
        let surface = Profile2d(shape);
        for height in [0.0, 1.0, 0.1, 20.0 / 3.0] {
            let legacy = RigidTool {
                origin: [0.0, height],
                direction: [0.0, -1.0],
            };
            let motion = ToolMotion::translating([0.0, height, 0.0], vec![(0, [0.0, -1.0, 0.0])]);
            motion.check(1).unwrap();
            motion.check_dim(2).unwrap();
            for travel in [0.0, 0.3, 1.0 / 3.0, 2.7, -0.1] {
                let pose = motion.pose(&[travel]);
                assert_eq!(pose.rotation, Matrix3::identity());
                for i in 0..23 {
                    for k in 0..17 {
                        let x = [0.37 * i as f64, -2.0 + 0.61 * k as f64 + 0.1 / 3.0];
                        let old = SurfacePoint::from_2d(&shape.project(legacy.local(x, travel)));
                        let new = pose.project(&surface, [x[0], x[1], 0.0]);
                        assert_eq!(bits(&new), bits(&old), "{height} {travel} {x:?}");
                    }
                }
            }
        }
        // Forming p = origin + u first and then x - p rounds differently.
        let legacy = RigidTool {
            origin: [0.0, 20.0 / 3.0],
            direction: [0.0, -1.0],
        };
        let p = [0.0, 20.0 / 3.0 - 1.0 / 3.0];
        let differs = (0..200)
            .map(|k| [0.5, -1.0 + 0.0371 * k as f64])
            .filter(|x| legacy.local(*x, 1.0 / 3.0) != [x[0] - p[0], x[1] - p[1]])
            .count();
        assert!(differs > 0);
        // 3D, several channels: exactly the projection of the local point,
        // and the local point is x - p to round-off.
        let s = Revolution3d(shape);
        let m = ToolMotion::translating(
            [0.3, -0.2, 1.7],
            vec![
                (1, [0.0, 0.0, -1.0]),
                (0, [0.6, 0.8, 0.0]),
                (1, [0.1, 0.0, 0.0]),
            ],
        );
        m.check(2).unwrap();
        let pose = m.pose(&[0.7, 1.3]);
        for x in [[0.5, 0.2, 0.1], [-1.0, 2.0, 3.0], [0.91, 0.58, 0.4]] {
            assert_eq!(
                bits(&pose.project(&s, x)),
                bits(&s.project(pose.to_local(x)))
            );
            let p = pose.position();
            let a = pose.to_local(x);
            for i in 0..3 {
                assert!((a[i] - (x[i] - p[i])).abs() < 1e-15);
            }
        }
    }

    fn close(fd: f64, an: f64) -> bool {
        (fd - an).abs() <= 1e-6 * (1.0 + an.abs())
    }

    /// Every derivative of the global projection at `x` against central
    /// differences in the first `dim` global coordinates.
    fn check_fd(
        pose: &Pose,
        s: &dyn RigidSurface,
        x: [f64; 3],
        same_piece: &dyn Fn([f64; 3]) -> bool,
    ) {
        let sp = pose.project(s, x);
        let dc = sp.dclosest();
        let nn: f64 = sp.normal.iter().map(|v| v * v).sum();
        assert!((nn - 1.0).abs() < 1e-14);
        for j in 0..s.dim() {
            let (mut a, mut b) = (x, x);
            a[j] += H;
            b[j] -= H;
            assert!(
                same_piece(pose.to_local(a)) && same_piece(pose.to_local(b)),
                "{s:?} {x:?}: stencil straddles a piece boundary"
            );
            let (pa, pb) = (pose.project(s, a), pose.project(s, b));
            let fd = |u: f64, v: f64| (u - v) / (2.0 * H);
            let msg = format!("{} at {x:?}, d/dx_{j}", s.name());
            assert!(close(fd(pa.gap, pb.gap), sp.normal[j]), "{msg}: gap");
            assert!(close(fd(pa.xi, pb.xi), sp.dxi[j]), "{msg}: xi");
            let (ca, cb) = (pa.closest(a), pb.closest(b));
            for i in 0..3 {
                assert!(
                    close(fd(pa.normal[i], pb.normal[i]), sp.dnormal[i][j]),
                    "{msg}: n_{i}"
                );
                assert!(
                    close(fd(pa.tangent[i], pb.tangent[i]), sp.dtangent[i][j]),
                    "{msg}: t_{i}"
                );
                assert!(close(fd(ca[i], cb[i]), dc[i][j]), "{msg}: closest_{i}");
            }
        }
        // The global closest point lies on the surface, and is the image of
        // the local one.
        let c = sp.closest(x);
        assert!(pose.project(s, c).gap.abs() < 1e-12);
        let local = s.project(pose.to_local(x));
        let cl = pose.to_global_point(local.closest(pose.to_local(x)));
        for i in 0..3 {
            assert!((c[i] - cl[i]).abs() < 1e-12);
        }
        // In 2D the results stay in the plane.
        if s.dim() == 2 {
            assert_eq!(sp.normal[2], 0.0);
            assert_eq!(sp.dxi[2], 0.0);
            assert!(sp.dnormal[2].iter().all(|&v| v == 0.0));
        }
    }

    fn rotated(axis: [f64; 3], angle: f64, origin: [f64; 3]) -> ToolMotion {
        let l = norm(axis);
        ToolMotion {
            origin,
            translation: vec![(0, [0.2, -1.0, 0.3]), (1, [1.0, 0.0, 0.0])],
            rotation: Some(Rotation::About {
                channel: 2,
                axis: axis.map(|v| v / l),
                rate: angle,
            }),
        }
    }

    #[test]
    fn rotated_wheels_and_needle_match_finite_differences() {
        let vals = [0.4, -0.7, 1.0];
        // The 2D wheel, turned about z.
        let w = Wheel2d { radius: 2.5 };
        for angle in [0.3, -2.0, PI] {
            let mut m = rotated([0.0, 0.0, 1.0], angle, [1.0, 3.0, 0.0]);
            m.translation[0].1[2] = 0.0;
            m.check(3).unwrap();
            m.check_dim(2).unwrap();
            let pose = m.pose(&vals);
            for (rho, phi) in [
                (2.9, 0.0),
                (3.3, 40.0),
                (2.2, -70.0),
                (3.0, 120.0),
                (2.6, -175.0),
            ] {
                // A point at angle phi (degrees from the wheel's local bottom)
                // and distance rho from its centre.
                let phi = f64::to_radians(phi);
                let local = [rho * phi.sin(), 2.5 - rho * phi.cos(), 0.0];
                let x = pose.to_global_point(local);
                check_fd(&pose, &w, x, &|_| true);
                let sp = pose.project(&w, x);
                assert!((sp.gap - (rho - 2.5)).abs() < 1e-13);
                assert!((sp.xi - 2.5 * phi).abs() < 1e-12);
            }
        }
        // The 3D wheel and needle, turned about arbitrary axes.
        let cyl = Cylinder3d { radius: 2.5 };
        let needle = ToolShape::n1_needle();
        let rev = Revolution3d(needle);
        let piece = |p: [f64; 3]| needle.segment([p[0].hypot(p[1]), p[2]]);
        for (axis, angle) in [
            ([0.3, -0.5, 0.8], 0.9),
            ([1.0, 0.0, 0.0], PI / 2.0),
            ([-0.2, 0.9, 0.1], -2.4),
        ] {
            let m = rotated(axis, angle, [0.5, -1.0, 4.0]);
            m.check(3).unwrap();
            let pose = m.pose(&vals);
            // R is a proper rotation.
            let r = pose.rotation;
            assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-15);
            assert!((r.determinant() - 1.0).abs() < 1e-15);
            for local in [
                [0.7, 1.3, -0.4],
                [-1.0, -30.0, 1.0],
                [2.0, 0.0, 4.5],
                [0.1, 5.0, 2.0],
            ] {
                let x = pose.to_global_point(local);
                let back = pose.to_local(x);
                for i in 0..3 {
                    assert!((back[i] - local[i]).abs() < 1e-13);
                }
                check_fd(&pose, &cyl, x, &|_| true);
            }
            for local in [
                [0.7, 0.2, -0.4],
                [-0.5, 0.4, 0.3],
                [2.4, -2.5, 6.0],
                [5.0, 1.0, 10.0],
                [0.05, 0.02, -0.5],
            ] {
                let x = pose.to_global_point(local);
                let p0 = piece(local);
                check_fd(&pose, &rev, x, &|q| piece(q) == p0);
                // The gap is frame-independent.
                let g = rev.project(local).gap;
                assert!((pose.project(&rev, x).gap - g).abs() < 1e-13 * (1.0 + g.abs()));
            }
        }
    }

    /// Wraps an arc length on the wheel into (-pi R, pi R].
    fn wrap(xi: f64, radius: f64) -> f64 {
        let c = 2.0 * PI * radius;
        xi - c * (xi / c).round()
    }

    #[test]
    fn rolling_wheel_rolls_without_slip() {
        let radius = 2.5;
        let w = Wheel2d { radius };
        let cyl = Cylinder3d { radius };
        let circ = 2.0 * PI * radius;
        // Channel 0 presses (down), channel 1 travels (+x, in units of 2 mm).
        let m2 = ToolMotion::rolling(
            [1.0, 0.0, 0.0],
            (0, [0.0, -1.0, 0.0]),
            (1, [2.0, 0.0, 0.0]),
            radius,
            2,
        );
        let m3 = ToolMotion::rolling(
            [1.0, 0.5, 0.0],
            (0, [0.0, 0.0, -1.0]),
            (1, [2.0, 0.0, 0.0]),
            radius,
            3,
        );
        for m in [&m2, &m3] {
            m.check(2).unwrap();
        }
        m2.check_dim(2).unwrap();
        m3.check_dim(3).unwrap();
        assert!(m3.check_dim(2).is_err());
        let press = 0.1;
        // The convention: clockwise in 2D, about +y in 3D.
        let dx = 0.3;
        let r2 = m2.pose(&[press, dx / 2.0]).rotation;
        let r3 = m3.pose(&[press, dx / 2.0]).rotation;
        assert!((r2 - axis_angle([0.0, 0.0, 1.0], -dx / radius)).norm() < 1e-15);
        assert!((r3 - axis_angle([0.0, 1.0, 0.0], dx / radius)).norm() < 1e-15);

        for k in 0..=40 {
            let dx = circ * k as f64 / 16.0 - 0.37;
            let vals = [press, dx / 2.0];
            let (p2, p3) = (m2.pose(&vals), m3.pose(&vals));
            // The centre moves with the translation only.
            let c2 = p2.to_global_point([0.0, radius, 0.0]);
            let c3 = p3.to_global_point([0.0, 0.0, radius]);
            let e2 = [1.0 + dx, radius - press, 0.0];
            let e3 = [1.0 + dx, 0.5, radius - press];
            for i in 0..3 {
                assert!(
                    (c2[i] - e2[i]).abs() < 1e-12 && (c3[i] - e3[i]).abs() < 1e-12,
                    "{k}"
                );
            }
            // The ground point under the centre touches the wheel at xi = +dx.
            let sp = p2.project(&w, [1.0 + dx, -0.2, 0.0]);
            assert!((sp.gap - (0.2 - press)).abs() < 1e-12);
            assert!((sp.normal[1] + 1.0).abs() < 1e-15);
            assert!(
                (wrap(sp.xi - dx, radius)).abs() < 1e-11,
                "{k}: {} vs {dx}",
                sp.xi
            );
            // The material point now in contact, carried to the ground.
            let phi = dx / radius;
            let mat = [radius * phi.sin(), radius - radius * phi.cos(), 0.0];
            let g = p2.to_global_point(mat);
            assert!(
                (g[0] - (1.0 + dx)).abs() < 1e-11 && (g[1] + press).abs() < 1e-11,
                "{k}"
            );
            let mat3 = [mat[0], 0.0, mat[1]];
            let g3 = p3.to_global_point(mat3);
            assert!(
                (g3[0] - (1.0 + dx)).abs() < 1e-11 && (g3[2] + press).abs() < 1e-11,
                "{k}"
            );
            // FD of the rolling poses.
            for x in [[1.0 + dx + 0.4, -0.2, 0.0], [dx - 1.0, 0.3, 0.0]] {
                check_fd(&p2, &w, x, &|_| true);
                check_fd(&p3, &cyl, [x[0], 0.7, x[1]], &|_| true);
            }
        }
        // The material point at the bottom at rest (x0) touches again after
        // travelling one circumference, and is at the back of the wheel after
        // a quarter turn (clockwise).
        for (p, centre) in [(&m2, [0.0, radius, 0.0]), (&m3, [0.0, 0.0, radius])] {
            let lo = [0.0; 3];
            let x0 = p.pose(&[press, 0.0]).to_global_point(lo);
            let x1 = p.pose(&[press, circ / 2.0]).to_global_point(lo);
            assert!((x1[0] - x0[0] - circ).abs() < 1e-12);
            for i in 1..3 {
                assert!((x1[i] - x0[i]).abs() < 1e-12);
            }
            let q = p.pose(&[press, circ / 8.0]).to_global_point(lo);
            let c = p.pose(&[press, circ / 8.0]).to_global_point(centre);
            assert!((q[0] - (c[0] - radius)).abs() < 1e-12);
        }
        let xi_at = |dx: f64| {
            m2.pose(&[press, dx / 2.0])
                .project(&w, [1.0 + dx, -0.5, 0.0])
                .xi
        };
        assert!(xi_at(0.0).abs() < 1e-15);
        assert!(wrap(xi_at(circ), radius).abs() < 1e-12);
        // xi of the contact point advances by exactly the travel.
        for dx in [0.01, 0.5, 1.7] {
            assert!((xi_at(dx) - xi_at(0.0) - dx).abs() < 1e-12);
        }
    }

    #[test]
    fn about_rotates_about_the_tool_origin() {
        let m = ToolMotion {
            origin: [1.0, 2.0, 3.0],
            translation: vec![],
            rotation: Some(Rotation::About {
                channel: 0,
                axis: [0.0, 0.0, 1.0],
                rate: 0.5,
            }),
        };
        m.check(1).unwrap();
        let pose = m.pose(&[PI]);
        // Quarter turn counter-clockwise: e_x -> e_y, the origin fixed.
        let a = pose.to_global_point([1.0, 0.0, 0.0]);
        let o = pose.to_global_point([0.0; 3]);
        assert_eq!(o, [1.0, 2.0, 3.0]);
        assert!((a[0] - 1.0).abs() < 1e-15 && (a[1] - 3.0).abs() < 1e-15);
        // No translation and zero angle is the rest pose.
        assert_eq!(m.pose(&[0.0]).rotation, Matrix3::identity());
        assert_eq!(m.pose(&[0.0]), Pose::at([1.0, 2.0, 3.0]));
        // Serde round trip.
        let rolling = ToolMotion::rolling(
            [0.0; 3],
            (0, [0.0, -1.0, 0.0]),
            (1, [1.0, 0.0, 0.0]),
            2.0,
            2,
        );
        for m in [&m, &rolling] {
            let s = serde_json::to_string(m).unwrap();
            assert_eq!(&serde_json::from_str::<ToolMotion>(&s).unwrap(), m);
        }
    }

    #[test]
    fn check_rejects_bad_motions() {
        let good = ToolMotion::rolling(
            [0.0; 3],
            (0, [0.0, -1.0, 0.0]),
            (1, [1.0, 0.0, 0.0]),
            2.0,
            2,
        );
        good.check(2).unwrap();
        assert!(good.check(1).unwrap_err().contains("channel 1"));
        let mut bad = Vec::new();
        let mut m = good.clone();
        m.translation[0].1 = [0.0; 3];
        bad.push(m);
        let mut m = good.clone();
        m.translation[1].1 = [f64::NAN, 0.0, 0.0];
        bad.push(m);
        let mut m = good.clone();
        m.origin[1] = f64::INFINITY;
        bad.push(m);
        for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let mut m = good.clone();
            m.rotation = Some(Rotation::Rolling {
                direction: [1.0, 0.0, 0.0],
                up: [0.0, 1.0, 0.0],
                radius: r,
            });
            bad.push(m);
        }
        // Travel not orthogonal to up, zero travel, non-unit axis, bad rate,
        // rotation channel out of range.
        bad.push(ToolMotion::rolling(
            [0.0; 3],
            (0, [0.0, -1.0, 0.0]),
            (1, [1.0, 1.0, 0.0]),
            2.0,
            2,
        ));
        bad.push(ToolMotion::rolling(
            [0.0; 3],
            (0, [0.0, -1.0, 0.0]),
            (1, [0.0; 3]),
            2.0,
            2,
        ));
        for (axis, rate, channel) in [
            ([0.0, 0.0, 2.0], 1.0, 0),
            ([0.0, 0.0, 0.0], 1.0, 0),
            ([0.0, 0.0, 1.0], f64::NAN, 0),
            ([0.0, 0.0, 1.0], 1.0, 2),
        ] {
            bad.push(ToolMotion {
                origin: [0.0; 3],
                translation: vec![],
                rotation: Some(Rotation::About {
                    channel,
                    axis,
                    rate,
                }),
            });
        }
        for m in &bad {
            assert!(m.check(2).is_err(), "{m:?}");
        }
        // Dimension checks.
        assert!(good.check_dim(2).is_ok() && good.check_dim(3).is_ok());
        assert!(good.check_dim(1).is_err());
        let mut m = good.clone();
        m.translation[0].1[2] = 0.1;
        assert!(m.check_dim(2).is_err());
        let tilted = ToolMotion {
            origin: [0.0; 3],
            translation: vec![],
            rotation: Some(Rotation::About {
                channel: 0,
                axis: [1.0, 0.0, 0.0],
                rate: 1.0,
            }),
        };
        assert!(tilted.check(1).is_ok() && tilted.check_dim(2).is_err());
    }

    #[test]
    fn channels_are_the_translations_and_an_explicit_rotation() {
        let rolling = ToolMotion::rolling(
            [0.0; 3],
            (2, [0.0, -1.0, 0.0]),
            (0, [1.0, 0.0, 0.0]),
            2.0,
            2,
        );
        assert_eq!(rolling.channels(), vec![0, 2]);
        let turning = ToolMotion {
            origin: [0.0; 3],
            translation: vec![(1, [0.0, -1.0, 0.0]), (1, [1.0, 0.0, 0.0])],
            rotation: Some(Rotation::About {
                channel: 3,
                axis: [0.0, 0.0, 1.0],
                rate: 1.0,
            }),
        };
        assert_eq!(turning.channels(), vec![1, 3]);
        assert!(ToolMotion::translating([0.0; 3], vec![])
            .channels()
            .is_empty());
    }
}
