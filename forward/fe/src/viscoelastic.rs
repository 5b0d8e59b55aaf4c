//! Prony-series viscoelasticity at the integration point, around any
//! [`PointMaterial`] as its elastic part.
//!
//! The viscoelastic isochoric second Piola-Kirchhoff stress is the
//! hereditary integral of the elastic one with the reduced relaxation
//! function of docs/benchmarks.md Q1 (and of the force-level QLV wrapper,
//! `palpate_enrich::Viscoelastic`):
//!
//! ```text
//! S(t) = int_0^t G(t - s) dS_e/ds ds,   G(t) = g_inf + sum_i g_i exp(-t / tau_i),
//! g_inf = 1 - sum_i g_i,                S_e = F^-1 P_e,
//! ```
//!
//! so `S = S_e` for an instantaneous load from rest (G(0) = 1) and
//! `S = g_inf S_e` once relaxed. With internal variables
//! `h_i = g_i int exp(-(t - s) / tau_i) dS_e`, `S = g_inf S_e + sum_i h_i`
//! and, for `S_e` linear in time over a step `dt` (Taylor, Pister &
//! Goudreau 1970; Simo & Hughes, *Computational Inelasticity*, 1998, 10.3.2;
//! Holzapfel, *Nonlinear Solid Mechanics*, 2000, 6.10), exactly
//!
//! ```text
//! h_i(n+1) = e_i h_i(n) + g_i phi_i (S_e(n+1) - S_e(n)),
//! e_i = exp(-dt / tau_i),  phi_i = (1 - e_i) / (dt / tau_i)   (phi_i = 1 at dt = 0),
//! ```
//!
//! the update of the wrapper's `qlv_convolve` applied to each component of
//! `S_e` instead of the force. (The brief's form `S = S_e + sum h_i` is this
//! one with the long-term response as `S_e`; the form here keeps `G(0) = 1`,
//! the wrapper's and Abaqus' normalisation by the instantaneous response,
//! and allows `g_inf = 0` without dividing by it.)
//!
//! Why the second Piola-Kirchhoff stress: it is a material tensor, so the
//! integral of its increments is objective (a rigid rotation changes
//! neither `S_e` nor the history), and it is the measure of Holzapfel's and
//! Simo's finite-strain models. The first Piola stress would rotate with
//! the body; the Cauchy stress would need an objective rate. The
//! volumetric part (the element's pressure or penalty) stays elastic.
//!
//! The stress after a step is `S = c S_e(F) + H` with
//! `c = g_inf + sum g_i phi_i` and `H = sum_i (e_i h_i(n) - g_i phi_i S_e(n))`
//! fixed by the committed history and `dt`, hence `P = F S = c P_e + F H`
//! and the consistent tangent `A_iJkL = c A_e,iJkL + delta_ik H_LJ` exactly.
//!
//! Not the same model as QLV on the force: for uniaxial compression the
//! nominal stress `lambda S_zz - lambda^-2 S_rr` (pressure eliminated by the
//! free lateral surface) is not the hereditary integral of the elastic
//! nominal stress at finite strain, because the pressure multiplies the
//! current `C^-1`; the difference, relative to the viscous part, is of
//! second order in the strain (1.4e-2 at 20 % compression; see
//! `tests/integration/c1_viscoelastic.rs`).

use nalgebra::Matrix3;

use crate::material::{PointMaterial, StressTangent9};
use crate::FeError;

/// Symmetric 3 x 3 components stored in the history: 00, 11, 22, 01, 12, 02.
const SYM: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)];

fn to_sym(s: &Matrix3<f64>, out: &mut [f64]) {
    for (k, &(i, j)) in SYM.iter().enumerate() {
        out[k] = 0.5 * (s[(i, j)] + s[(j, i)]);
    }
}

fn from_sym(v: &[f64]) -> Matrix3<f64> {
    let mut s = Matrix3::zeros();
    for (k, &(i, j)) in SYM.iter().enumerate() {
        s[(i, j)] = v[k];
        s[(j, i)] = v[k];
    }
    s
}

