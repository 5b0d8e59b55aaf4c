//! Drucker stability of the incompressible material, as Abaqus' "evaluate" reports it.
//!
//! # Definition
//!
//! For an incompressible principal state with Cauchy stresses `sigma_i = l_i dW/dl_i - p` and log
//! strains `e_i = ln l_i` (`e_3 = -e_1 - e_2`), the material is Drucker stable when the 2x2 matrix
//! `D_ab = d(sigma_a - sigma_3)/d e_b` (`a, b in {1, 2}`, the pressure eliminated) is positive
//! definite (Abaqus Analysis User's Guide, "Hyperelastic behavior of rubberlike materials",
//! stability; Drucker 1959: `d sigma : d e > 0`). With `tau_a = l_a W_a` and
//! `H_ab = d tau_a / d e_b = l_a l_b W_ab + delta_ab l_a W_a` (all `e` independent),
//! `D_ab = H_ab - H_a3 - H_3b + H_33`, which is symmetric.
//!
//! Along each mode path (uniaxial `(s, s^-1/2, s^-1/2)`, equibiaxial `(s, s, s^-2)`, planar
//! `(s, 1, 1/s)`) [`drucker`] scans `s` in `[0.1, 10]` outwards from 1 on a log grid of
//! 2000 steps per decade, then bisects (in `ln s`) each edge where stability is first lost.

use serde::{Deserialize, Serialize};

use crate::Law;

/// Contiguous stretch range around 1 within `[0.1, 10]` where the mode is stable.
/// `lower == upper == 1` when the material is unstable already at rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StableRange {
    /// Smallest stable stretch (0.1 when stable down to there).
    pub lower: f64,
    /// Largest stable stretch (10 when stable up to there).
    pub upper: f64,
}

impl StableRange {
    /// True when `stretch` lies inside the range.
    pub fn contains(&self, stretch: f64) -> bool {
        self.lower <= stretch && stretch <= self.upper
    }
}

/// Stable ranges of the three classical modes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DruckerReport {
    /// Uniaxial tension/compression (`s` is the axial stretch).
    pub uniaxial: StableRange,
    /// Equibiaxial tension/compression (`s` is the in-plane stretch).
    pub biaxial: StableRange,
    /// Planar tension/compression (`s` is the stretch in the loaded direction).
    pub planar: StableRange,
}

/// The deformation modes scanned by [`drucker`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Mode {
    /// `(s, s^-1/2, s^-1/2)`.
    Uniaxial,
    /// `(s, s, s^-2)`.
    Biaxial,
    /// `(s, 1, 1/s)`.
    Planar,
}

impl Mode {
    /// Principal stretches of the mode at stretch `s`.
    pub fn stretches(&self, s: f64) -> [f64; 3] {
        match self {
            Mode::Uniaxial => [s, 1.0 / s.sqrt(), 1.0 / s.sqrt()],
            Mode::Biaxial => [s, s, 1.0 / (s * s)],
            Mode::Planar => [s, 1.0, 1.0 / s],
        }
    }
}

/// The Drucker matrix `D_ab = H_ab - H_a3 - H_3b + H_33` at incompressible stretches `lam` (module doc).
pub fn drucker_matrix(law: &Law, p: &[f64], lam: [f64; 3]) -> [[f64; 2]; 2] {
    let d = law.isochoric_principal(p, lam);
    let mut h = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            h[a][b] = lam[a] * lam[b] * 0.5 * (d.d2w[a][b] + d.d2w[b][a]);
        }
        h[a][a] += lam[a] * d.dw[a];
    }
    let mut dm = [[0.0; 2]; 2];
    for a in 0..2 {
        for b in 0..2 {
            dm[a][b] = h[a][b] - h[a][2] - h[2][b] + h[2][2];
        }
    }
    dm
}

/// True when [`drucker_matrix`] is positive definite (`D_11 > 0` and `det D > 0`).
///
/// The determinant is taken of the matrix divided by its largest entry, so that a stiff law
/// (an exponential at large `I1`, entries beyond `1e154`) does not overflow it; a NaN entry
/// (a law outside its domain, Gent beyond `Jm`) is unstable.
pub fn is_stable(law: &Law, p: &[f64], lam: [f64; 3]) -> bool {
    let d = drucker_matrix(law, p, lam);
    let scale = d.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(scale > 0.0 && scale.is_finite()) {
        return false;
    }
    let e = d.map(|row| row.map(|v| v / scale));
    e[0][0] > 0.0 && e[0][0] * e[1][1] - e[0][1] * e[1][0] > 0.0
}

/// Grid steps per decade of the scan.
const STEPS_PER_DECADE: usize = 2000;
/// Bisection steps on `ln s` at an edge (interval `ln 10 / 2000 / 2^50`).
const BISECTIONS: usize = 50;

/// Edge of the stable range from `s = 1` towards `end` (0.1 or 10).
fn edge(law: &Law, p: &[f64], mode: Mode, end: f64) -> f64 {
    let stable = |x: f64| is_stable(law, p, mode.stretches(x.exp()));
    let x_end = end.ln();
    let mut last_stable = 0.0;
    for k in 1..=STEPS_PER_DECADE {
        let x = x_end * k as f64 / STEPS_PER_DECADE as f64;
        if !stable(x) {
            let (mut good, mut bad) = (last_stable, x);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (good + bad);
                if stable(mid) {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            return good.exp();
        }
        last_stable = x;
    }
    end
}

fn range(law: &Law, p: &[f64], mode: Mode) -> StableRange {
    if !is_stable(law, p, [1.0; 3]) {
        return StableRange {
            lower: 1.0,
            upper: 1.0,
        };
    }
    StableRange {
        lower: edge(law, p, mode, 0.1),
        upper: edge(law, p, mode, 10.0),
    }
}

/// Drucker-stable stretch ranges of the uniaxial, equibiaxial and planar modes (module doc).
pub fn drucker(law: &Law, p: &[f64]) -> DruckerReport {
    DruckerReport {
        uniaxial: range(law, p, Mode::Uniaxial),
        biaxial: range(law, p, Mode::Biaxial),
        planar: range(law, p, Mode::Planar),
    }
}
