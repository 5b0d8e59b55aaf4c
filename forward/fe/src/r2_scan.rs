//! `R2NoduleScan`: the force of the R2 wheel rolled past ONE nodule, as a
//! function of the nodule's depth, sampled at wheel offsets from the
//! nodule — the forward model behind the R2 localisation surrogate
//! (studies/src/localize).
//!
//! Why offsets: with a frictionless wheel and pure-penalty contact the
//! state depends on the wheel position alone ([`R2Rolling::rolled_pass`]),
//! and away from the block's ends the block is invariant under translation
//! in x, so the force at wheel position p over a nodule at (x_n, d) is
//!
//!   F(p) ~ F0(p) + E(p - x_n; d),
//!
//! F0 the force without nodules and E the nodule's excess. This model rolls
//! the wheel past one nodule at the block's centre `centre` (x = 75 mm for
//! R2) through the positions `centre + offset` of a
//! [`Drive::PositionMm`] loading of offsets; its parameter is the depth
//! (optionally the nodule-to-tissue shear-modulus ratio). The excess is
//! this force minus F0 at the same positions (the nodule-free pass of
//! [`R2Rolling::with_nodules`]`(vec![])`). How well translation invariance
//! and superposition hold is measured against FE in
//! docs/validation/r2-localisation.md.
//!
//! The material parameters are fixed (`material`, BENCHMARKS.md's by
//! default); a common scale of both moduli scales every force exactly
//! (Arruda-Boyce energies are linear in mu, and the contact penalty is
//! proportional to the tissue's mu), so a tissue-modulus nuisance needs no
//! surrogate dimension.

use palpate_core::{
    Drive, Evaluator, ForwardError, ForwardModel, Loading, Observable, Output, ParamSpace,
    ParamSpec,
};

use crate::mesh::inclusions::MIN_CLEARANCE;
use crate::r2::{Nodule, R2Rolling};

/// One nodule rolled past, depth (and ratio) as parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct R2NoduleScan {
    /// The R2 model whose RD, laws, mesh and contact are used; its nodules
    /// are replaced by the scanned one.
    pub template: R2Rolling,
    /// x of the scanned nodule (mm).
    pub centre: f64,
    /// Tissue then nodule law parameters (as [`R2Rolling`]'s theta).
    pub material: Vec<f64>,
    /// Whether the second parameter is the ratio of the nodule's shear
    /// modulus to the tissue's (the nodule's first law parameter is then
    /// `ratio * material[0]`).
    pub with_ratio: bool,
    space: ParamSpace,
}

impl R2NoduleScan {
    /// The scan of `template` (R2's laws with [`R2Rolling::BENCHMARK_PARAMS`])
    /// about the block's centre; depth bounds are the mesh's: the nodule
    /// inside the block with [`MIN_CLEARANCE`] to the top and bottom.
    pub fn new(template: R2Rolling, with_ratio: bool) -> Self {
        let r = template.nodule_radius;
        let mut params = vec![ParamSpec::new(
            "depth",
            "mm",
            r + MIN_CLEARANCE,
            template.height - r - MIN_CLEARANCE,
            0.5 * template.height,
        )];
        let material = R2Rolling::BENCHMARK_PARAMS.to_vec();
        if with_ratio {
            let ratio = material[2] / material[0];
            params.push(ParamSpec::new("ratio", "1", 1.0, f64::INFINITY, ratio));
        }
        R2NoduleScan {
            centre: 0.5 * template.length,
            template,
            material,
            with_ratio,
            space: ParamSpace::new(params),
        }
    }

    /// The one-nodule R2 model at `theta` and its law parameters.
    pub fn model_at(&self, theta: &[f64]) -> (R2Rolling, Vec<f64>) {
        let model = self.template.with_nodules(vec![Nodule {
            x: self.centre,
            depth: theta[0],
        }]);
        let mut material = self.material.clone();
        if self.with_ratio {
            material[2] = theta[1] * material[0];
        }
        (model, material)
    }

    /// The vertical force at `centre + offsets` (increasing), one rolled
    /// segment pressed at the first.
    pub fn scan(&self, theta: &[f64], offsets: &[f64]) -> Result<Vec<f64>, ForwardError> {
        let (mut model, material) = self.model_at(theta);
        let positions: Vec<f64> = offsets.iter().map(|o| self.centre + o).collect();
        let (first, last) = match (positions.first(), positions.last()) {
            (Some(a), Some(b)) => (*a, *b),
            _ => return Ok(Vec::new()),
        };
        model.press_x = first;
        model.roll_to = model.roll_to.max(last);
        // One rolled path solved in this thread (scans already run in
        // parallel over the surrogate's design).
        let loading = Loading::quasi_static(Drive::PositionMm, positions);
        let (sim, _) = model.simulate(&material, &loading, None)?;
        Ok(sim.outputs.iter().map(|r| r[0]).collect())
    }
}

struct ScanEvaluator<'a>(&'a R2NoduleScan);

impl Evaluator for ScanEvaluator<'_> {
    fn predict_into(
        &mut self,
        theta: &[f64],
        loading: &Loading,
        out: &mut [f64],
    ) -> Result<(), ForwardError> {
        if loading.drive_kind != Drive::PositionMm {
            return Err(ForwardError::InvalidLoading(format!(
                "the R2 nodule scan is driven by wheel offsets from the nodule ({}), got {}",
                Drive::PositionMm.column(),
                loading.drive_kind.column()
            )));
        }
        palpate_core::check_output_slots(out.len(), loading.len(), 1)?;
        let f = self.0.scan(theta, &loading.drive)?;
        out.copy_from_slice(&f);
        Ok(())
    }
}

impl ForwardModel for R2NoduleScan {
    fn name(&self) -> String {
        format!(
            "R2 nodule scan (one nodule at x = {} mm, wheel offsets from it), {}",
            self.centre,
            self.template.with_nodules(Vec::new()).name()
        )
    }
    fn space(&self) -> &ParamSpace {
        &self.space
    }
    fn observable(&self) -> Observable {
        Observable::ForceN
    }
    fn outputs(&self) -> Vec<Output> {
        vec![Output::new("force_N", Observable::ForceN)]
    }
    fn evaluator(&self) -> Box<dyn Evaluator + '_> {
        Box::new(ScanEvaluator(self))
    }
    /// A rolled FE pass per prediction.
    fn expensive(&self) -> bool {
        true
    }
}