/// A Prony series `G(t) = 1 - sum_i g_i (1 - exp(-t / tau_i))`: relative
/// moduli `g_i >= 0` with `sum g_i < 1` and relaxation times `tau_i > 0` (s).
#[derive(Debug, Clone, PartialEq)]
pub struct Prony {
    terms: Vec<(f64, f64)>,
}

impl Prony {
    /// The series of `(g_i, tau_i)`; an error names the first bad term.
    pub fn new(terms: Vec<(f64, f64)>) -> Result<Self, FeError> {
        let bad = |field: String, reason: String| FeError::InvalidConfig { field, reason };
        if terms.is_empty() {
            return Err(bad("prony".into(), "needs at least one term".into()));
        }
        for (i, &(g, tau)) in terms.iter().enumerate() {
            if !(g >= 0.0 && g.is_finite()) {
                return Err(bad(format!("g{}", i + 1), format!("{g} must be >= 0")));
            }
            if !(tau > 0.0 && tau.is_finite()) {
                return Err(bad(
                    format!("tau{}", i + 1),
                    format!("{tau} s: a relaxation time must be positive and finite"),
                ));
            }
        }
        let sum: f64 = terms.iter().map(|t| t.0).sum();
        if !(sum < 1.0) {
            return Err(bad(
                "prony".into(),
                format!("the weights sum to {sum}; they must sum to less than 1"),
            ));
        }
        Ok(Prony { terms })
    }

    /// The terms `(g_i, tau_i)`.
    pub fn terms(&self) -> &[(f64, f64)] {
        &self.terms
    }

    /// `[g1, tau1, g2, tau2, ...]`, the wrapper's parameter order.
    pub fn flat(&self) -> Vec<f64> {
        self.terms.iter().flat_map(|&(g, t)| [g, t]).collect()
    }

    /// The long-term relative modulus `g_inf = 1 - sum g_i`.
    pub fn g_inf(&self) -> f64 {
        1.0 - self.terms.iter().map(|t| t.0).sum::<f64>()
    }

    /// `G(t)`.
    pub fn relaxation(&self, t: f64) -> f64 {
        self.g_inf()
            + self
                .terms
                .iter()
                .map(|&(g, tau)| g * (-t / tau).exp())
                .sum::<f64>()
    }

    /// The shortest relaxation time (s).
    pub fn shortest_time(&self) -> f64 {
        self.terms.iter().map(|t| t.1).fold(f64::INFINITY, f64::min)
    }

    /// `(e_i, phi_i)` of term `i` over a step `dt` (`dt = inf`: (0, 0)).
    fn factors(tau: f64, dt: f64) -> (f64, f64) {
        let x = dt / tau;
        if x > 0.0 {
            ((-x).exp(), -(-x).exp_m1() / x)
        } else {
            (1.0, 1.0)
        }
    }
}

