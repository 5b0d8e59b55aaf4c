//! Stage 1's force-level correction of a staged Q1 identification
//! ([`crate::apps::two_stage`]): the relaxation during the ramp, from the elastic
//! FE curve without another FE run.

use crate::apps::two_stage::Q1Record;
use palpate_core::{ForwardModel, Loading};
use palpate_inverse::{fit, DataSet, FitOptions, Objective, ResidualKind};
use std::sync::Arc;

/// The elastic force curve of stage 1 scaled by the parameter `s`, at the
/// samples of the record: `s F_e(k)` (the ramp's elastic FE predictions,
/// then the end-of-ramp value through the hold). The base of the
/// force-level QLV of [`ramp_correction`].
struct ScaledCurve {
    fe: Vec<f64>,
    space: palpate_core::ParamSpace,
}

impl ForwardModel for ScaledCurve {
    fn name(&self) -> String {
        "scaled elastic force curve of stage 1".into()
    }
    fn space(&self) -> &palpate_core::ParamSpace {
        &self.space
    }
    fn observable(&self) -> palpate_core::Observable {
        palpate_core::Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn palpate_core::Evaluator + '_> {
        Box::new(ScaledEvaluator(self))
    }
}

struct ScaledEvaluator<'a>(&'a ScaledCurve);

impl palpate_core::Evaluator for ScaledEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), palpate_core::ForwardError> {
        if out.len() != self.0.fe.len() || loading.len() != out.len() {
            return Err(palpate_core::ForwardError::InvalidLoading(
                "the scaled curve answers only for its record".into(),
            ));
        }
        for (o, f) in out.iter_mut().zip(&self.0.fe) {
            *o = theta[0] * f;
        }
        Ok(())
    }
}

/// The relaxation during the ramp lowers the ramp force, so stage 1's
/// elastic fit underestimates the instantaneous moduli. Force-level QLV
/// (`palpate_enrich::Viscoelastic`, Fung's QLV on the force: exact for the
/// punch in the linear range by the correspondence principle) of the stage-1
/// elastic curve `s F_e(t)` is fitted to the whole record by LM in
/// `s, g_i, tau_i` from `s = 1` and the default Prony start; it costs no FE
/// run (the curve is stage 1's). Returns `s` (the factor on the moduli:
/// the force is proportional to them for a law with one modulus, e.g.
/// neo-Hookean, under exact incompressibility) and the Prony terms,
/// increasing in tau, as the start of stage 2. `None` when the record is
/// not a ramp then a hold at constant depth, or the fit fails.
pub fn ramp_correction(
    record: &Q1Record,
    fe_ramp: &[f64],
    terms: usize,
) -> Option<(f64, Vec<f64>)> {
    let k = record.ramp_end();
    if fe_ramp.len() != k + 1 || record.depth[k..].iter().any(|&d| d != record.depth[k]) {
        return None;
    }
    let mut fe = fe_ramp.to_vec();
    fe.resize(record.depth.len(), fe_ramp[k]);
    let base = ScaledCurve {
        fe,
        space: palpate_core::ParamSpace::new(vec![palpate_core::ParamSpec::new(
            "scale",
            "1",
            0.0,
            f64::INFINITY,
            1.0,
        )]),
    };
    let qlv = palpate_enrich::Viscoelastic::new(Box::new(base), terms);
    let set = DataSet::new(
        "ramp correction",
        Arc::new(qlv),
        record.loading(),
        record.force.clone(),
    );
    let objective = Objective::new(vec![set], ResidualKind::Absolute, &[]).ok()?;
    let report = fit(&objective, &FitOptions::default()).ok()?;
    let theta: Vec<f64> = report.parameters.iter().map(|p| p.value).collect();
    let mut pairs: Vec<(f64, f64)> = (0..terms)
        .map(|i| (theta[1 + 2 * i], theta[2 + 2 * i]))
        .collect();
    pairs.sort_by(|a, b| a.1.total_cmp(&b.1));
    let sum: f64 = pairs.iter().map(|p| p.0).sum();
    (report.converged && sum < 1.0 && theta[0] > 0.0).then(|| {
        (
            theta[0],
            pairs.into_iter().flat_map(|(g, t)| [g, t]).collect(),
        )
    })
}
