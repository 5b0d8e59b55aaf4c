//! Enrichment `tool_compliance`: a series spring between the recorded
//! displacement and the tool.

use crate::convert::split;
use crate::wrap::{enrich_wrapper, wrapper_effects};
use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output,
    ParamRole, ParamSpace, ParamSpec,
};
use std::sync::Arc;

/// Maximum Newton iterations of the compliance solve.
const MAX_ITERATIONS: usize = 60;

/// The recorded displacement d includes the deflection of the machine:
/// d = u + c F(u), with u the tool's true travel and c = 1/k the compliance
/// (mm/N). The prediction is F(u) with u solved at every sample.
///
/// Parametrised by `c_mm_per_N` >= 0 rather than the stiffness k so that
/// "off" (a rigid machine, k = infinity) is the reachable point c = 0 where a
/// score test can differentiate; k = 1/c.
///
/// The solve is a Newton iteration on the whole history at once,
/// u <- u - (u + c F(u) - d) / (1 + c s), with the diagonal slope s = dF_i/du_i
/// estimated from one run with the history perturbed by +h, -h, +h, ... at
/// alternate samples. For a rate-independent model that slope is exact; for
/// a fading-memory one (QLV, a Prony series) the contributions of the past
/// samples alternate in sign and nearly cancel, so the slope is close to the
/// instantaneous one, the true diagonal of the causal Jacobian. Shifting the
/// whole history by the same h would give the relaxed slope instead, which
/// makes the iteration crawl when the compliance is stiff against a relaxing
/// specimen. The residual is checked to 1e-10 mm either way.
///
/// The spring is loaded by the wrapped model's first output, the force
/// along the drive ([`palpate_core::Output`]). A wrapped model with several
/// outputs keeps them: u is solved with the first, and every output is the
/// wrapped model's at that u (e.g. the horizontal force at the true travel).
pub struct ToolCompliance {
    base: Arc<dyn ForwardModel>,
    space: ParamSpace,
}

impl ToolCompliance {
    /// Tool compliance around `base` (a displacement-driven force model).
    pub fn new(base: Box<dyn ForwardModel>) -> Self {
        Self::from_arc(Arc::from(base))
    }

    /// Same, sharing the base model.
    pub fn from_arc(base: Arc<dyn ForwardModel>) -> Self {
        let space = base.space().extended(&[ParamSpec::new(
            "c_mm_per_N",
            "mm/N",
            0.0,
            f64::INFINITY,
            1e-3,
        )
        .with_role(ParamRole::Compliance)]);
        ToolCompliance { base, space }
    }
}

struct ToolComplianceEvaluator<'a> {
    model: &'a ToolCompliance,
    base: Box<dyn Evaluator + 'a>,
    shifted: Vec<f64>,
}

impl ToolComplianceEvaluator<'_> {
    /// The wrapped model on `loading`: its first output (`k == 1`) or its
    /// `k` outputs per sample.
    fn base_at(
        base: &mut (dyn Evaluator + '_),
        theta: &[f64],
        loading: &Loading,
        k: usize,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        if k == 1 {
            base.predict_into(theta, loading, out)
        } else {
            base.predict_outputs_into(theta, loading, out)
        }
    }

    /// Solves the travel and writes the wrapped model's `k` outputs at it
    /// (`out` holds `loading.len() * k` values; the spring takes column 0).
    fn solve(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        k: usize,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let (base_theta, own) = split(theta, &self.model.space, 1)?;
        let c = own[0];
        let n = loading.len();
        if out.len() != n * k {
            return Err(ForwardError::InvalidLoading(if k == 1 {
                format!("output has {} slots for {n} samples", out.len())
            } else {
                format!(
                    "output has {} slots for {n} samples x {k} outputs",
                    out.len()
                )
            }));
        }
        let base = self.base.as_mut();
        if c == 0.0 {
            return Self::base_at(base, base_theta, loading, k, out);
        }
        let scale = 1.0 + loading.drive.iter().fold(0.0f64, |a, d| a.max(d.abs()));
        let h = 1e-7 * scale;
        let tol = 1e-10 * scale;
        let mut u = loading.drive.clone();
        self.shifted.resize(n * k, 0.0);
        let mut worst_sample = 0;
        for _ in 0..MAX_ITERATIONS {
            Self::base_at(base, base_theta, &loading.with_drive(u.clone()), k, out)?;
            let (mut worst, mut at) = (0.0f64, 0);
            for i in 0..n {
                let r = (u[i] + c * out[i * k] - loading.drive[i]).abs();
                if r > worst {
                    (worst, at) = (r, i);
                }
            }
            worst_sample = at;
            if worst <= tol {
                return Ok(());
            }
            let sign = |i: usize| if i.is_multiple_of(2) { 1.0 } else { -1.0 };
            let plus: Vec<f64> = u.iter().enumerate().map(|(i, x)| x + sign(i) * h).collect();
            Self::base_at(
                base,
                base_theta,
                &loading.with_drive(plus),
                k,
                &mut self.shifted,
            )?;
            let mut largest_update = 0.0f64;
            for i in 0..n {
                let slope = (self.shifted[i * k] - out[i * k]) / (sign(i) * h);
                let denom = 1.0 + c * slope;
                let denom = if denom > 0.05 { denom } else { 1.0 };
                let du = (u[i] + c * out[i * k] - loading.drive[i]) / denom;
                u[i] -= du;
                largest_update = largest_update.max(du.abs());
            }
            // For a stiff specimen (c F'(u) >> 1) the residual cannot fall below
            // c F' x (round-off of u); the travel u itself is then converged.
            if largest_update <= 1e-13 * scale {
                return Self::base_at(base, base_theta, &loading.with_drive(u), k, out);
            }
        }
        Err(ForwardError::NotConverged {
            sample: worst_sample,
            drive: loading.drive[worst_sample],
            cuts: 0,
            reason: format!(
                "tool-compliance solve did not converge in {MAX_ITERATIONS} iterations"
            ),
            completed: Vec::new(),
        })
    }
}

impl Evaluator for ToolComplianceEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.solve(theta, loading, 1, out)
    }
    fn predict_outputs_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let k = self.model.base.outputs().len();
        self.solve(theta, loading, k, out)
    }
}

impl ForwardModel for ToolCompliance {
    fn name(&self) -> String {
        format!("{} + tool compliance", self.base.name())
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        self.base.observable()
    }
    fn outputs(&self) -> Vec<Output> {
        self.base.outputs()
    }
    fn expensive(&self) -> bool {
        self.base.expensive()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(ToolComplianceEvaluator {
            model: self,
            base: self.base.evaluator(),
            shifted: Vec::new(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for ToolCompliance {
    fn effects(&self) -> Vec<Effect> {
        wrapper_effects(self.base.as_ref(), Effect::ToolCompliance)
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        let this = Arc::new(ToolCompliance::from_arc(self.base.clone()));
        enrich_wrapper(this, self.base.as_ref(), Effect::ToolCompliance, effect)
    }
    /// Base parameters, then c = 0 (a rigid machine).
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        v.push(0.0);
        v
    }
}