impl std::str::FromStr for Prony {
    type Err = FeError;
    /// `g1=0.3,tau1=0.5,g2=0.2,tau2=10` (terms numbered from 1, every `g`
    /// with its `tau`, any order).
    fn from_str(s: &str) -> Result<Self, FeError> {
        let bad = |reason: String| FeError::InvalidConfig {
            field: "prony".into(),
            reason,
        };
        let mut g: Vec<Option<f64>> = Vec::new();
        let mut tau: Vec<Option<f64>> = Vec::new();
        for item in s.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (key, value) = item
                .split_once('=')
                .ok_or_else(|| bad(format!("`{item}` is not name=value")))?;
            let value: f64 = value
                .trim()
                .parse()
                .map_err(|_| bad(format!("`{item}`: not a number")))?;
            let key = key.trim();
            let (list, index) = if let Some(i) = key.strip_prefix("tau") {
                (&mut tau, i)
            } else if let Some(i) = key.strip_prefix('g') {
                (&mut g, i)
            } else {
                return Err(bad(format!("`{key}`: expected g<i> or tau<i>")));
            };
            let i: usize = index
                .parse()
                .ok()
                .filter(|&i| i >= 1)
                .ok_or_else(|| bad(format!("`{key}`: terms are numbered from 1")))?;
            if list.len() < i {
                list.resize(i, None);
            }
            if list[i - 1].replace(value).is_some() {
                return Err(bad(format!("`{key}` given twice")));
            }
        }
        let n = g.len().max(tau.len());
        let mut terms = Vec::with_capacity(n);
        for i in 0..n {
            match (g.get(i).copied().flatten(), tau.get(i).copied().flatten()) {
                (Some(gi), Some(ti)) => terms.push((gi, ti)),
                _ => {
                    return Err(bad(format!(
                        "term {} needs both g{} and tau{}",
                        i + 1,
                        i + 1,
                        i + 1
                    )))
                }
            }
        }
        Prony::new(terms)
    }
}

impl std::fmt::Display for Prony {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, (g, tau)) in self.terms.iter().enumerate() {
            if i > 0 {
                write!(f, ",")?;
            }
            write!(f, "g{}={g},tau{}={tau}", i + 1, i + 1)?;
        }
        Ok(())
    }
}

/// The elastic material `M` with a Prony series on its isochoric second
/// Piola-Kirchhoff stress (module documentation). History per point:
/// `h_1, ..., h_M, S_e(n)`, six symmetric components each; zero is the
/// stress-free reference at rest.
#[derive(Debug, Clone, PartialEq)]
pub struct Viscoelastic<M> {
    pub elastic: M,
    pub prony: Prony,
}

impl<M: PointMaterial> Viscoelastic<M> {
    pub fn new(elastic: M, prony: Prony) -> Self {
        Viscoelastic { elastic, prony }
    }

    /// `c` and `H` of `S = c S_e(F) + H` after a step `dt` from `old`.
    fn split(&self, dt: f64, old: &[f64]) -> (f64, Matrix3<f64>) {
        let m = self.prony.terms.len();
        let se_old = from_sym(&old[6 * m..6 * m + 6]);
        let mut c = self.prony.g_inf();
        let mut h = Matrix3::zeros();
        for (i, &(g, tau)) in self.prony.terms.iter().enumerate() {
            let (e, phi) = Prony::factors(tau, dt);
            c += g * phi;
            h += e * from_sym(&old[6 * i..6 * i + 6]) - (g * phi) * se_old;
        }
        (c, h)
    }
}

impl<M: PointMaterial> PointMaterial for Viscoelastic<M> {
    /// The instantaneous (elastic) response from rest.
    fn iso_stress_tangent(&self, f: &Matrix3<f64>) -> StressTangent9 {
        self.elastic.iso_stress_tangent(f)
    }
    fn history_len(&self) -> usize {
        6 * (self.prony.terms.len() + 1)
    }
    fn stress_tangent_with_history(
        &self,
        f: &Matrix3<f64>,
        dt: f64,
        old: &[f64],
    ) -> StressTangent9 {
        let (pe, ae) = self.elastic.iso_stress_tangent(f);
        let (c, h) = self.split(dt, old);
        let p = c * pe + f * h;
        let mut a = c * ae;
        for i in 0..3 {
            for jj in 0..3 {
                for l in 0..3 {
                    a[(3 * i + jj, 3 * i + l)] += h[(l, jj)];
                }
            }
        }
        (p, a)
    }
    fn update_history(&self, f: &Matrix3<f64>, dt: f64, old: &[f64], new: &mut [f64]) {
        let m = self.prony.terms.len();
        let (pe, _) = self.elastic.iso_stress_tangent(f);
        let se = f.try_inverse().unwrap_or_else(Matrix3::zeros) * pe;
        let se_old = from_sym(&old[6 * m..6 * m + 6]);
        for (i, &(g, tau)) in self.prony.terms.iter().enumerate() {
            let (e, phi) = Prony::factors(tau, dt);
            let hi = e * from_sym(&old[6 * i..6 * i + 6]) + (g * phi) * (se - se_old);
            to_sym(&hi, &mut new[6 * i..6 * i + 6]);
        }
        to_sym(&se, &mut new[6 * m..6 * m + 6]);
    }
    fn shear_modulus(&self) -> f64 {
        self.elastic.shear_modulus()
    }
}

