//! The discretisation error of an FE force curve from one coarser solve:
//! Richardson extrapolation with an order of convergence the model states
//! (and where that order comes from).
//!
//! With forces `F_h` on a mesh and `F_rh` on a mesh whose elements are `r`
//! times larger, and error `F_h - F ~ C h^p`,
//!
//! ```text
//! F ~ F_h + (F_h - F_rh) / (r^p - 1),    error of F_h = F_h - F = (F_rh - F_h) / (r^p - 1).
//! ```
//!
//! Two meshes cannot observe `p`; the models take it from their documented
//! convergence studies ([`ConvergenceOrder`], e.g. [`crate::N1Setup::convergence_order`]).
//! [`observed_order`] is the three-mesh order those studies report.
//!
//! Used by `palpate simulate` only: a model's `predict` stays one solve.

use crate::FeError;

/// An order of convergence of a model's force with the element size, and
/// where it was measured.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceOrder {
    pub order: f64,
    /// The study that measured it (document, section, case).
    pub source: String,
}

/// A coarser companion of a model for the error estimate: the model on a
/// mesh with elements `ratio` times larger.
#[derive(Debug, Clone, PartialEq)]
pub struct Coarser<M> {
    pub model: M,
    /// Element size ratio h_coarse / h_fine (> 1).
    pub ratio: f64,
    /// The coarse mesh in words (e.g. `10x5 elements`).
    pub mesh: String,
}

/// The estimate at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorEstimate {
    /// The extrapolated (converged) force.
    pub converged: f64,
    /// Error of the fine solution: fine - converged.
    pub error: f64,
    /// `error / converged`; `None` where the force is ~0 (below 1e-6 of the
    /// largest force of the curve: round-off, such as the unloaded first
    /// sample, where the error is set to 0).
    pub relative: Option<f64>,
}

/// Two meshes whose forces differ by at most this fraction agree to solver
/// round-off (Newton tolerance), and the error is reported as zero rather
/// than an amplified noise.
pub const AGREEMENT: f64 = 1e-8;

/// Richardson estimates per sample from `fine` and `coarse` forces (same
/// samples; `coarse` may be shorter when the coarse solve stopped early:
/// the estimates cover the samples both have), element-size ratio `ratio`
/// (> 1) and order `order` (> 0).
pub fn richardson(
    fine: &[f64],
    coarse: &[f64],
    ratio: f64,
    order: f64,
) -> Result<Vec<ErrorEstimate>, FeError> {
    let bad = |field: &str, reason: String| FeError::InvalidConfig {
        field: field.into(),
        reason,
    };
    if !(ratio > 1.0 && ratio.is_finite()) {
        return Err(bad("ratio", format!("{ratio}: must be > 1")));
    }
    if !(order > 0.0 && order.is_finite()) {
        return Err(bad("order", format!("{order}: must be > 0")));
    }
    if coarse.len() > fine.len() {
        return Err(bad(
            "coarse",
            format!("{} samples for {} fine ones", coarse.len(), fine.len()),
        ));
    }
    if let Some(x) = fine.iter().chain(coarse).find(|x| !x.is_finite()) {
        return Err(bad("forces", format!("{x} is not finite")));
    }
    let scale = fine.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    let factor = ratio.powf(order) - 1.0;
    Ok(fine
        .iter()
        .zip(coarse)
        .map(|(&f, &c)| {
            let delta = c - f;
            let zero = f.abs() <= 1e-6 * scale;
            let error = if zero || delta.abs() <= AGREEMENT * f.abs().max(c.abs()) {
                0.0
            } else {
                delta / factor
            };
            let converged = f - error;
            let relative = (!zero && converged != 0.0).then(|| error / converged);
            ErrorEstimate {
                converged,
                error,
                relative,
            }
        })
        .collect())
}

