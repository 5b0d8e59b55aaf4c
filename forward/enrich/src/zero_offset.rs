//! Enrichment `zero_offset`: the true contact point differs from the recorded
//! zero of displacement.

use crate::convert::split;
use crate::wrap::{enrich_wrapper, wrapper_effects};
use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output,
    ParamRole, ParamSpace, ParamSpec,
};
use std::borrow::Cow;
use std::sync::Arc;

/// F(d) = base(max(d - d0, 0)): contact starts at recorded displacement `d0`
/// (positive: the tool travels `d0` before touching; negative: the specimen
/// was already pre-compressed by `-d0` at the recorded zero). One parameter
/// `d0_mm` in [-5, 5] mm, off at d0 = 0 (an interior point, so sensitivities
/// exist there). The wrapped model sees the shifted history, times unchanged;
/// it has the wrapped model's outputs, every one at the shifted history.
pub struct ZeroOffset {
    base: Arc<dyn ForwardModel>,
    space: ParamSpace,
}

/// The offset of a displacement drive: `d0_mm` in [-5, 5] mm, plausibly
/// within 0.1 mm of the recorded zero.
fn displacement_offset() -> ParamSpec {
    ParamSpec::new("d0_mm", "mm", -5.0, 5.0, 0.0)
        .with_role(ParamRole::Offset)
        .with_plausible(-0.1, 0.1)
}

/// The offset of a stretch drive (homogeneous tests): `d0_stretch` in
/// [-0.5, 0.5], the true stretch being the recorded one minus it (a zero of
/// displacement off by d0_stretch x the gauge length), plausibly within 0.02.
fn stretch_offset() -> ParamSpec {
    ParamSpec::new("d0_stretch", "1", -0.5, 0.5, 0.0)
        .with_role(ParamRole::Offset)
        .with_plausible(-0.02, 0.02)
}

impl ZeroOffset {
    /// Zero offset around `base` (a displacement-driven model).
    pub fn new(base: Box<dyn ForwardModel>) -> Self {
        Self::from_arc(Arc::from(base))
    }

    /// Same, sharing the base model.
    pub fn from_arc(base: Arc<dyn ForwardModel>) -> Self {
        Self::with_spec(base, displacement_offset())
    }

    /// Zero offset of the stretch around a stretch-driven model (homogeneous
    /// tests): lambda = recorded - d0_stretch.
    pub fn on_stretch(base: Arc<dyn ForwardModel>) -> Self {
        Self::with_spec(base, stretch_offset())
    }

    fn with_spec(base: Arc<dyn ForwardModel>, spec: ParamSpec) -> Self {
        let space = base.space().extended(&[spec]);
        ZeroOffset { base, space }
    }
}

struct ZeroOffsetEvaluator<'a> {
    model: &'a ZeroOffset,
    base: Box<dyn Evaluator + 'a>,
}

/// The history the wrapped model sees: the drive shifted by `d0` (none when
/// `d0 == 0`, so "off" is the base model exactly).
fn shifted(loading: &Loading, d0: f64) -> Cow<'_, Loading> {
    if d0 == 0.0 {
        Cow::Borrowed(loading)
    } else {
        Cow::Owned(loading.with_drive(loading.drive.iter().map(|d| (d - d0).max(0.0)).collect()))
    }
}

impl Evaluator for ZeroOffsetEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let (base_theta, own) = split(theta, &self.model.space, 1)?;
        self.base
            .predict_into(base_theta, &shifted(loading, own[0]), out)
    }
    fn predict_outputs_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let (base_theta, own) = split(theta, &self.model.space, 1)?;
        self.base
            .predict_outputs_into(base_theta, &shifted(loading, own[0]), out)
    }
}

impl ForwardModel for ZeroOffset {
    fn name(&self) -> String {
        format!("{} + zero offset", self.base.name())
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
        Box::new(ZeroOffsetEvaluator {
            model: self,
            base: self.base.evaluator(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for ZeroOffset {
    fn effects(&self) -> Vec<Effect> {
        wrapper_effects(self.base.as_ref(), Effect::ZeroOffset)
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        let spec = self.space.params[self.space.len() - 1].clone();
        let this = Arc::new(ZeroOffset::with_spec(self.base.clone(), spec));
        enrich_wrapper(this, self.base.as_ref(), Effect::ZeroOffset, effect)
    }
    /// Base parameters, then d0 = 0.
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        v.push(0.0);
        v
    }
}