/// `P = F S` of the isochoric viscoelastic stress for a history (tests).
#[cfg(test)]
fn stress_of(
    m: &Viscoelastic<impl PointMaterial>,
    f: &Matrix3<f64>,
    history: &[f64],
) -> Matrix3<f64> {
    let k = m.prony.terms.len();
    let mut s = m.prony.g_inf() * from_sym(&history[6 * k..6 * k + 6]);
    for i in 0..k {
        s += from_sym(&history[6 * i..6 * i + 6]);
    }
    f * s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::LawMaterial;

    fn material() -> Viscoelastic<LawMaterial> {
        Viscoelastic::new(
            LawMaterial::new("mooney-rivlin".parse().unwrap(), vec![0.3, 0.1]).unwrap(),
            Prony::new(vec![(0.3, 0.5), (0.2, 10.0)]).unwrap(),
        )
    }

    fn f1() -> Matrix3<f64> {
        Matrix3::new(1.1, 0.2, 0.0, -0.1, 0.9, 0.05, 0.0, 0.03, 1.05)
    }

    /// A history after two steps from rest, so every part of `H` is non-zero.
    fn history(m: &Viscoelastic<LawMaterial>) -> Vec<f64> {
        let n = m.history_len();
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        let f0 = Matrix3::new(0.95, 0.1, 0.0, 0.05, 1.08, 0.0, 0.0, 0.0, 0.97);
        m.update_history(&f0, 0.2, &a, &mut b);
        m.update_history(&f1(), 0.3, &b, &mut a);
        a
    }

    #[test]
    fn tangent_matches_finite_differences_at_fixed_history_and_dt() {
        let m = material();
        let old = history(&m);
        let f = Matrix3::new(1.2, 0.15, 0.02, -0.05, 0.85, 0.04, 0.01, 0.02, 1.1);
        for dt in [0.0, 0.07, 1.5, 40.0] {
            let (_, a) = m.stress_tangent_with_history(&f, dt, &old);
            let h = 1e-6;
            let scale = a.abs().max();
            for k in 0..9 {
                let (mut fp, mut fm) = (f, f);
                fp[(k / 3, k % 3)] += h;
                fm[(k / 3, k % 3)] -= h;
                let dp = (m.stress_tangent_with_history(&fp, dt, &old).0
                    - m.stress_tangent_with_history(&fm, dt, &old).0)
                    / (2.0 * h);
                for i in 0..9 {
                    let d = dp[(i / 3, i % 3)] - a[(i, k)];
                    assert!(d.abs() < 1e-7 * scale, "dt {dt}: A[{i}][{k}] off by {d}");
                }
            }
        }
    }

    /// The stress of a step is the stress of the history it leaves behind.
    #[test]
    fn stress_is_that_of_the_updated_history() {
        let m = material();
        let old = history(&m);
        let f = Matrix3::new(1.15, 0.1, 0.0, 0.0, 0.9, 0.02, 0.0, 0.0, 0.98);
        let mut new = vec![0.0; m.history_len()];
        for dt in [0.0, 0.3, 7.0] {
            m.update_history(&f, dt, &old, &mut new);
            let p = m.stress_tangent_with_history(&f, dt, &old).0;
            let d = (p - stress_of(&m, &f, &new)).norm();
            assert!(d < 1e-13 * p.norm(), "dt {dt}: {d}");
        }
    }

    /// From rest, an instantaneous step (dt = 0) gives the elastic
    /// response; an infinitely slow one (dt = inf) the relaxed response
    /// `g_inf P_e`; and a step held for t relaxes as `G(t)`.
    #[test]
    fn instantaneous_relaxed_and_held_limits() {
        let m = material();
        let rest = vec![0.0; m.history_len()];
        let f = f1();
        let pe = m.elastic.iso_stress_tangent(&f).0;
        let p0 = m.stress_tangent_with_history(&f, 0.0, &rest).0;
        assert!((p0 - pe).norm() < 1e-14 * pe.norm());
        let pinf = m.stress_tangent_with_history(&f, f64::INFINITY, &rest).0;
        assert!((pinf - 0.5 * pe).norm() < 1e-14 * pe.norm());
        let mut h = vec![0.0; m.history_len()];
        m.update_history(&f, 0.0, &rest, &mut h);
        // held at f: S_e does not change, h decays exactly over any steps
        let mut t = 0.0;
        for dt in [0.1, 0.25, 1.0, 3.0] {
            let p = m.stress_tangent_with_history(&f, dt, &h).0;
            t += dt;
            let g = m.prony.relaxation(t);
            assert!((p - g * pe).norm() < 1e-13 * pe.norm(), "t {t}");
            let old = h.clone();
            m.update_history(&f, dt, &old, &mut h);
        }
    }

    /// Rotating the body rotates P and leaves S and the history unchanged.
    #[test]
    fn objective() {
        let m = material();
        let old = history(&m);
        let f = f1();
        let (a, b) = (0.4f64, -0.7f64);
        let q = Matrix3::new(a.cos(), -a.sin(), 0.0, a.sin(), a.cos(), 0.0, 0.0, 0.0, 1.0)
            * Matrix3::new(1.0, 0.0, 0.0, 0.0, b.cos(), -b.sin(), 0.0, b.sin(), b.cos());
        let p = m.stress_tangent_with_history(&f, 0.4, &old).0;
        let pq = m.stress_tangent_with_history(&(q * f), 0.4, &old).0;
        assert!((q * p - pq).norm() < 1e-12 * p.norm());
        let (mut h1, mut h2) = (vec![0.0; old.len()], vec![0.0; old.len()]);
        m.update_history(&f, 0.4, &old, &mut h1);
        m.update_history(&(q * f), 0.4, &old, &mut h2);
        for (x, y) in h1.iter().zip(&h2) {
            assert!((x - y).abs() < 1e-12, "{x} {y}");
        }
    }

    #[test]
    fn prony_parses_and_refuses_bad_series() {
        let p: Prony = "g1=0.3, tau1=0.5,tau2=10,g2=0.2".parse().unwrap();
        assert_eq!(p.terms(), &[(0.3, 0.5), (0.2, 10.0)]);
        assert_eq!(p.to_string().parse::<Prony>().unwrap(), p);
        assert_eq!(p.flat(), vec![0.3, 0.5, 0.2, 10.0]);
        assert!((p.g_inf() - 0.5).abs() < 1e-15);
        assert_eq!(p.shortest_time(), 0.5);
        for (bad, says) in [
            ("g1=0.6,tau1=1,g2=0.4,tau2=2", "sum to 1"),
            ("g1=0.3,tau1=0", "tau1"),
            ("g1=0.3,tau1=-2", "positive"),
            ("g1=-0.1,tau1=1", "g1"),
            ("g1=0.3", "needs both g1 and tau1"),
            ("g1=0.3,tau1=1,g3=0.1,tau3=2", "term 2"),
            ("g1=0.3,tau1=x", "not a number"),
            ("k1=0.3", "expected g<i>"),
            ("g0=0.3,tau0=1", "numbered from 1"),
            ("g1=0.3,g1=0.2,tau1=1", "twice"),
            ("", "at least one term"),
        ] {
            let err = bad.parse::<Prony>().unwrap_err().to_string();
            assert!(err.contains(says), "{bad}: {err}");
        }
    }
}
