//! `Q1Viscous`: the Q1 punch ([`Q1Punch`]) with a one-term Prony series on
//! the law's isochoric stress whose weight and time constant are parameters
//! (`g1`, `tau1_s`) — the `viscoelasticity` enrichment of the elastic Q1
//! model for the gap diagnosis (GAP.md).
//!
//! The relaxation function is G(t) = 1 - g1 (1 - exp(-t / tau1))
//! (finite-strain quasi-linear viscoelasticity with exact recursive
//! convolution, [`crate::viscoelastic::Viscoelastic`]; Simo 1987). "Off" is
//! g1 = 0, where the prediction is the elastic model's, bit for bit (the
//! elastic path is taken). One term, not two as for the analytic C1 model:
//! every prediction is a viscoelastic FE run, and a second term doubles the
//! parameters the fit must difference; a ramp-and-hold punch record
//! identifies one dominant time constant.
//!
//! The time steps of a viscoelastic run are the record's samples (its
//! longest sampling interval is the largest step), not a fraction of tau1:
//! a step that followed tau1 would make the prediction a step function of
//! tau1 and its finite-difference sensitivities noise, and would make a
//! short tau1 expensive. The recursive convolution is exact for a strain
//! history linear within a step, so the sampling only sets how finely the
//! history is followed (the displacement steps of the ramp still obey
//! `options.max_step`).

use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamRole,
    ParamSpace, ParamSpec,
};

use super::Q1Punch;
use crate::viscoelastic::Prony;

/// The Q1 punch with a parametrised one-term Prony series.
#[derive(Debug, Clone, PartialEq)]
pub struct Q1Viscous {
    /// The elastic model (its `prony` is ignored).
    pub elastic: Q1Punch,
    /// Largest time increment (s); `None`: the record's longest sampling
    /// interval.
    pub max_time_step: Option<f64>,
    space: ParamSpace,
}

impl Q1Viscous {
    /// Starting (and "off" point's) relaxation time (s).
    pub const TAU_START: f64 = 1.0;

    /// `elastic` with the Prony weight and time constant appended to its
    /// parameters.
    pub fn new(elastic: Q1Punch) -> Self {
        let space = elastic.space().extended(&[
            ParamSpec::new("g1", "1", 0.0, 0.95, 0.1)
                .with_role(ParamRole::RelaxationWeight { term: 1 }),
            ParamSpec::new("tau1_s", "s", 1e-3, 1e4, Self::TAU_START)
                .with_role(ParamRole::TimeConstant { term: 1 }),
        ]);
        let mut elastic = elastic;
        elastic.prony = None;
        Q1Viscous {
            elastic,
            max_time_step: None,
            space,
        }
    }

    /// The model run for `theta`: elastic at g1 = 0, else with the series
    /// and the record's longest sampling interval as largest time step.
    fn at(&self, theta: &[f64], loading: &Loading) -> Result<Q1Punch, ForwardError> {
        let p = self.elastic.space().len();
        let (g, tau) = (theta[p], theta[p + 1]);
        let mut m = self.elastic.clone();
        if g == 0.0 {
            return Ok(m);
        }
        let time = loading.time.as_ref().ok_or_else(|| {
            ForwardError::InvalidLoading(
                "Q1 viscoelasticity needs a timed record (a time_s column)".into(),
            )
        })?;
        let dt = time.windows(2).map(|w| w[1] - w[0]).fold(0.0f64, f64::max);
        m.prony = Some(
            Prony::new(vec![(g, tau)]).map_err(|e| ForwardError::InvalidConfig {
                field: "g1/tau1_s".into(),
                reason: e.to_string(),
            })?,
        );
        m.options.max_time_step = match self.max_time_step {
            Some(h) => Some(h),
            None if dt > 0.0 => Some(dt),
            None => None,
        };
        Ok(m)
    }
}

struct Q1ViscousEval<'a> {
    model: &'a Q1Viscous,
}

impl Evaluator for Q1ViscousEval<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.model.space.check(theta)?;
        let p = self.model.elastic.space().len();
        let m = self.model.at(theta, loading)?;
        let mut ev = m.evaluator();
        ev.predict_into(&theta[..p], loading, out)
    }
}

impl ForwardModel for Q1Viscous {
    fn name(&self) -> String {
        format!("{}, Prony g1 tau1", self.elastic.name())
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(Q1ViscousEval { model: self })
    }
    fn expensive(&self) -> bool {
        true
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for Q1Viscous {
    /// One enrichment at a time: none beyond the relaxation.
    fn effects(&self) -> Vec<Effect> {
        Vec::new()
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        Err(ForwardError::InvalidConfig {
            field: "effect".into(),
            reason: format!("`{effect}` does not apply to {}", self.name()),
        })
    }
    /// The elastic parameters, g1 = 0 ("off") and the starting tau1.
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        v.extend([0.0, Self::TAU_START]);
        v
    }
}
