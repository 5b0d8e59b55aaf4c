//! A coarse forward model corrected by a fine one at one parameter point:
//! multi-fidelity output correction (output space mapping; Bandler et al.,
//! "Space mapping: the state of the art", IEEE Trans. Microwave Theory Tech.
//! 52(1), 2004, section on output space mapping; Koziel, Bandler & Madsen,
//! "A space-mapping framework for engineering optimization", IEEE MTT 54(10),
//! 2006).
//!
//! With a coarse model `c(theta)` (a cheap FE mesh) and a fine one
//! `f(theta)` (a mesh as fine as the data need), both on one loading, the
//! corrected model at the anchor `theta_k` is, sample by sample,
//!
//! ```text
//! m_i(theta) = r_i c_i(theta) + d_i,
//! r_i = f_i(theta_k) / c_i(theta_k),  d_i = 0      where |c_i(theta_k)| > eps max |c(theta_k)|,
//! r_i = 1,                            d_i = f_i(theta_k) - c_i(theta_k)  elsewhere,
//! ```
//!
//! so `m(theta_k) = f(theta_k)` exactly and `m` has the coarse model's
//! sensitivities, scaled. The ratio form is chosen over a plain offset
//! because the discretisation error of a displacement-driven FE force is,
//! to first order, proportional to the force: for a law with one modulus
//! under exact incompressibility the force of either mesh is proportional
//! to the modulus, so the ratio does not depend on it at all, and the fit
//! of `m` reaches the fine model's optimum in that parameter without a
//! second fine run. For the other parameters the ratio moves slowly, and
//! an outer loop (fit `m`, move the anchor to the estimate, fit again)
//! converges to a point where the fine model's residual is stationary up to
//! the ratio's own derivative (Koziel et al. 2006, the "output SM" fixed
//! point); callers stop the loop when the estimates move by a small part of
//! their standard errors.
//!
//! The correction is for one loading: [`CorrectedModel`] refuses any other.

use palpate_core::{
    Evaluator, ForwardError, ForwardModel, Loading, Observable, Output, ParamSpace,
};
use std::sync::Arc;

/// Below this part of the largest |coarse| prediction a sample is corrected
/// by an offset, not a ratio (the force at zero depth is zero on both
/// meshes).
pub const RATIO_FLOOR: f64 = 1e-6;

/// The per-sample correction `m_i = ratio_i c_i + offset_i` of a coarse
/// model, made at one parameter point of one loading.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FidelityCorrection {
    pub ratio: Vec<f64>,
    pub offset: Vec<f64>,
    /// The anchor `theta_k` both models ran at.
    pub anchor: Vec<f64>,
}

impl FidelityCorrection {
    /// The correction from the fine and the coarse predictions at one point.
    pub fn from_predictions(fine: &[f64], coarse: &[f64], anchor: &[f64]) -> FidelityCorrection {
        let scale = coarse.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        let (ratio, offset) = fine
            .iter()
            .zip(coarse)
            .map(|(&f, &c)| {
                if c.abs() > RATIO_FLOOR * scale {
                    (f / c, 0.0)
                } else {
                    (1.0, f - c)
                }
            })
            .unzip();
        FidelityCorrection {
            ratio,
            offset,
            anchor: anchor.to_vec(),
        }
    }

    /// Runs both models at `anchor` on `loading` and makes the correction.
    /// The models must share their parameter space.
    pub fn at(
        fine: &dyn ForwardModel,
        coarse: &dyn ForwardModel,
        anchor: &[f64],
        loading: &Loading,
    ) -> Result<FidelityCorrection, ForwardError> {
        if fine.space().names() != coarse.space().names() {
            return Err(ForwardError::InvalidConfig {
                field: "fidelity correction".into(),
                reason: format!(
                    "the fine model `{}` and the coarse model `{}` have different parameters",
                    fine.name(),
                    coarse.name()
                ),
            });
        }
        let f = fine.predict(anchor, loading)?;
        let c = coarse.predict(anchor, loading)?;
        Ok(FidelityCorrection::from_predictions(&f, &c, anchor))
    }

    /// The largest |ratio - 1| over the ratio-corrected samples: how far the
    /// coarse model was from the fine one, relatively.
    pub fn max_relative_change(&self) -> f64 {
        self.ratio
            .iter()
            .map(|r| (r - 1.0).abs())
            .fold(0.0, f64::max)
    }

    /// Applies the correction to coarse predictions in place.
    pub fn apply(&self, coarse: &mut [f64]) {
        for ((c, r), d) in coarse.iter_mut().zip(&self.ratio).zip(&self.offset) {
            *c = r * *c + d;
        }
    }
}

/// A coarse model with a [`FidelityCorrection`]: predicts `r_i c_i(theta) +
/// d_i` on the loading the correction was made on, and refuses any other.
pub struct CorrectedModel {
    pub coarse: Arc<dyn ForwardModel>,
    pub correction: FidelityCorrection,
    /// The loading the correction was made on.
    pub loading: Loading,
    name: String,
}

