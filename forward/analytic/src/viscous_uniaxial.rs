//! Finite-strain viscoelastic uniaxial tension/compression: a Prony series
//! on the isochoric second Piola-Kirchhoff stress (the homogeneous form of
//! `palpate_fe::Viscoelastic`).

use crate::convert::{check_law_params, check_loading, law_space};
use palpate_core::enrichable::not_applicable;
use palpate_core::{
    Drive, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable,
    ParamSpace, ParamSpec,
};
use palpate_enrich::{check_prony, qlv_convolve};
use palpate_material::Law;

/// Uniaxial nominal stress of an incompressible viscoelastic solid whose
/// isochoric second Piola-Kirchhoff stress relaxes with a Prony series
/// (Simo, CMAME 60 (1987) 153; Holzapfel, *Nonlinear Solid Mechanics*,
/// 2000, sec. 6.10):
///
/// ```text
/// S(t) = int_0^t G(t - s) dS_e/ds ds,   G(t) = 1 - sum_i g_i (1 - exp(-t / tau_i)),
/// S_e,a = (lt_a W_a - mean_b lt_b W_b) / l_a^2     (principal, isochoric projection),
/// P(t) = l S_1(t) - l^-2 S_2(t)                    (lateral Cauchy stress zero),
/// ```
///
/// with `l = (s, s^-1/2, s^-1/2)` and `W_a` the law's principal derivatives.
/// The pressure is fixed by the free lateral surface at the current
/// stretch, so this is *not* QLV (`palpate_enrich::Viscoelastic`, which
/// convolves the elastic nominal stress itself): the relaxed part multiplies
/// the current `C^-1`, and the two differ at finite strain (at 20 %
/// compression by ~1e-2 of the viscous part; VHB 4910 at stretch 3 by tens
/// of percent, `docs/validation/real-data.md`). For an instantaneous step
/// from rest both give the elastic response; long after it, `g_inf` times
/// it (`g_inf = 1 - sum g_i`).
///
/// The hereditary integral uses the exact update for a piecewise-linear
/// history ([`qlv_convolve`], Taylor, Pister & Goudreau 1970) on each
/// principal component of `S_e`. Parameters: the law's, then
/// `g1, tau1_s, g2, tau2_s, ...` as in the QLV wrapper. Needs `loading.time`.
#[derive(Debug, Clone, PartialEq)]
pub struct ViscousUniaxial {
    pub law: Law,
    terms: usize,
    space: ParamSpace,
}

impl ViscousUniaxial {
    /// The model with `terms` Prony terms (1..=6).
    pub fn new(law: Law, terms: usize) -> Result<Self, ForwardError> {
        if !(1..=6).contains(&terms) {
            return Err(ForwardError::InvalidConfig {
                field: "terms".into(),
                reason: format!("{terms} Prony terms; expected 1 to 6"),
            });
        }
        let mut own = Vec::with_capacity(2 * terms);
        for i in 1..=terms {
            own.push(ParamSpec::new(format!("g{i}"), "1", 0.0, 1.0, 0.1));
            own.push(ParamSpec::new(
                format!("tau{i}_s"),
                "s",
                0.0,
                f64::INFINITY,
                10f64.powi(i as i32 - 1),
            ));
        }
        let space = law_space(&law).extended(&own);
        Ok(ViscousUniaxial { law, terms, space })
    }

    /// Number of Prony terms.
    pub fn terms(&self) -> usize {
        self.terms
    }

    /// Principal isochoric second Piola-Kirchhoff stresses `(S_1, S_2)` of
    /// the elastic law at uniaxial stretch `s`.
    pub fn elastic_pk2(&self, law_theta: &[f64], s: f64) -> (f64, f64) {
        let t = 1.0 / s.sqrt();
        let lam = [s, t, t];
        let d = self.law.isochoric_principal(law_theta, lam);
        let gt = [lam[0] * d.dw[0], lam[1] * d.dw[1], lam[2] * d.dw[2]];
        let mean = (gt[0] + gt[1] + gt[2]) / 3.0;
        ((gt[0] - mean) / (s * s), (gt[1] - mean) / (t * t))
    }
}

struct ViscousUniaxialEvaluator<'a> {
    model: &'a ViscousUniaxial,
    s1: Vec<f64>,
    s2: Vec<f64>,
    r1: Vec<f64>,
    r2: Vec<f64>,
}

impl Evaluator for ViscousUniaxialEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let m = self.model;
        m.space.check(theta)?;
        let (law_theta, prony) = theta.split_at(theta.len() - 2 * m.terms);
        check_law_params(&m.law, &law_space(&m.law), law_theta)?;
        check_prony(prony, m.terms)?;
        check_loading(loading, Drive::Stretch, out.len())?;
        let time = loading.time.as_deref().ok_or_else(|| {
            ForwardError::InvalidLoading(
                "a viscoelastic model needs a timed history (column time_s)".into(),
            )
        })?;
        let n = loading.len();
        for v in [&mut self.s1, &mut self.s2, &mut self.r1, &mut self.r2] {
            v.resize(n, 0.0);
        }
        for (k, &s) in loading.drive.iter().enumerate() {
            if s.is_nan() || s <= 0.0 {
                return Err(ForwardError::Unphysical {
                    drive: s,
                    reason: "stretch must be positive".into(),
                });
            }
            (self.s1[k], self.s2[k]) = m.elastic_pk2(law_theta, s);
        }
        qlv_convolve(time, &self.s1, prony, &mut self.r1);
        qlv_convolve(time, &self.s2, prony, &mut self.r2);
        for (k, o) in out.iter_mut().enumerate() {
            let s = loading.drive[k];
            *o = s * self.r1[k] - self.r2[k] / (s * s);
            if !o.is_finite() {
                return Err(ForwardError::Unphysical {
                    drive: s,
                    reason: format!("{} viscoelastic stress is not finite", m.law),
                });
            }
        }
        Ok(())
    }
}

impl ForwardModel for ViscousUniaxial {
    fn name(&self) -> String {
        format!(
            "finite-strain viscoelastic uniaxial {} ({} Prony terms)",
            self.law, self.terms
        )
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::NominalStressMPa
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(ViscousUniaxialEvaluator {
            model: self,
            s1: Vec::new(),
            s2: Vec::new(),
            r1: Vec::new(),
            r2: Vec::new(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for ViscousUniaxial {
    fn effects(&self) -> Vec<Effect> {
        Vec::new()
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        Err(not_applicable(effect, &self.name()))
    }
}