/// The observed order from three meshes with a constant element-size ratio
/// `ratio` (forces from coarse to fine): `log((F1 - F2) / (F2 - F3)) / log r`;
/// `None` when the differences do not shrink monotonically.
pub fn observed_order(coarse: f64, medium: f64, fine: f64, ratio: f64) -> Option<f64> {
    let q = (coarse - medium) / (medium - fine);
    (q > 1.0 && q.is_finite() && ratio > 1.0).then(|| q.ln() / ratio.ln())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// F(h) = F* + C h^p: the estimate recovers F* exactly for the true p.
    #[test]
    fn a_manufactured_sequence_of_known_order_is_extrapolated_exactly() {
        for p in [0.58, 1.0, 1.22, 2.0] {
            for r in [2.0, 1.5, 1.849] {
                let exact: Vec<f64> = (0..5).map(|k| 3.0 + 0.7 * k as f64).collect();
                let c = [0.0, 0.2, -0.4, 1.1, 0.9];
                let h = 0.3;
                let f = |hh: f64| -> Vec<f64> {
                    exact
                        .iter()
                        .zip(&c)
                        .map(|(e, c)| e + c * hh.powf(p))
                        .collect()
                };
                let (fine, coarse) = (f(h), f(r * h));
                let est = richardson(&fine, &coarse, r, p).unwrap();
                for k in 0..5 {
                    assert!(
                        (est[k].converged - exact[k]).abs() < 1e-12,
                        "p {p} r {r} k {k}: {:?} vs {}",
                        est[k],
                        exact[k]
                    );
                    let e = c[k] * h.powf(p);
                    assert!((est[k].error - e).abs() < 1e-12);
                    assert!((est[k].relative.unwrap() - e / exact[k]).abs() < 1e-12);
                }
                let order = observed_order(f(r * r * h)[4], f(r * h)[4], f(h)[4], r).unwrap();
                assert!((order - p).abs() < 1e-9, "{order} vs {p}");
            }
        }
    }

    /// The C1 bonded order stated by `C1Fe::convergence_order` from its
    /// three meshes.
    #[test]
    fn the_c1_bonded_order_from_its_three_meshes() {
        let p = observed_order(29.81, 29.09, 28.61, 2.0).unwrap();
        assert!((p - 0.585).abs() < 1e-3, "{p}");
    }

    #[test]
    fn agreement_to_round_off_and_zero_force_are_guarded() {
        // Meshes agreeing to 1e-12 (C1 frictionless: exact on any mesh).
        let fine = [-4e-14, 1.0, 2.0];
        let coarse = [3e-14, 1.0 + 1e-12, 2.0 - 3e-12];
        let est = richardson(&fine, &coarse, 2.0, 0.58).unwrap();
        for (e, f) in est.iter().zip(&fine) {
            assert_eq!(e.error, 0.0);
            assert_eq!(e.converged, *f);
        }
        assert_eq!(
            richardson(&fine, &[0.0, 1.1, 2.2], 2.0, 1.0).unwrap()[0].error,
            0.0
        );
        assert_eq!(est[0].relative, None, "no relative error at zero force");
        assert_eq!(est[1].relative, Some(0.0));
        // A shorter coarse curve (stopped early) covers its samples only.
        let est = richardson(&fine, &coarse[..2], 2.0, 1.0).unwrap();
        assert_eq!(est.len(), 2);
    }

    #[test]
    fn bad_inputs_are_named() {
        let e = |r, p, c: &[f64]| richardson(&[1.0, 2.0], c, r, p).unwrap_err().to_string();
        assert!(e(1.0, 1.0, &[1.0, 2.0]).contains("ratio"));
        assert!(e(2.0, 0.0, &[1.0, 2.0]).contains("order"));
        assert!(e(2.0, f64::NAN, &[1.0, 2.0]).contains("order"));
        assert!(e(2.0, 1.0, &[1.0, 2.0, 3.0]).contains("coarse"));
        assert!(e(2.0, 1.0, &[1.0, f64::NAN]).contains("forces"));
        assert_eq!(observed_order(1.0, 2.0, 3.0, 2.0), None, "not converging");
        assert_eq!(observed_order(3.0, 2.0, 1.5, 1.0), None, "ratio 1");
    }

    #[test]
    fn the_models_coarser_companions() {
        use crate::{C1Fe, MeshDensity, N1Needle, Platens};
        let law: palpate_material::Law = "neo-hookean".parse().unwrap();
        let mut c1 = C1Fe::new(law, Platens::Bonded);
        c1.elements = (38, 18);
        let c = c1.coarser().unwrap();
        assert_eq!(
            (c.model.elements, c.ratio, c.mesh.as_str()),
            ((19, 9), 2.0, "19x9")
        );
        c1.elements = (19, 9);
        let c = c1.coarser().unwrap();
        assert_eq!(c.model.elements, (10, 5));
        assert!((c.ratio - (171.0f64 / 50.0).sqrt()).abs() < 1e-15);
        c1.elements = (1, 1);
        assert!(c1.coarser().is_err());
        assert_eq!(c1.convergence_order().order, 0.58);

        let mut n1 = N1Needle::new(law);
        let level1 = MeshDensity::COARSE.grading(n1.fine_zone);
        let g = n1.coarser().model.grading.unwrap();
        assert!((g.h_fine - level1.h_fine).abs() < 1e-15);
        assert!((g.growth - level1.growth).abs() < 1e-15);
        assert_eq!(g.fine_length, level1.fine_length);
        // Level 1 has no coarser level: its elements doubled.
        n1.mesh = MeshDensity::COARSE;
        let c = n1.coarser();
        let g = c.model.grading.unwrap();
        assert!((g.h_fine - 0.8).abs() < 1e-15 && (g.growth - 1.4).abs() < 1e-15);
        assert_eq!(c.ratio, 2.0);
        assert_eq!(c.mesh, "0.8 mm elements under the tool, growth 1.4");
        assert!(!n1.convergence_order().source.contains("not for this tool"));
        n1.tool = crate::ToolShape::Sphere { radius: 2.5 };
        assert!(n1.convergence_order().source.contains("not for this tool"));
    }

    /// Frictionless C1 is exact on any mesh: the estimate is zero.
    #[test]
    fn frictionless_c1_has_no_discretisation_error() {
        use crate::{C1Fe, Platens};
        use palpate_core::{Drive, ForwardModel, Loading};
        let mut m = C1Fe::new("neo-hookean".parse().unwrap(), Platens::Frictionless);
        m.elements = (4, 2);
        let c = m.coarser().unwrap();
        let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 1.0, 2.0]);
        let theta = [1101.295e-6];
        let fine = m.predict(&theta, &loading).unwrap();
        let coarse = c.model.predict(&theta, &loading).unwrap();
        let est = richardson(&fine, &coarse, c.ratio, m.convergence_order().order).unwrap();
        for e in &est {
            assert_eq!(e.error, 0.0, "{fine:?} vs {coarse:?}");
        }
    }
}