impl CorrectedModel {
    pub fn new(
        coarse: Arc<dyn ForwardModel>,
        correction: FidelityCorrection,
        loading: Loading,
        fine_name: &str,
    ) -> CorrectedModel {
        let name = format!("{}, corrected to {fine_name}", coarse.name());
        CorrectedModel {
            coarse,
            correction,
            loading,
            name,
        }
    }
}

impl ForwardModel for CorrectedModel {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn space(&self) -> &ParamSpace {
        self.coarse.space()
    }
    fn observable(&self) -> Observable {
        self.coarse.observable()
    }
    /// Only the first output is corrected, so only it is offered.
    fn outputs(&self) -> Vec<Output> {
        vec![Output::from(self.coarse.observable())]
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(CorrectedEvaluator {
            model: self,
            inner: self.coarse.evaluator(),
        })
    }
    fn expensive(&self) -> bool {
        self.coarse.expensive()
    }
}

struct CorrectedEvaluator<'a> {
    model: &'a CorrectedModel,
    inner: Box<dyn Evaluator + 'a>,
}

impl Evaluator for CorrectedEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        if loading != &self.model.loading {
            return Err(ForwardError::InvalidLoading(format!(
                "{}: the correction was made on another loading ({} samples, this one {})",
                self.model.name,
                self.model.loading.len(),
                loading.len()
            )));
        }
        self.inner.predict_into(theta, loading, out)?;
        self.model.correction.apply(out);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use palpate_core::{Drive, ParamSpec};

    /// `F = E d + b d^2 + h E d^3`: `h` plays the mesh error.
    struct Toy {
        space: ParamSpace,
        h: f64,
    }
    struct ToyEval(f64);
    impl Evaluator for ToyEval {
        fn predict_into(
            &mut self,
            t: &[f64],
            l: &Loading,
            o: &mut [f64],
        ) -> Result<(), ForwardError> {
            for (o, d) in o.iter_mut().zip(&l.drive) {
                *o = t[0] * d * (1.0 + self.0 * d * d) + t[1] * d * d;
            }
            Ok(())
        }
    }
    impl ForwardModel for Toy {
        fn name(&self) -> String {
            format!("toy h {}", self.h)
        }
        fn space(&self) -> &ParamSpace {
            &self.space
        }
        fn observable(&self) -> Observable {
            Observable::ForceN
        }
        fn evaluator(&self) -> Box<dyn Evaluator + '_> {
            Box::new(ToyEval(self.h))
        }
    }
    fn toy(h: f64) -> Toy {
        Toy {
            space: ParamSpace::new(vec![
                ParamSpec::new("E", "N/mm", 0.0, f64::INFINITY, 1.0),
                ParamSpec::new("b", "N/mm2", f64::NEG_INFINITY, f64::INFINITY, 0.0),
            ]),
            h,
        }
    }

    /// At its anchor the corrected model is the fine one; the zero-force
    /// sample takes the offset; another loading is refused.
    #[test]
    fn the_corrected_model_is_the_fine_one_at_its_anchor() {
        let (fine, coarse) = (toy(0.01), Arc::new(toy(0.2)));
        let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.5, 1.0, 2.0]);
        let anchor = [2.0, 0.3];
        let c = FidelityCorrection::at(&fine, coarse.as_ref(), &anchor, &loading).unwrap();
        assert_eq!((c.ratio[0], c.offset[0]), (1.0, 0.0));
        assert!(c.max_relative_change() > 0.1);
        let m = CorrectedModel::new(coarse, c, loading.clone(), "h 0.01");
        let want = fine.predict(&anchor, &loading).unwrap();
        let got = m.predict(&anchor, &loading).unwrap();
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-14 * w.abs().max(1.0), "{g} {w}");
        }
        // away from the anchor it is not (b's term has no mesh error here)
        let away = m.predict(&[2.0, 1.0], &loading).unwrap();
        let fine_away = fine.predict(&[2.0, 1.0], &loading).unwrap();
        assert!((away[3] - fine_away[3]).abs() > 1e-3);
        let other = Loading::quasi_static(Drive::DisplacementMm, vec![0.0, 0.5, 1.0]);
        assert!(matches!(
            m.predict(&anchor, &other),
            Err(ForwardError::InvalidLoading(_))
        ));
    }

    /// For a force proportional to the one parameter, the ratio does not
    /// depend on the anchor: the corrected model is the fine one
    /// everywhere.
    #[test]
    fn a_one_modulus_force_is_corrected_everywhere() {
        let (fine, coarse) = (toy(0.01), Arc::new(toy(0.2)));
        let loading = Loading::quasi_static(Drive::DisplacementMm, vec![0.5, 1.0, 2.0]);
        let c = FidelityCorrection::at(&fine, coarse.as_ref(), &[1.0, 0.0], &loading).unwrap();
        let m = CorrectedModel::new(coarse, c, loading.clone(), "fine");
        let got = m.predict(&[3.7, 0.0], &loading).unwrap();
        let want = fine.predict(&[3.7, 0.0], &loading).unwrap();
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-13 * w.abs(), "{g} {w}");
        }
    }
}
