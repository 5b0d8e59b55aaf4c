//! Quasi-linear viscoelasticity (Fung) with a Prony series, around any model.

use crate::convert::split;
use crate::wrap::{enrich_wrapper, wrapper_effects};
use palpate_core::{
    check_output_slots, Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading,
    Observable, Output, ParamRole, ParamSpace, ParamSpec,
};
use std::sync::Arc;

/// Quasi-linear viscoelastic response of the wrapped (elastic) model:
///
/// F(t) = int_0^t G(t - s) dFe/ds ds,  G(t) = 1 - sum_i g_i (1 - exp(-t / tau_i))
///
/// (Fung, *Biomechanics*, 1993, ch. 7; benchmark Q1), with Fe the wrapped
/// model's prediction at the same samples. For homogeneous tests the force is
/// proportional to the stress, so this is exact there; for a structure
/// (indentation) it is the usual QLV approximation applied to the force.
/// A wrapped model with several outputs (force components) keeps them: the
/// same relaxation function acts on each, F_j(t) = int G dFe_j, as it does on
/// each component of a force vector under the force-level approximation.
///
/// Parameters: the wrapped model's, then `g1, tau1_s, g2, tau2_s, ...` with
/// g_i in [0, 1], sum g_i <= 1 and tau_i > 0 (checked: an error, never a
/// clamp). g_i = 0 switches the effect off ([`Enrichable::embed`]). Needs
/// `loading.time`.
///
/// Label switching: the response is symmetric in the terms, so the model
/// accepts them in any order rather than rejecting tau_1 > tau_2 (a
/// rejection makes finite-difference steps fail whenever an estimate pushes
/// two relaxation times together); [`Viscoelastic::canonical_order`] gives
/// the canonical labelling (increasing tau) for reports and samples.
pub struct Viscoelastic {
    base: Arc<dyn ForwardModel>,
    terms: usize,
    space: ParamSpace,
}

impl Viscoelastic {
    /// QLV with `terms` Prony terms around `base`.
    pub fn new(base: Box<dyn ForwardModel>, terms: usize) -> Self {
        Self::from_arc(Arc::from(base), terms)
    }

    /// Same, sharing the base model.
    pub fn from_arc(base: Arc<dyn ForwardModel>, terms: usize) -> Self {
        let space = base.space().extended(&prony_params(terms));
        Viscoelastic { base, terms, space }
    }

    /// Number of Prony terms.
    pub fn terms(&self) -> usize {
        self.terms
    }

    /// The same parameter vector with the Prony terms sorted by increasing
    /// relaxation time (the canonical labelling: the response does not
    /// depend on the order of the terms, so estimates and samples should be
    /// reported in this order to avoid label switching).
    pub fn canonical_order(&self, theta: &[f64]) -> Vec<f64> {
        let p = theta.len() - 2 * self.terms;
        let mut pairs: Vec<(f64, f64)> = (0..self.terms)
            .map(|i| (theta[p + 2 * i], theta[p + 2 * i + 1]))
            .collect();
        pairs.sort_by(|a, b| a.1.total_cmp(&b.1));
        let mut out = theta[..p].to_vec();
        for (g, tau) in pairs {
            out.push(g);
            out.push(tau);
        }
        out
    }
}

/// Checks the Prony parameters `[g1, tau1, g2, tau2, ...]` of `terms` terms:
/// tau_i > 0 and sum g_i <= 1 (so G(inf) = 1 - sum g_i >= 0); g_i >= 0 is
/// the parameter space's bound. The error names the parameter
/// (`tau2_s`, `g3`) as [`prony_params`] does.
pub fn check_prony(prony: &[f64], terms: usize) -> Result<(), ForwardError> {
    let mut sum = 0.0;
    for i in 0..terms {
        let (g, tau) = (prony[2 * i], prony[2 * i + 1]);
        sum += g;
        if tau.is_nan() || tau <= 0.0 {
            return Err(ForwardError::InvalidParameter {
                name: format!("tau{}_s", i + 1),
                value: tau,
                reason: "relaxation time must be positive".into(),
            });
        }
    }
    if sum.is_nan() || sum > 1.0 {
        return Err(ForwardError::InvalidParameter {
            name: format!("g{terms}"),
            value: prony[2 * (terms - 1)],
            reason: format!("sum of g_i = {sum} must not exceed 1"),
        });
    }
    Ok(())
}

/// The parameters of `terms` Prony terms, `g1, tau1_s, g2, tau2_s, ...`:
/// g_i in [0, 1] starting at 0.1, tau_i > 0 (s) starting one decade apart
/// (1 s, 10 s, ...). The same list for every model that takes Prony terms
/// as parameters ([`Viscoelastic`] here, the FE models' own series).
pub fn prony_params(terms: usize) -> Vec<ParamSpec> {
    let mut own = Vec::with_capacity(2 * terms);
    for i in 1..=terms {
        own.push(
            ParamSpec::new(format!("g{i}"), "1", 0.0, 1.0, 0.1)
                .with_role(ParamRole::RelaxationWeight { term: i }),
        );
        own.push(
            ParamSpec::new(format!("tau{i}_s"), "s", 0.0, f64::INFINITY, default_tau(i))
                .with_role(ParamRole::TimeConstant { term: i }),
        );
    }
    own
}

/// Starting relaxation time of term `i` (1-based): one decade apart, 1 s, 10 s, ...
fn default_tau(i: usize) -> f64 {
    10f64.powi(i as i32 - 1)
}

