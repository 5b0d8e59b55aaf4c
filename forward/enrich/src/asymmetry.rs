//! Enrichment `tension_compression_asymmetry`: a different stiffness in
//! compression than in tension.

use crate::convert::split;
use crate::wrap::{enrich_wrapper, wrapper_effects};
use palpate_core::{
    Effect, Enrichable, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output,
    ParamSpace, ParamSpec,
};
use std::sync::Arc;

/// A bimodular response around a stretch-driven model: the wrapped model's
/// prediction multiplied by (1 + a) wherever the stretch is below 1
/// (compression) and unchanged in tension,
///
/// ```text
/// P(lambda) = (1 + a H(1 - lambda)) P_base(lambda),
/// ```
///
/// continuous at lambda = 1 where P_base = 0. A compression modulus (1 + a)
/// times the tension modulus is how brain tissue is reported (stiffer in
/// compression: Budday et al. 2017, Acta Biomaterialia 48, 319-340; Miller &
/// Chinzei 2002, J. Biomech. 35, 483-490). One parameter `asymmetry` in
/// [-0.9, 20], off at a = 0 (interior). A record that stays on one side of
/// lambda = 1 cannot see it (its sensitivity is zero there).
pub struct TensionCompressionAsymmetry {
    base: Arc<dyn ForwardModel>,
    space: ParamSpace,
}

impl TensionCompressionAsymmetry {
    /// Asymmetry around a stretch-driven `base`.
    pub fn from_arc(base: Arc<dyn ForwardModel>) -> Self {
        let space = base
            .space()
            .extended(&[ParamSpec::new("asymmetry", "1", -0.9, 20.0, 0.0)]);
        TensionCompressionAsymmetry { base, space }
    }
}

struct AsymmetryEvaluator<'a> {
    model: &'a TensionCompressionAsymmetry,
    base: Box<dyn Evaluator + 'a>,
}

impl Evaluator for AsymmetryEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        let (base_theta, own) = split(theta, &self.model.space, 1)?;
        self.base.predict_into(base_theta, loading, out)?;
        for (o, &s) in out.iter_mut().zip(&loading.drive) {
            if s < 1.0 {
                *o *= 1.0 + own[0];
            }
        }
        Ok(())
    }
}

impl ForwardModel for TensionCompressionAsymmetry {
    fn name(&self) -> String {
        format!("{} + tension-compression asymmetry", self.base.name())
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        self.base.observable()
    }
    fn outputs(&self) -> Vec<Output> {
        self.base.outputs().into_iter().take(1).collect()
    }
    fn expensive(&self) -> bool {
        self.base.expensive()
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(AsymmetryEvaluator {
            model: self,
            base: self.base.evaluator(),
        })
    }
    fn as_enrichable(&self) -> Option<&dyn Enrichable> {
        Some(self)
    }
}

impl Enrichable for TensionCompressionAsymmetry {
    /// The drive/response wrappers the wrapped model offers (relaxation,
    /// a zero offset): they act on the asymmetric response as on any other.
    fn effects(&self) -> Vec<Effect> {
        wrapper_effects(self.base.as_ref(), Effect::TensionCompressionAsymmetry)
    }
    fn enrich(&self, effect: Effect) -> Result<Box<dyn ForwardModel>, ForwardError> {
        let this = Arc::new(TensionCompressionAsymmetry {
            base: self.base.clone(),
            space: self.space.clone(),
        });
        enrich_wrapper(
            this,
            self.base.as_ref(),
            Effect::TensionCompressionAsymmetry,
            effect,
        )
    }
    /// Base parameters, then a = 0.
    fn embed(&self, base_theta: &[f64]) -> Vec<f64> {
        let mut v = base_theta.to_vec();
        v.push(0.0);
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_core::{Drive, ParamRole};

    struct Linear(ParamSpace);
    struct Eval;
    impl Evaluator for Eval {
        fn predict_into(
            &mut self,
            t: &[f64],
            l: &Loading,
            o: &mut [f64],
        ) -> Result<(), ForwardError> {
            for (o, s) in o.iter_mut().zip(&l.drive) {
                *o = t[0] * (s - 1.0);
            }
            Ok(())
        }
    }
    impl ForwardModel for Linear {
        fn name(&self) -> String {
            "linear".into()
        }
        fn space(&self) -> &ParamSpace {
            &self.0
        }
        fn observable(&self) -> Observable {
            Observable::NominalStressMPa
        }
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(Eval)
        }
    }

    #[test]
    fn compression_is_scaled_and_off_is_the_base() {
        let base = Arc::new(Linear(ParamSpace::new(vec![ParamSpec::new(
            "E", "MPa", 0.0, 10.0, 1.0,
        )
        .with_role(ParamRole::Modulus)])));
        let m = TensionCompressionAsymmetry::from_arc(base.clone());
        let l = Loading::quasi_static(Drive::Stretch, vec![0.8, 1.0, 1.2]);
        assert_eq!(
            m.predict(&m.embed(&[2.0]), &l).unwrap(),
            base.predict(&[2.0], &l).unwrap()
        );
        let f = m.predict(&[2.0, 0.5], &l).unwrap();
        assert!((f[0] - 1.5 * 2.0 * -0.2).abs() < 1e-12 && f[1] == 0.0);
        assert!((f[2] - 0.4).abs() < 1e-12);
    }

    /// Wrapped in a zero offset, the asymmetric response gets an offset of
    /// the stretch (not of a displacement: its observable is a stress), off
    /// at 0.
    #[test]
    fn it_offers_the_stretch_offset_and_relaxation() {
        let l = Loading::quasi_static(Drive::Stretch, vec![0.8, 1.0, 1.2]);
        let tca = TensionCompressionAsymmetry::from_arc(Arc::new(Linear(ParamSpace::new(vec![
            ParamSpec::new("E", "MPa", 0.0, 10.0, 1.0),
        ]))));
        let shifted = crate::wrap(Effect::ZeroOffset, Arc::new(tca)).unwrap();
        assert_eq!(shifted.space().names(), ["E", "asymmetry", "d0_stretch"]);
        let off = shifted.as_enrichable().unwrap().embed(&[2.0, 0.5]);
        assert_eq!(off, [2.0, 0.5, 0.0]);
        // a stretch offset of 0.1: the true stretch is the recorded one minus 0.1
        let f = shifted.predict(&[2.0, 0.5, 0.1], &l).unwrap();
        assert!((f[1] - 1.5 * 2.0 * -0.1).abs() < 1e-12, "{f:?}");
    }
}
