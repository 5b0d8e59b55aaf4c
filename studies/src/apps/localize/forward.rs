//! The localisation model of N nodules as a [`ForwardModel`]: parameters
//! `x_1, d_1, ..., x_N, d_N, s` (each nodule's position on the rolled path
//! and depth in the surrogate's box, mm, and the modulus scale on [1/2, 2]),
//! the drive the wheel position (mm), the output the force (N),
//!
//!   F(p) = s [ F0(p) + sum_n E(p - x_n; d_n) ]   ([`super`]),
//!
//! and the surrogate's held-out error variance at each position as its
//! [`ErrorVariance`], so that its posterior is palpate-uq's
//! [`palpate_uq::model_error::ModelErrorPosterior`].

use super::LocModel;
use palpate_core::{
    Drive, Evaluator, ForwardError, ForwardModel, Loading, Observable, ParamSpace, ParamSpec,
};
use palpate_uq::model_error::ErrorVariance;

/// Bounds of the modulus scale s.
pub const SCALE_BOUNDS: (f64, f64) = (0.5, 2.0);

/// The localisation model of `nodules` nodules (module docs).
pub struct LocForward<'a> {
    model: &'a LocModel,
    nodules: usize,
    space: ParamSpace,
}

impl<'a> LocForward<'a> {
    /// `nodules` nodules on `model` (the parameters' names: `x1_mm`,
    /// `depth1_mm`, ..., `scale`).
    pub fn new(model: &'a LocModel, nodules: usize) -> Self {
        let (lo, hi) = model.path;
        let (dlo, dhi) = model.depth_box;
        let mut params = Vec::with_capacity(2 * nodules + 1);
        for j in 0..nodules {
            let x0 = lo + (hi - lo) * (j as f64 + 0.5) / nodules as f64;
            params.push(ParamSpec::new(format!("x{}_mm", j + 1), "mm", lo, hi, x0));
            params.push(ParamSpec::new(
                format!("depth{}_mm", j + 1),
                "mm",
                dlo,
                dhi,
                0.5 * (dlo + dhi),
            ));
        }
        params.push(ParamSpec::new(
            "scale",
            "1",
            SCALE_BOUNDS.0,
            SCALE_BOUNDS.1,
            1.0,
        ));
        LocForward {
            model,
            nodules,
            space: ParamSpace::new(params),
        }
    }

    /// The loading of a record at wheel positions `positions` (mm).
    pub fn loading(positions: &[f64]) -> Loading {
        Loading::quasi_static(Drive::PositionMm, positions.to_vec())
    }

    /// The parameter vector of nodules `(x, depth)` and scale `s`.
    pub fn theta(nodules: &[(f64, f64)], s: f64) -> Vec<f64> {
        let mut t: Vec<f64> = nodules.iter().flat_map(|&(x, d)| [x, d]).collect();
        t.push(s);
        t
    }

    fn check(&self, theta: &[f64], loading: &Loading) -> Result<(), ForwardError> {
        if theta.len() != self.space.len() {
            return Err(ForwardError::WrongParameterCount {
                expected: self.space.len(),
                got: theta.len(),
            });
        }
        if loading.drive_kind != Drive::PositionMm {
            return Err(ForwardError::InvalidLoading(format!(
                "the localisation model is driven by the wheel position, not {:?}",
                loading.drive_kind
            )));
        }
        Ok(())
    }

    fn split(&self, theta: &[f64], nodules: &mut Vec<(f64, f64)>) -> f64 {
        nodules.clear();
        nodules.extend((0..self.nodules).map(|j| (theta[2 * j], theta[2 * j + 1])));
        theta[2 * self.nodules]
    }
}

struct LocEval<'a> {
    fwd: &'a LocForward<'a>,
    grid: Vec<f64>,
    nodules: Vec<(f64, f64)>,
}

impl Evaluator for LocEval<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.fwd.check(theta, loading)?;
        let s = self.fwd.split(theta, &mut self.nodules);
        self.fwd
            .model
            .predict_into(&loading.drive, &self.nodules, s, out, &mut self.grid)
            .map_err(|e| ForwardError::InvalidParameter {
                name: "depth".into(),
                value: f64::NAN,
                reason: format!("the scan surrogate: {e}"),
            })
    }
}

impl ForwardModel for LocForward<'_> {
    fn name(&self) -> String {
        format!(
            "R2 localisation, RD {} mm, {} nodule(s)",
            self.model.rd, self.nodules
        )
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(LocEval {
            fwd: self,
            grid: vec![0.0; self.model.scan.loading().len()],
            nodules: Vec::with_capacity(self.nodules),
        })
    }
}

impl ErrorVariance for LocForward<'_> {
    fn error_variance_into(
        &self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        self.check(theta, loading)?;
        let mut nodules = Vec::with_capacity(self.nodules);
        let s = self.split(theta, &mut nodules);
        self.model
            .error_variance_into(&loading.drive, &nodules, s, out);
        Ok(())
    }
}
