//! The kinematic idealisation of a two-dimensional element: how the in-plane
//! displacement field makes a 3 x 3 deformation gradient and what volume a
//! unit of reference area carries.
//!
//! Components are ordered (r, z, theta) for [`Kinematics::Axisymmetric`] and
//! (x, y, z) for [`Kinematics::PlaneStrain`]. A 2D element only ever touches
//! the five components `F00, F01, F10, F11, F22` ([`F_COMPONENTS`]).

use serde::{Deserialize, Serialize};

/// Indices (row-major, `3 i + j`) of the five deformation-gradient
/// components a 2D element carries.
pub const F_COMPONENTS: [usize; 5] = [0, 1, 3, 4, 8];

/// The kinematic idealisation owned by a 2D element.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kinematics {
    /// Body of revolution about the z axis (r = coordinate 0): hoop stretch
    /// `F22 = r / R`, volume element `2 pi R dR dZ` (the whole 360 degrees).
    Axisymmetric,
    /// Plane strain of a slab of the given thickness (mm): `F22 = 1`.
    PlaneStrain { thickness: f64 },
}

impl Kinematics {
    /// Reference volume per unit reference area at radius `r_ref`.
    pub fn volume_factor(&self, r_ref: f64) -> f64 {
        match *self {
            Kinematics::Axisymmetric => 2.0 * std::f64::consts::PI * r_ref,
            Kinematics::PlaneStrain { thickness } => thickness,
        }
    }

    /// Out-of-plane stretch `F22` and its derivative with respect to the
    /// in-plane displacement component 0 at a point with interpolated
    /// reference coordinate `r_ref` and displacement `u_r`:
    /// returns `(F22, dF22/du_r)`; multiply the latter by the shape function.
    pub fn out_of_plane(&self, r_ref: f64, u_r: f64) -> (f64, f64) {
        match *self {
            Kinematics::Axisymmetric => (1.0 + u_r / r_ref, 1.0 / r_ref),
            Kinematics::PlaneStrain { .. } => (1.0, 0.0),
        }
    }
}

/// `J = det F` of the 5-component gradient `[F00, F01, F10, F11, F22]`, its
/// gradient and its (constant-pattern) Hessian.
pub fn jacobian_derivs(f: &[f64; 5]) -> (f64, [f64; 5], [[f64; 5]; 5]) {
    let [f00, f01, f10, f11, f22] = *f;
    let det2 = f00 * f11 - f01 * f10;
    let j = det2 * f22;
    let g = [f11 * f22, -f10 * f22, -f01 * f22, f00 * f22, det2];
    let mut h = [[0.0; 5]; 5];
    let mut set = |a: usize, b: usize, v: f64| {
        h[a][b] = v;
        h[b][a] = v;
    };
    set(0, 3, f22);
    set(1, 2, -f22);
    set(0, 4, f11);
    set(3, 4, f00);
    set(1, 4, -f10);
    set(2, 4, -f01);
    (j, g, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobian_derivatives_match_finite_differences() {
        let f = [1.1, 0.2, -0.3, 0.9, 1.05];
        let (j, g, h) = jacobian_derivs(&f);
        assert!((j - (1.1 * 0.9 + 0.06) * 1.05).abs() < 1e-14);
        let eps = 1e-6;
        for k in 0..5 {
            let (mut fp, mut fm) = (f, f);
            fp[k] += eps;
            fm[k] -= eps;
            let (jp, gp, _) = jacobian_derivs(&fp);
            let (jm, gm, _) = jacobian_derivs(&fm);
            assert!(((jp - jm) / (2.0 * eps) - g[k]).abs() < 1e-8);
            for l in 0..5 {
                assert!(((gp[l] - gm[l]) / (2.0 * eps) - h[l][k]).abs() < 1e-8);
            }
        }
    }
}
