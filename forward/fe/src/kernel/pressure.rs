//! The pressure field of a mixed element: piecewise constant (P0) or
//! discontinuous linear (P1) per cell, or none (plane stress).
//!
//! With the decoupled energy `Psi(F) = W(J^{-1/3} F) + U(J)` the three-field
//! (Hu-Washizu) functional with pressure and dilatation in the same space
//! `span{psi_m}` condenses to
//!
//! ```text
//! Pi_e(u)    = int W_iso dV + int U(theta) dV,   theta = psi . M^{-1} v      (penalty)
//! Pi_e(u, q) = int W_iso dV + s q . (v - V)                                  (exact)
//! ```
//!
//! with `M_mn = int psi_m psi_n dV`, `v_m = int psi_m J dV`,
//! `V_m = int psi_m dV` (Simo, Taylor & Pister 1985, CMAME 51:177; for P0
//! this is the mean-dilatation element of Nagtegaal, Parks & Rice 1974; for
//! Q2/P1, Sussman & Bathe 1987, Computers & Structures 26:357). P1 uses
//! the *unmapped* linear functions of the reference coordinates
//! `(1, (X - X_c)/h, (Y - Y_c)/h[, (Z - Z_c)/h])`, which keep the optimal
//! convergence order on distorted meshes (Boffi, Brezzi & Fortin,
//! *Mixed Finite Element Methods*, 2013, 8.6.3).

use serde::{Deserialize, Serialize};

/// The pressure space of a mixed element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PressureSpace {
    /// No pressure field (plane stress).
    None,
    /// One constant per cell.
    P0,
    /// Discontinuous linear: 3 functions per cell in 2D, 4 in 3D.
    P1,
}

impl PressureSpace {
    /// Number of pressure functions per cell in `dim` dimensions.
    pub fn len(&self, dim: usize) -> usize {
        match self {
            PressureSpace::None => 0,
            PressureSpace::P0 => 1,
            PressureSpace::P1 => dim + 1,
        }
    }

    /// The functions at reference point `x` of a cell with centroid `c` and
    /// size `h` (only the first [`PressureSpace::len`] entries are used).
    pub fn eval(&self, dim: usize, x: &[f64; 3], c: &[f64; 3], h: f64) -> [f64; 4] {
        let mut psi = [0.0; 4];
        match self {
            PressureSpace::None => {}
            PressureSpace::P0 => psi[0] = 1.0,
            PressureSpace::P1 => {
                psi[0] = 1.0;
                for i in 0..dim {
                    psi[i + 1] = (x[i] - c[i]) / h;
                }
            }
        }
        psi
    }
}