/// Exact convolution for an elastic response `fe` that is piecewise linear
/// in time between samples, written into `out`:
///
/// F_k = g_inf Fe_k + sum_i g_i h_i,k,  g_inf = 1 - sum_i g_i,
/// h_i,k = e_i h_i,k-1 + (Fe_k - Fe_k-1) tau_i / dt (1 - e_i),  e_i = exp(-dt / tau_i),
///
/// with h_i,0 = Fe_0 (the body is at rest before the first sample, so a
/// non-zero first value is an instantaneous step) and, for dt = 0, a step
/// h_i += dFe. This is the recursive update of the hereditary integral of
/// Taylor, Pister & Goudreau (1970) and Simo & Hughes (*Computational
/// Inelasticity*, 1998, section 10.3.2), exact (no time-step error) for
/// piecewise-linear Fe; see also Puso & Weiss (1998) for QLV.
/// `prony` is `[g1, tau1, g2, tau2, ...]`; no checks are made here.
pub fn qlv_convolve(time: &[f64], fe: &[f64], prony: &[f64], out: &mut [f64]) {
    let terms = prony.len() / 2;
    let g_inf = 1.0 - (0..terms).map(|i| prony[2 * i]).sum::<f64>();
    let mut h: Vec<f64> = vec![fe.first().copied().unwrap_or(0.0); terms];
    for k in 0..fe.len() {
        if k > 0 {
            let dt = time[k] - time[k - 1];
            let dfe = fe[k] - fe[k - 1];
            for (i, hi) in h.iter_mut().enumerate() {
                let tau = prony[2 * i + 1];
                let x = dt / tau;
                // (1 - e^-x) / x computed without cancellation for small x.
                let phi = if x > 0.0 { -(-x).exp_m1() / x } else { 1.0 };
                *hi = (-x).exp() * *hi + dfe * phi;
            }
        }
        out[k] = g_inf * fe[k]
            + h.iter()
                .enumerate()
                .map(|(i, hi)| prony[2 * i] * hi)
                .sum::<f64>();
    }
}

struct ViscoelasticEvaluator<'a> {
    model: &'a Viscoelastic,
    base: Box<dyn Evaluator + 'a>,
    fe: Vec<f64>,
    column: Vec<f64>,
    relaxed: Vec<f64>,
}

/// The wrapped model's part of `theta`, the Prony parameters and the times.
type Checked<'t, 'l> = (&'t [f64], &'t [f64], &'l [f64]);

impl ViscoelasticEvaluator<'_> {
    /// Checks the parameters and the history.
    fn check<'t, 'l>(
        &self,
        theta: &'t [f64],
        loading: &'l Loading,
    ) -> Result<Checked<'t, 'l>, ForwardError> {
        let m = self.model;
        let (base_theta, prony) = split(theta, &m.space, 2 * m.terms)?;
        if m.terms > 0 {
            check_prony(prony, m.terms)?;
        }
        let time = loading.time.as_ref().ok_or_else(|| {
            ForwardError::InvalidLoading(
                "a viscoelastic model needs the time of each sample".into(),
            )
        })?;
        loading.validate().map_err(ForwardError::InvalidLoading)?;
        Ok((base_theta, prony, time))
    }
}

impl Evaluator for ViscoelasticEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let (base_theta, prony, time) = self.check(theta, loading)?;
        if out.len() != loading.len() {
            return Err(ForwardError::InvalidLoading(format!(
                "output has {} slots for {} samples",
                out.len(),
                loading.len()
            )));
        }
        self.fe.resize(loading.len(), 0.0);
        self.base.predict_into(base_theta, loading, &mut self.fe)?;
        qlv_convolve(time, &self.fe, prony, out);
        Ok(())
    }

    /// Each output column convolved with the same relaxation function.
    fn predict_outputs_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let k = self.model.base.outputs().len();
        if k == 1 {
            return self.predict_into(theta, loading, out);
        }
        let (base_theta, prony, time) = self.check(theta, loading)?;
        let n = loading.len();
        check_output_slots(out.len(), n, k)?;
        self.fe.resize(n * k, 0.0);
        self.base
            .predict_outputs_into(base_theta, loading, &mut self.fe)?;
        self.column.resize(n, 0.0);
        self.relaxed.resize(n, 0.0);
        for j in 0..k {
            for i in 0..n {
                self.column[i] = self.fe[i * k + j];
            }
            qlv_convolve(time, &self.column, prony, &mut self.relaxed);
            for i in 0..n {
                out[i * k + j] = self.relaxed[i];
            }
        }
        Ok(())
    }
}

impl ForwardModel for Viscoelastic {
    fn name(&self) -> String {
        format!("{} + QLV ({} Prony terms)", self.base.name(), self.terms)
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
        Box::new(ViscoelasticEvaluator {
            model: self,
            base: self.base.evaluator(),
            fe: Vec::new(),
            column: Vec::new(),
            relaxed: Vec::new(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for Viscoelastic {
    fn effects(&self) -> Vec<Effect> {
        wrapper_effects(self.base.as_ref(), Effect::Viscoelasticity)
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        let this = Arc::new(Viscoelastic {
            base: self.base.clone(),
            terms: self.terms,
            space: self.space.clone(),
        });
        enrich_wrapper(this, self.base.as_ref(), Effect::Viscoelasticity, effect)
    }
    /// Base parameters, then g_i = 0 with tau_i at their starting values.
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        for i in 1..=self.terms {
            v.push(0.0);
            v.push(default_tau(i));
        }
        v
    }
}
