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
//! Near the block's ends translation invariance fails (the end is more
//! compliant: one nodule's excess leans towards the nearer end by up to
//! ~0.3 mm within 25 mm of it, `tools/src/bin/r2_excess_shape.rs`), so
//! [`R2NoduleScan::along_block`] adds the nodule's position as a second
//! parameter, `ln_x` = ln(x_n / 1 mm) on [ln(press_x), ln(centre)] (the
//! logarithm spreads a space-filling design towards the end, where the
//! excess changes fastest); its offsets are signed and run on both sides of
//! the nodule. A nodule right of the centre is the mirror image of one left
//! of it (the block and the path are symmetric), so the left half is
//! enough. An offset whose wheel position falls outside the rolled path
//! takes the force at the path's nearer end (the position clamped to the
//! path), so every scan has the same outputs and each output is continuous
//! in x_n (a mirror or nearest-offset fill jumps where the path's end
//! crosses an offset, which a surrogate cannot fit).
//!
//! The material parameters are fixed (`material`, docs/benchmarks.md's by
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
    /// Whether a parameter (after the depth and `ln_x`) is the ratio of the
    /// nodule's shear modulus to the tissue's (the nodule's first law
    /// parameter is then `ratio * material[0]`).
    pub with_ratio: bool,
    /// Whether the second parameter is `ln_x`, the log of the nodule's x
    /// (mm; [`R2NoduleScan::along_block`]); otherwise the nodule sits at
    /// `centre`.
    pub with_position: bool,
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
            with_position: false,
            space: ParamSpace::new(params),
        }
    }

    /// The scan with the nodule's position as the second parameter, `ln_x`
    /// on [ln(press_x), ln(centre)] (see the module docs); the offsets of
    /// its loading are signed.
    pub fn along_block(template: R2Rolling, with_ratio: bool) -> Self {
        let mut s = Self::new(template, with_ratio);
        let centre = s.centre;
        let lo = s
            .template
            .press_x
            .max(s.template.nodule_radius + MIN_CLEARANCE);
        let mut params = s.space.params.clone();
        params.insert(
            1,
            ParamSpec::new("ln_x", "ln mm", lo.ln(), centre.ln(), centre.ln()),
        );
        s.space = ParamSpace::new(params);
        s.with_position = true;
        s
    }

    /// The nodule's x at `theta`.
    pub fn nodule_x(&self, theta: &[f64]) -> f64 {
        if self.with_position {
            theta[1].exp()
        } else {
            self.centre
        }
    }

    /// The one-nodule R2 model at `theta` and its law parameters.
    pub fn model_at(&self, theta: &[f64]) -> (R2Rolling, Vec<f64>) {
        let model = self.template.with_nodules(vec![Nodule {
            x: self.nodule_x(theta),
            depth: theta[0],
        }]);
        let mut material = self.material.clone();
        if self.with_ratio {
            material[2] = theta[1 + usize::from(self.with_position)] * material[0];
        }
        (model, material)
    }

    /// The vertical force at `x_n + offsets` (increasing), one rolled
    /// segment pressed at the first. With [`R2NoduleScan::with_position`]
    /// the positions are clamped to the rolled path (module docs).
    pub fn scan(&self, theta: &[f64], offsets: &[f64]) -> Result<Vec<f64>, ForwardError> {
        let (mut model, material) = self.model_at(theta);
        let x = self.nodule_x(theta);
        let (lo, hi) = (self.template.press_x, self.template.roll_to);
        let at = |o: f64| {
            if self.with_position {
                (x + o).clamp(lo, hi)
            } else {
                x + o
            }
        };
        let mut positions: Vec<f64> = offsets.iter().map(|&o| at(o)).collect();
        positions.dedup_by(|a, b| (*a - *b).abs() <= 1e-9);
        let (first, last) = match (positions.first(), positions.last()) {
            (Some(a), Some(b)) => (*a, *b),
            _ => return Ok(Vec::new()),
        };
        model.press_x = first;
        model.roll_to = model.roll_to.max(last);
        // One rolled path solved in this thread (scans already run in
        // parallel over the surrogate's design).
        let loading = Loading::quasi_static(Drive::PositionMm, positions.clone());
        let (sim, _) = model.simulate(&material, &loading, None)?;
        Ok(offsets
            .iter()
            .map(|&o| {
                let p = at(o);
                let k = positions
                    .iter()
                    .position(|q| (q - p).abs() <= 1e-9)
                    .unwrap_or(0);
                sim.outputs[k][0]
            })
            .collect())
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
            "R2 nodule scan (one nodule at {}, wheel offsets from it), {}",
            if self.with_position {
                "x = exp(ln_x) mm".to_string()
            } else {
                format!("x = {} mm", self.centre)
            },
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
